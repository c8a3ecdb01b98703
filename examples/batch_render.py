"""Render a still of every preset in summer and in winter, offscreen (no window, no GPU needed).

    .venv/bin/python examples/batch_render.py --out stills/ --size 960x540

Each picture is what ``treeanim render PRESET --season S --out FILE.png`` makes; this script
only loops over presets and seasons.
"""

import argparse
from pathlib import Path

import treeanim as ta
from treeanim.cli import main as treeanim


def run() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="stills", help="folder for the PNGs (default ./stills)")
    parser.add_argument("--size", default="960x540", help="image size WxH (default 960x540)")
    parser.add_argument("--wind", default="5", help="wind speed at the tree top, m/s (default 5)")
    args = parser.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    for name in ta.list_presets():
        for season in ("0", "1"):
            path = out / f"{name}_season{season}.png"
            status = treeanim(["render", name, "--season", season, "--wind", args.wind, "--size", args.size,
                               "--quiet", "--out", str(path)])
            if status:  # (treeanim render has printed where it wrote)
                return status
    return 0


if __name__ == "__main__":
    raise SystemExit(run())
