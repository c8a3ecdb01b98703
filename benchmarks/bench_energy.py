"""Does a hard release ever gain energy, and how fast does a gale spin the fastest part?

A script, not a test::

    python benchmarks/bench_energy.py [--steps 120 30 10]

* **Release.** The synthetic scan (assets/qsm) in cherry leaves, its first main limb pulled
  with 15 kN (more than its wood bears: the pull is held at the rupture force) for 3 s, let go
  in calm air and followed 4 s: the largest change of ``Simulation.energy`` in one step, as a
  share of the energy before it (negative: it only ever fell), at each step length.
* **Gale.** The grassland and the small cherry in a 30 m/s wind for 5 s: the largest angular
  speed of any segment (rad/s) and the lowest node (m; the ground is at 0).
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

import treeanim as ta

QSM = Path(__file__).resolve().parents[1] / "assets" / "qsm" / "synthetic_broadleaf.txt"


def release(rate: float) -> float:
    """The largest relative energy change in one step after a hard release at ``rate`` steps a second."""
    tree = ta.load_qsm(QSM, leaves="cherry")
    limb = int(np.flatnonzero((tree.level == 2) & (tree.kind == "branch"))[0])
    dt = 1.0 / rate
    sim = ta.Simulation(tree)
    sim.pull(limb, (15e3, 0.0, 0.0))
    for _ in range(int(round(3 / dt))):
        sim.step(dt)
    sim.release()
    E = [sim.energy]
    for _ in range(int(round(4 / dt))):
        sim.step(dt)
        E.append(sim.energy)
    E = np.array(E)
    return float(np.max(np.diff(E) / E[:-1]))


def gale(preset: str, rate: float) -> tuple[float, float]:
    """The fastest segment's angular speed (rad/s) and the lowest node (m) in a 30 m/s gale."""
    tree = ta.load_preset(preset)
    sim = ta.Simulation(tree, wind=ta.WindField(speed=30.0, seed=3))
    dt = 1.0 / rate
    fastest, lowest = 0.0, np.inf
    for _ in range(int(round(5 / dt))):
        sim.step(dt)
        fastest = max(fastest, float(np.linalg.norm(sim.state.tree.Om, axis=1).max()))
        lowest = min(lowest, float(sim.positions[:, 1].min()))
    return fastest, lowest


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=float, nargs="+", default=[120.0, 30.0, 10.0], help="steps a second")
    args = ap.parse_args()
    for rate in args.steps:
        print(f"1/{rate:g} s: hard release, largest energy change in a step {100 * release(rate):+.2f} %", flush=True)
        for preset in ("grassland", "small_cherry"):
            fastest, lowest = gale(preset, rate)
            print(f"    30 m/s gale, {preset}: fastest segment {fastest:.0f} rad/s, lowest node {lowest:+.3f} m",
                  flush=True)


if __name__ == "__main__":
    main()
