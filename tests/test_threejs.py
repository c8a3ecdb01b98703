"""The README's three.js recipe, as written, plays an exported clip in headless Chromium."""

import re

import numpy as np

from browser import changed, frames, serve
from test_export import NODE_MODULES, export
from test_readme import ROOT

#: After the README's code, in the same module: once the clip has loaded (the file and its leaf
#: texture, whose decoding runs beside the page's virtual clock), hand out a frame 0.5 s and 2 s
#: later (rendered again right there: the recipe's canvas keeps no drawing buffer).
HARNESS = """
const shot = () => {
  renderer.render(scene, camera);
  const frame = document.createElement('pre');
  frame.className = 'frame';
  frame.textContent = renderer.domElement.toDataURL('image/png');
  document.body.appendChild(frame);
};
const loaded = setInterval(() => {  // the glb (its leaf texture decoded) is in once the mixer is
  if (mixer === null) return;
  clearInterval(loaded);
  setTimeout(shot, 500);
  setTimeout(shot, 2000);
}, 100);
"""


def readme_threejs() -> str:
    """The README's three.js code block."""
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    return re.search(r"\*\*three\.js\*\*[^`]*```js\n(.*?)```", text, re.S).group(1)


def test_the_readme_threejs_recipe_plays_the_clip(tmp_path):
    code = readme_threejs()
    assert "cherry.glb" in code and "AnimationMixer" in code
    web = tmp_path / "web"
    web.mkdir()
    res = export("small_cherry", "--seconds", "3", "--fps", "30", "--wind", "15", "--out", str(web / "cherry.glb"))
    assert res.returncode == 0, res.stderr
    (web / "three").symlink_to(NODE_MODULES / "three")
    (web / "index.html").write_text(
        '<!doctype html><html><head><meta charset="utf-8"><style>body { margin: 0 }</style>'
        '<script type="importmap">{"imports": {"three": "./three/build/three.module.js", '
        '"three/addons/": "./three/examples/jsm/"}}</script></head><body>'
        f'<script type="module">\n{code}\n{HARNESS}</script></body></html>', encoding="utf-8")
    with serve(web) as port:
        first, later = frames(f"http://127.0.0.1:{port}/index.html", tmp_path / "profile")
    tree = np.mean(np.abs(first).sum(axis=2) > 10)  # the recipe's scene has no background: black
    assert 0.003 < tree < 0.5, "the tree is drawn (small: the recipe frames the large cherry)"
    assert changed(first, later) > 0.05 * tree, "the clip plays: the tree moves between 0.5 s and 2 s after it loaded"
