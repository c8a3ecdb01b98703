"""How the wind's drag on each preset grows with its speed: Vogel's exponent, whole and in parts.

A script, not a test::

    python benchmarks/bench_drag.py [--presets small_cherry ...] [--speeds 3 5 10 20 30] [--turbulence 0.3]

For each preset and speed it holds a steady, uniform wind along x over the tree (no gusts, no
turbulence) for two seconds of 1/60 s steps and averages the air's force along x on every body
(wood, and the leaves' forces on their twigs) over the last second, in leaf (summer) and bare
(winter). With ``--turbulence I`` the wind is the default physical wind of that turbulence
intensity instead (its gusts and profile too, the same seed in leaf and bare), averaged over
eight seconds after two. It reports the force on the whole tree, on its trunk (object 0), on
the crown's wood (winter, less the trunk) and on the foliage (summer less winter), the exponent
2 + b of F ∝ U^(2+b) between successive speeds for the whole tree, the crown (all but the
trunk) and the foliage alone, how far F/U² falls from 5 to 20 m/s, and the crown's drag
coefficient on its outline at rest (the convex hull of the tree across the wind, ½ρU²·C_d·A).
REALISM.md: b ≈ −0.5 … −1 for broadleaf foliage, leaves reducing drag 2–5× at 10–20 m/s.

It reads the step's force array (``Simulation``'s private tree model): the public API has no
force on the tree.
"""

from __future__ import annotations

import argparse

import numpy as np

PRESETS = ("small_cherry", "large_cherry", "tulip_poplar")
SPEEDS = (3.0, 5.0, 10.0, 20.0, 30.0)
DT = 1 / 60
AIR_DENSITY = 1.2


class Steady:
    """A uniform wind, the same everywhere and always."""

    def __init__(self, speed: float) -> None:
        self.u = np.array([speed, 0.0, 0.0])

    def sample(self, points, t):
        return np.broadcast_to(self.u, np.shape(points)).copy()


def forces(tree, speed: float, season: float, turbulence: float = 0.0) -> tuple[float, float]:
    """(whole tree, trunk): the air's mean force along the wind (N), over the second second of a
    steady wind, or over seconds 2–10 of a turbulent one."""
    import treeanim as ta

    if turbulence > 0.0:
        wind, start, stop = ta.WindField(speed=speed, turbulence=turbulence), 2.0, 10.0
    else:
        wind, start, stop = Steady(speed), 1.0, 2.0
    sim = ta.Simulation(tree, wind=wind, season=season)
    impl = sim._impl
    first = impl._s.body_of_obj
    whole, trunk = [], []
    for k in range(int(round(stop / DT))):
        sim.step(DT)
        if k * DT >= start:
            F = impl._work.F[:, 3]
            whole.append(F.sum())
            trunk.append(F[first[0]:first[1]].sum())
    return float(np.mean(whole)), float(np.mean(trunk))


def outline(tree) -> float:
    """The area (m²) of the tree's convex outline across the wind (its y–z projection)."""
    from scipy.spatial import ConvexHull

    return float(ConvexHull(np.asarray(tree.rest_positions)[:, [2, 1]]).volume)


def exponents(F: dict, speeds) -> str:
    return " ".join(f"{np.log(F[b] / F[a]) / np.log(b / a):.2f}" for a, b in zip(speeds, speeds[1:]))


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--presets", nargs="+", default=list(PRESETS))
    ap.add_argument("--speeds", nargs="+", type=float, default=list(SPEEDS))
    ap.add_argument("--turbulence", type=float, default=0.0, help="turbulence intensity (0: a steady wind)")
    args = ap.parse_args(argv)
    import treeanim as ta

    speeds = sorted(args.speeds)
    print("| preset | U (m/s) | whole (N) | trunk | crown wood | foliage | crown C_d on its outline |")
    print("|---|---|---|---|---|---|---|")
    summary = []
    for name in args.presets:
        tree = ta.load_preset(name)
        area = outline(tree)
        whole, crown, foliage = {}, {}, {}
        for U in speeds:
            (fs, ts), (fw, tw) = forces(tree, U, 0.0, args.turbulence), forces(tree, U, 1.0, args.turbulence)
            whole[U], crown[U], foliage[U] = fs, fs - ts, fs - fw
            cd = crown[U] / (0.5 * AIR_DENSITY * U * U * area)
            print(f"| {name} | {U:g} | {fs:.1f} | {ts:.1f} | {fw - tw:.1f} | {fs - fw:.1f} | {cd:.2f} |")
        fall = "" if not {5.0, 20.0} <= set(speeds) else f"{whole[5.0] / 25.0 / (whole[20.0] / 400.0):.2f}×"
        summary.append(f"| {name} | {exponents(whole, speeds)} | {exponents(crown, speeds)} | "
                       f"{exponents(foliage, speeds)} | {fall} |")
    print()
    print("| preset | 2 + b, whole tree | crown (no trunk) | foliage | F/U² falls, 5 → 20 m/s |")
    print("|---|---|---|---|---|")
    print("\n".join(summary))


if __name__ == "__main__":
    main()
