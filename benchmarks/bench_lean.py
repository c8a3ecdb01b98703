"""How far the wind leans each preset: limb lean at 5, 15 and 30 m/s, summer and winter.

A script, not a test::

    python benchmarks/bench_lean.py [--presets small_cherry ...] [--seconds 20] [--paper]

For each preset, season (summer 0, winter 1) and wind speed it runs the default turbulent
wind (:class:`~treeanim.physics.wind.WindField` at that speed) for ``--seconds`` after a
settling period and reports the *lean*: the mean downwind displacement of the limb tips
(the tips of the objects of levels 1–2: trunk and main limbs; for the grassland, the blades),
as a percentage of the tree's height. The summer/winter ratio is the summer lean over the
winter lean at 30 m/s. ``--paper`` measures the paper's model (``model="paper"``) instead of the
tree model (the default).

The README's table (issue #10) is this script's output.
"""

from __future__ import annotations

import argparse

import numpy as np

PRESETS = ("beam", "small_cherry", "large_cherry", "tulip_poplar", "grassland")
SPEEDS = (5.0, 15.0, 30.0)
DT = 1 / 30


def limbs(tree) -> np.ndarray:
    """Objects whose tips measure the lean: trunk and main limbs (levels 1–2) or blades."""
    branch = tree.kind != "leaf"
    return np.flatnonzero(branch & (tree.level <= 2))


def lean(tree, speed: float, season: float, seconds: float, settle: float = 5.0, model: str = "tree") -> float:
    """Mean downwind displacement of the limb tips over ``seconds`` (after ``settle``), % of height."""
    import treeanim as ta

    sim = ta.Simulation(tree, wind=ta.WindField(speed=speed, direction=(1.0, 0.0, 0.0)), season=season,
                        model=model)
    objs = limbs(tree)
    tips = tree.object_start[objs] + tree.object_count[objs] - 1
    rest = tree.rest_positions[tips, 0]
    for _ in range(int(settle / DT)):
        sim.step(DT)
    total, n = 0.0, int(seconds / DT)
    for _ in range(n):
        sim.step(DT)
        total += float(np.mean(sim.positions[tips, 0] - rest))
    height = float(np.ptp(tree.rest_positions[:, 1]))
    return 100.0 * total / n / height


def main() -> None:
    import treeanim as ta

    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--presets", nargs="+", default=list(PRESETS))
    ap.add_argument("--seconds", type=float, default=20.0)
    ap.add_argument("--paper", action="store_true", help="the paper's model (model='paper'; default: the tree model)")
    args = ap.parse_args()
    model = "paper" if args.paper else "tree"
    print(f"limb lean, % of the tree's height ({model} model, "
          f"default turbulent wind, mean over {args.seconds:g} s)\n")
    head = " | ".join(f"{s:g} m/s" for s in SPEEDS)
    print(f"| preset | {head} | summer/winter at 30 m/s |")
    print("|---" * (len(SPEEDS) + 2) + "|")
    for name in args.presets:
        tree = ta.load_preset(name)
        summer = [lean(tree, s, 0.0, args.seconds, model=model) for s in SPEEDS]
        winter = lean(tree, SPEEDS[-1], 1.0, args.seconds, model=model)
        ratio = summer[-1] / winter if winter > 0 else float("inf")
        cells = " | ".join(f"{x:.2f}" for x in summer)
        print(f"| {name} | {cells} | {ratio:.2f} |", flush=True)


if __name__ == "__main__":
    main()
