"""TreeQSM import and physical modes: import time, step time, frequencies against field figures.

A script, not a test::

    python benchmarks/bench_qsm.py [--cylinders 3000] [--steps 200]

* **import**: a synthetic QSM of about ``--cylinders`` cylinders (``synthetic_table``) written
  as text and as a MATLAB file, read and built into a Tree (:func:`load_qsm`): median of 5;
* **step**: median milliseconds per :meth:`Simulation.step` of 1/60 s in a 5 m/s wind, with
  the physical modes, leafless and with ``--leaves cherry`` (one thread);
* **beam theory**: a uniform cylinder's physical frequency against (1.875²/2π)·√(EI/ρAL⁴);
* **DBH/H²**: the trunk's frequency for a family of synthetic trees (forest-grown slenderness,
  H/DBH ≈ 60 and open-grown, H/DBH ≈ 37), against REALISM.md's 0.1–0.3 Hz for 12–25 m trees;
* **leaves**: trunk f and ζ leafless and in leaf, with the species' default leaves per metre
  and with a denser crown, against REALISM.md's 10–25 % lower f and 2–5× ζ: the modal
  parameters, and the sway measured in the simulation after a pull is let go.
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"

import argparse  # noqa: E402
import platform  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402
from scipy.io import savemat  # noqa: E402


def big_table(cylinders: int):
    """A synthetic QSM of about ``cylinders`` cylinders (a 20 m tree, 0.5 m DBH)."""
    from treeanim.model.qsm import synthetic_table

    length = 0.35
    while True:  # shorter cylinders until the count is reached
        table = synthetic_table(height=20.0, dbh=0.5, limbs=24, twigs=8, sub_twigs=4, cylinder_length=length)
        if len(table) >= cylinders or length < 0.05:
            return table
        length *= 0.9


def median_time(fn, repeat=5) -> float:
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return float(np.median(times))


def step_ms(tree, steps: int) -> float:
    import treeanim as ta

    sim = ta.Simulation(tree, wind=ta.WindField(speed=5.0, seed=0))
    for _ in range(20):
        sim.step(1 / 60)
    times = []
    for _ in range(steps):
        t0 = time.perf_counter()
        sim.step(1 / 60)
        times.append(time.perf_counter() - t0)
    return 1e3 * float(np.median(times))


def trunk(table, leaves=None) -> tuple[float, float]:
    import treeanim as ta
    from treeanim.model.qsm import build_tree

    sim = ta.Simulation(build_tree(table, leaves=leaves), model="paper")  # its modes (beam theory)
    return float(sim.modes.f[0, 0]), float(sim.modes.zeta[0, 0])


def released(tree, seconds: float = 20.0) -> tuple[float, float]:
    """Frequency and damping ratio of the trunk's free sway after a pull, from the simulation:
    the period between upward zero crossings, and the logarithmic decrement of the peaks."""
    import treeanim as ta
    from treeanim.physics.trace import trace_tips

    sim = ta.Simulation(tree)
    sim.pull(0, (3000.0, 0.0, 0.0))
    sim.step(30.0)  # a held pull settles
    sim.release()
    t, tips = trace_tips(sim, 0, seconds, 1 / 240)
    x = tips[:, 0, 0] - tree.rest_positions[tree.object_start[0] + tree.object_count[0] - 1, 0]
    up = np.flatnonzero((x[:-1] < 0) & (x[1:] >= 0))
    tc = t[up] - x[up] * (t[up + 1] - t[up]) / (x[up + 1] - x[up])
    f = 1.0 / np.mean(np.diff(tc))
    peaks = np.array([x[a:b].max() for a, b in zip(up[:-1], up[1:])])
    delta = np.mean(np.log(peaks[:-1] / peaks[1:]))
    return float(f), float(delta / np.sqrt(4 * np.pi**2 + delta**2))


def main() -> None:
    import treeanim as ta
    from treeanim.model.build import ObjectSpec, assemble
    from treeanim.model.params import WOOD_TYPES, PhysicsParams
    from treeanim.model.qsm import load_qsm, synthetic_table, write_table

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cylinders", type=int, default=3000)
    ap.add_argument("--steps", type=int, default=200)
    args = ap.parse_args()
    print(f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}, "
          f"numpy {np.__version__}")

    table = big_table(args.cylinders)
    with tempfile.TemporaryDirectory() as tmp:
        txt, mat = Path(tmp) / "big.txt", Path(tmp) / "big.mat"
        write_table(txt, table)
        savemat(mat, {"cylinders": table})
        t_txt = median_time(lambda: load_qsm(txt))
        t_mat = median_time(lambda: load_qsm(mat))
        t_leaf = median_time(lambda: load_qsm(txt, leaves="cherry"), repeat=3)
        bare, leafy = load_qsm(txt), load_qsm(txt, leaves="cherry")
    print(f"\nimport of {len(table):,} cylinders ({bare.n_objects:,} branches, {bare.n_nodes:,} nodes): "
          f"text {t_txt:.3f} s, .mat {t_mat:.3f} s, text with --leaves cherry ({leafy.stats()['leaves']:,} leaves) "
          f"{t_leaf:.3f} s")
    t0 = time.perf_counter()
    ta.Simulation(bare)
    print(f"Simulation set-up (tree model): {time.perf_counter() - t0:.3f} s")
    print(f"step, 1/60 s, 5 m/s: leafless {step_ms(bare, args.steps):.2f} ms, in leaf "
          f"{step_ms(leafy, args.steps // 4):.2f} ms (real time: under 16.7 ms)")

    print("\nuniform cylinder, physical f / beam theory:")
    for (L, D, n, wood) in ((10.0, 0.3, 1, "hardwood"), (10.0, 0.3, 6, "hardwood"), (3.0, 0.05, 4, "softwood")):
        w = WOOD_TYPES[wood]
        pts = np.column_stack([np.zeros(n + 1), np.linspace(0, L, n + 1), np.zeros(n + 1)])
        tree = assemble([ObjectSpec(pts, np.full(n + 1, D))], name="c", physics=PhysicsParams(**w))
        f = ta.Simulation(tree, model="paper", modes="physical").modes.f[0, 0]
        E, rho = w["wood_youngs_modulus"], w["wood_density"]
        f_th = 1.875104**2 / (2 * np.pi) * np.sqrt(E * (np.pi * D**4 / 64) / (rho * (np.pi * D**2 / 4) * L**4))
        print(f"  L {L:g} m, D {D:g} m, {n} segments, {wood}: {f:.4f} Hz / {f_th:.4f} Hz = {f / f_th:.4f}")

    print("\ntrunk frequency, synthetic family (leafless):")
    print("  H (m)  DBH (m)  DBH/H²     f (Hz)  f/(DBH/H²)")
    for slender in (60.0, 37.5):
        for H in (12.0, 15.0, 20.0, 25.0):
            dbh = H / slender
            f, z = trunk(synthetic_table(height=H, dbh=dbh))
            print(f"  {H:5.1f}  {dbh:7.3f}  {dbh / H**2:.5f}  {f:6.3f}  {f / (dbh / H**2):7.1f}")

    print("\nleaves (synthetic_broadleaf geometry, 15 m, DBH 0.4 m): trunk f, zeta")
    table = synthetic_table(height=15.0, dbh=0.4, limbs=12, twigs=5, sub_twigs=3)
    f0, z0 = trunk(table)
    print(f"  leafless                 f {f0:.3f} Hz  zeta {z0:.3f}")
    for leaves in ("cherry", "cherry:120", "cherry:200", "tulip_poplar"):
        f, z = trunk(table, leaves)
        print(f"  --leaves {leaves:<15} f {f:.3f} Hz ({100 * (f / f0 - 1):+.1f} %)  zeta {z:.3f} ({z / z0:.2f}x)")
    print("\nmeasured in the simulation: the trunk pulled and released in calm air (the tree model)")
    from treeanim.model.qsm import build_tree

    f0, z0 = released(build_tree(table))
    print(f"  leafless                 f {f0:.3f} Hz  zeta {z0:.3f}")
    for leaves in ("cherry", "cherry:200"):
        f, z = released(build_tree(table, leaves=leaves))
        print(f"  --leaves {leaves:<15} f {f:.3f} Hz ({100 * (f / f0 - 1):+.1f} %)  zeta {z:.3f} ({z / z0:.2f}x)")


if __name__ == "__main__":
    main()
