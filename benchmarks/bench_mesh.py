"""Mesh build timings (a script, not a test).

    python benchmarks/bench_mesh.py [--presets small_cherry large_cherry ...] [--repeat 5]

Prints, per preset, the objects, nodes and triangles of its tree and the median and fastest
time of :func:`treeanim.render.mesh.build_mesh` (the static GPU mesh, built once per tree when
the viewer or ``treeanim render`` loads it). The build is vectorised over objects: the target
is well under a second for any shipped preset (large_cherry's 800,000 triangles included).
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import sys
import time
from pathlib import Path

try:
    import treeanim  # noqa: F401
except ImportError:  # running from a checkout without installing
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "src"))

import numpy as np

import treeanim as ta
from treeanim.render.mesh import build_mesh


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--presets", nargs="+", default=None, help="presets to measure (default: all shipped)")
    ap.add_argument("--repeat", type=int, default=5, help="builds per preset (default 5)")
    args = ap.parse_args(argv)
    names = args.presets or ta.list_presets()
    print(f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores; Python "
          f"{platform.python_version()}, numpy {np.__version__}")
    print(f"{'preset':<16}{'objects':>10}{'nodes':>10}{'triangles':>12}{'median ms':>12}{'min ms':>10}")
    for name in names:
        tree = ta.load_preset(name)
        times = []
        for _ in range(max(1, args.repeat)):
            t0 = time.perf_counter()
            mesh = build_mesh(tree)
            times.append((time.perf_counter() - t0) * 1e3)
        assert mesh.triangle_count == int(tree.triangles_per_object().sum())
        print(f"{name:<16}{tree.n_objects:>10,}{tree.n_nodes:>10,}{mesh.triangle_count:>12,}"
              f"{statistics.median(times):>12.1f}{min(times):>10.1f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
