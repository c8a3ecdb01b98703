"""The paper's Table 1 beside ours, measured on this machine (a script, not a test).

    python benchmarks/bench_table1.py [--presets NAME ...] [--size 1280x720] [--frames 20]
                                      [--steps 200] [--samples 4] [--json table1.json]

A thin wrapper of ``treeanim bench`` (same options; see ``treeanim bench --help``): per preset,
objects, nodes and triangles (ours / the paper's), the median simulation time per step with
wind, the median offscreen render time per frame (pixels read back, so the GPU has finished),
and FPS = 1000 / (sim + render), with the CPU and the GL renderer named. The latest table
measured is kept in benchmarks/README.md.
"""

from __future__ import annotations

import sys
from pathlib import Path

try:
    import treeanim  # noqa: F401
except ImportError:  # running from a checkout without installing
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "src"))

from treeanim.cli import main

if __name__ == "__main__":
    sys.exit(main(["bench", *sys.argv[1:]]))
