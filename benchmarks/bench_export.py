"""Export cost per preset, joint budget and format: time, peak memory and size (a script, not a test).

    python benchmarks/bench_export.py [--presets small_cherry large_cherry] [--seconds 5]
                                      [--budgets all 1024 256] [--formats glb usdc shader]

Runs ``treeanim export`` once per row as a separate process (``/usr/bin/time``: wall time of the
whole command, simulation, baking, fitting and writing included, and its peak resident memory)
and prints a Markdown table, a row as each finishes. ``shader`` is ``--motion shader`` (a static
mesh: no budget, no clip length).
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
from pathlib import Path


def run(preset: str, seconds: float, budget: str, fmt: str, folder: Path) -> tuple[float, float, float]:
    """(seconds, peak MB, file MB) of one export."""
    out = folder / f"{preset}.{'glb' if fmt == 'shader' else fmt}"
    args = [sys.executable, "-m", "treeanim", "export", preset, "--out", str(out), "--quiet"]
    args += ["--motion", "shader"] if fmt == "shader" else ["--seconds", str(seconds), "--joints", budget]
    res = subprocess.run(["/usr/bin/time", "-f", "%e %M", *args], capture_output=True, text=True)
    if res.returncode != 0:
        raise SystemExit(f"{' '.join(args)} failed: {res.stderr.strip().splitlines()[-1]}")
    wall, kb = res.stderr.strip().splitlines()[-1].split()
    size = sum(f.stat().st_size for f in folder.iterdir() if f.stem.startswith(preset))
    for f in folder.iterdir():
        f.unlink()
    return float(wall), int(kb) / 1024, size / 1e6


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--presets", nargs="+", default=["small_cherry", "large_cherry", "tulip_poplar", "grassland"])
    ap.add_argument("--seconds", type=float, default=5.0)
    ap.add_argument("--budgets", nargs="+", default=["all", "1024", "256"])
    ap.add_argument("--formats", nargs="+", default=["glb", "usdc", "shader"], choices=["glb", "gltf", "usdc", "usda", "shader"])
    args = ap.parse_args()
    print(f"{args.seconds:g} s at 30 fps in the default wind (5 m/s)\n")
    print("| preset | format | joints | time | peak memory | size |")
    print("|---|---|---:|---:|---:|---:|")
    with tempfile.TemporaryDirectory() as tmp:
        for preset in args.presets:
            for fmt in args.formats:
                for budget in ["—"] if fmt == "shader" else args.budgets:
                    wall, mem, size = run(preset, args.seconds, budget, fmt, Path(tmp))
                    print(f"| {preset} | {fmt} | {budget} | {wall:.1f} s | {mem:.0f} MB | {size:.1f} MB |", flush=True)


if __name__ == "__main__":
    main()
