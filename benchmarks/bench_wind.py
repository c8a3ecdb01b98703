"""Wind-field timings (a script, not a test).

    python benchmarks/bench_wind.py [--points 10000] [--grid 32] [--repeat 200]

Prints the median time to build the three N³ noise grids (fresh seeds, so no cache hits;
the build includes the lookup tables, as the first ``sample`` call of a new field pays it)
and the median time of one ``WindField.sample`` call on 1,000 and K points, for the paper's
field and the physical one (the default; its tile build too). Targets (issues #3, #11):
build < 50 ms for N = 32, sample < 1 ms for 10,000 points.
"""

from __future__ import annotations

import argparse
import os
import platform
import sys
import time
from pathlib import Path

try:
    import treeanim  # noqa: F401
except ImportError:  # running from a checkout without installing
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "src"))

import numpy as np
import scipy

from treeanim.physics.wind import WindField, fbm_noise


def median_ms(fn, repeat: int) -> tuple[float, float]:
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    times = np.array(times) * 1e3
    return float(np.median(times)), float(np.percentile(times, 90))


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--points", type=int, default=10_000)
    ap.add_argument("--grid", type=int, default=32)
    ap.add_argument("--repeat", type=int, default=200)
    args = ap.parse_args(argv)

    print(f"python {platform.python_version()}, numpy {np.__version__}, scipy {scipy.__version__}, "
          f"{os.cpu_count()} CPUs, {platform.machine()}")

    # Build: three fbm grids + padded lookup tables, via the public path (first sample).
    seeds = iter(range(10_000, 10_000 + 10 * args.repeat))
    probe = np.array([[0.0, 5.0, 0.0]])

    def build():
        WindField(model="paper", grid=args.grid, seed=next(seeds)).sample(probe, 0.0)

    build()  # warm up imports and FFT plans
    n_build = max(5, min(args.repeat // 10, 30))
    med, p90 = median_ms(build, n_build)
    print(f"build three {args.grid}³ grids (+ tables):  median {med:7.2f} ms   p90 {p90:7.2f} ms"
          f"   (target < 50 ms)")
    med_f, _ = median_ms(lambda: fbm_noise(args.grid, 1.67, next(seeds)), n_build)
    print(f"  of which one fbm_noise({args.grid}):          median {med_f:7.2f} ms")

    # Sample: K points spread over (and beyond) the default bounds, advancing time.
    rng = np.random.default_rng(0)
    pts = rng.uniform((-6.0, 0.0, -6.0), (6.0, 11.0, 6.0), (args.points, 3))
    seeds_phys = iter(range(50_000, 50_100))
    t0 = time.perf_counter()
    WindField(seed=next(seeds_phys)).sample(probe, 0.0)
    print(f"build the physical tile (+ tables):     {1e3 * (time.perf_counter() - t0):7.2f} ms (once per seed, β)")
    for model in ("paper", "physical"):
        own = dict(grid=args.grid) if model == "paper" else {}  # the grid is the paper's setting
        wind = WindField(model=model, direction=(1.0, 0.0, 0.4), speed=8.0, **own)
        for k in sorted({1000, args.points}):
            p = pts[:k]
            clock = iter(np.arange(10 * args.repeat + 20) / 60.0)
            wind.sample(p, 0.0)
            for _ in range(10):
                wind.sample(p, next(clock))
            med, p90 = median_ms(lambda: wind.sample(p, next(clock)), args.repeat)
            target = "   (target < 1 ms)" if k == 10_000 else ""
            print(f"{model:>8} sample {k:6d} points:    median {med:7.3f} ms   p90 {p90:7.3f} ms"
                  f"   = {med * 1e6 / k:5.1f} ns/point{target}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
