"""Headless Chromium (SwiftShader WebGL) for the tests: serve a folder, read frames out of a page.

A page hands a frame out by writing its canvas as a PNG data URL into an element
(``<pre class="frame">``); ``--dump-dom`` prints the page once its virtual time has run out.
"""

import base64
import functools
import http.server
import re
import shutil
import subprocess
import threading
from contextlib import contextmanager
from pathlib import Path

import numpy as np
from PIL import Image


@contextmanager
def serve(folder: Path):
    """Serve ``folder`` over HTTP on a free local port; yields the port."""
    handler = functools.partial(http.server.SimpleHTTPRequestHandler, directory=str(folder))
    handler.log_message = lambda *a: None
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    try:
        yield server.server_address[1]
    finally:
        server.shutdown()


#: The virtual time (ms) for a page that draws one still frame once it has loaded: idle, its
#: clock runs ahead of the decoding of the glb's leaf texture, which does not hold it back, and
#: with a tenth of this some pages were dumped before their frame under load.
STILL_MS = 600_000


def frames(url: str, profile: Path, virtual_ms: int = 60000) -> list[np.ndarray]:
    """The RGB frames (H, W, 3) float the page at ``url`` hands out, in order."""
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    assert chromium, "chromium is not installed: run scripts/test"
    res = subprocess.run([chromium, "--headless", "--no-sandbox", "--disable-gpu", "--use-angle=swiftshader",
                          "--enable-unsafe-swiftshader", f"--user-data-dir={profile}", "--window-size=480,480",
                          f"--virtual-time-budget={virtual_ms}", "--dump-dom", url],
                         capture_output=True, text=True, timeout=300)
    pngs = re.findall(r"data:image/png;base64,([A-Za-z0-9+/=]+)", res.stdout)
    assert pngs, res.stderr[-2000:]
    out = []
    for i, data in enumerate(pngs):
        path = profile.with_name(f"{profile.name}-{i}.png")
        path.write_bytes(base64.b64decode(data))
        out.append(np.asarray(Image.open(path).convert("RGB"), float))
    return out


def changed(a: np.ndarray, b: np.ndarray) -> float:
    """The fraction of pixels that differ visibly between two frames."""
    return float(np.mean(np.abs(a - b).sum(axis=2) > 30))
