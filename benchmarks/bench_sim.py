"""Simulation speed per preset: median milliseconds per step, wind on, one thread.

A script, not a test::

    python benchmarks/bench_sim.py [--steps 600] [--presets small_cherry large_cherry ...]

For each preset it runs ``--warmup`` steps, then times ``--steps`` steps of 1/60 s with a
5 m/s turbulent wind (``WindField``) and reports the median and 90th percentile of

* ``step``: :meth:`Simulation.step` alone (wind sampling, loads, oscillators, bending, the
  hierarchy's structural nodes);
* ``step+pose``: the step plus reading ``positions`` and ``rotations`` (the full per-node pose
  a renderer uploads every frame; built lazily on first access).

Each is reported as the median wall time, its 90th percentile, and the median CPU time of the
thread (``cpu``), which a busy shared machine disturbs much less than the wall clock.

Each preset is timed twice: with the paper's model (``model="paper"``, each object on its own)
and with the tree model (``model="tree"``, the default: the whole tree as one implicit
structure, docs/design.md §12), whose ratio to the paper's step is the last column.
``--falling`` adds a row for the tree model while the leaves fall after the season jumps to
winter (issue #12), timed from the moment they let go.

Targets (issue #4): large_cherry <= 3 ms, grassland <= 2 ms, small_cherry <= 1 ms per step.
Where a preset cannot be loaded (presets not installed) a synthetic tree of the same size is
timed instead, and the row says so.
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"

import argparse  # noqa: E402
import platform  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

PRESETS = ("small_cherry", "large_cherry", "tulip_poplar", "grassland")
TARGETS_MS = {"small_cherry": 1.0, "large_cherry": 3.0, "grassland": 2.0}


def synthetic(name: str):
    """A tree of roughly the preset's size (Table 1), for when presets are unavailable."""
    from treeanim.model.build import ObjectSpec, assemble

    rng = np.random.default_rng(0)
    sizes = {  # (levels of branching, children per branch, leaves per terminal branch)
        "small_cherry": (6, 2, 26),
        "large_cherry": (6, 3, 22),
        "tulip_poplar": (3, 17, 7),
    }
    specs: list[ObjectSpec] = []
    if name == "grassland":
        for _ in range(5000):
            base = np.array([rng.uniform(-5, 5), 0.0, rng.uniform(-5, 5)])
            pts = base + np.outer(np.linspace(0, 0.4, 4), [0.05, 1.0, 0.02])
            specs.append(ObjectSpec(pts, np.array([0.01, 0.008, 0.006, 0.002]), "blade", 1))
        return assemble(specs, name="synthetic_grassland")
    depth, children, leaves = sizes[name]

    def branch(base, d, length, diam, level, parent, attach):
        pts = base + np.outer(np.linspace(0, length, 3), d)
        specs.append(ObjectSpec(pts, np.linspace(diam, diam * 0.7, 3), "branch", level, parent, attach))
        me = len(specs) - 1
        if level < depth:
            for _ in range(children):
                nd = d + rng.normal(scale=0.6, size=3)
                nd /= np.linalg.norm(nd)
                branch(pts[-1], nd, length * 0.7, diam * 0.6, level + 1, me, 2)
        else:
            for _ in range(leaves):
                nd = rng.normal(size=3)
                nd /= np.linalg.norm(nd)
                pet = pts[1] + np.outer(np.linspace(0, 0.03, 4), nd)
                specs.append(ObjectSpec(pet, np.full(4, 0.002), "leaf", level + 1, me, 1,
                                        w=np.cross(nd, rng.normal(size=3)), lamina_length=0.1))

    branch(np.zeros(3), np.array([0.0, 1.0, 0.0]), 1.5, 0.3, 1, -1, 0)
    return assemble(specs, name=f"synthetic_{name}")


def load(name: str):
    try:
        import treeanim

        return treeanim.load_preset(name), False
    except Exception:  # noqa: BLE001 - presets missing: time a synthetic tree instead
        return synthetic(name), True


def bench(tree, steps: int, warmup: int, speed: float, dt: float, model: str = "tree",
          falling: bool = False) -> dict:
    from treeanim.physics.simulation import Simulation
    from treeanim.physics.wind import WindField

    sim = Simulation(tree, wind=WindField(speed=speed, seed=1), model=model)
    for _ in range(warmup):
        sim.step(dt)
    if falling:  # the season slider to winter: the leaves let go (each timing loop starts so)
        sim.season = 1.0
    clock = time.perf_counter
    cpu = time.thread_time  # CPU time of this thread: robust on a shared, busy machine
    t_step, c_step = np.empty(steps), np.empty(steps)
    for k in range(steps):
        t0, c0 = clock(), cpu()
        sim.step(dt)
        c_step[k], t_step[k] = cpu() - c0, clock() - t0
    t_pose, c_pose = np.empty(steps), np.empty(steps)
    if falling:  # back on the tree, and off again
        sim.season = 0.0
        sim.season = 1.0
    for k in range(steps):
        t0, c0 = clock(), cpu()
        sim.step(dt)
        sim.positions
        sim.rotations
        c_pose[k], t_pose[k] = cpu() - c0, clock() - t0
    return {
        "step": 1e3 * np.median(t_step),
        "step_p90": 1e3 * np.percentile(t_step, 90),
        "step_cpu": 1e3 * np.median(c_step),
        "pose": 1e3 * np.median(t_pose),
        "pose_p90": 1e3 * np.percentile(t_pose, 90),
        "pose_cpu": 1e3 * np.median(c_pose),
        "finite": bool(np.all(np.isfinite(sim.positions))),
    }


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--presets", nargs="+", default=list(PRESETS))
    ap.add_argument("--steps", type=int, default=600)
    ap.add_argument("--warmup", type=int, default=60)
    ap.add_argument("--speed", type=float, default=5.0, help="wind speed at the tree top (m/s)")
    ap.add_argument("--dt", type=float, default=1 / 60)
    ap.add_argument("--falling", action="store_true",
                    help="also time the tree model while the leaves fall (season set to winter after the "
                         "warm-up; use --steps of about 2 s, while they are in the air)")
    args = ap.parse_args(argv)
    print(f"# {platform.processor() or platform.machine()}, Python {platform.python_version()}, "
          f"numpy {np.__version__}, one thread, wind {args.speed} m/s, dt {args.dt:.4g} s, "
          f"{args.steps} steps")
    print(f"{'preset':<32}{'objects':>8}{'nodes':>8}{'step ms':>10}{'p90':>7}{'cpu':>7}"
          f"{'step+pose ms':>14}{'p90':>7}{'cpu':>7}{'target':>8}{'×paper':>8}")
    for name in args.presets:
        tree, synth = load(name)
        paper_cpu = None
        models = ("paper", "tree") + (("leaves falling",) if args.falling and (tree.kind == "leaf").any() else ())
        for model in models:
            r = bench(tree, args.steps, args.warmup, args.speed, args.dt, model="paper" if model == "paper" else "tree",
                      falling=model == "leaves falling")
            label = f"{name}{' (synthetic)' if synth else ''}, {model}"
            target = TARGETS_MS.get(name)
            ratio = "" if paper_cpu is None else f"{r['step_cpu'] / paper_cpu:.2f}"
            paper_cpu = paper_cpu or r["step_cpu"]
            print(f"{label:<32}{tree.n_objects:>8}{tree.n_nodes:>8}{r['step']:>10.2f}{r['step_p90']:>7.2f}"
                  f"{r['step_cpu']:>7.2f}{r['pose']:>14.2f}{r['pose_p90']:>7.2f}{r['pose_cpu']:>7.2f}"
                  f"{(f'{target:.1f}' if target else '-'):>8}{ratio:>8}" + ("" if r["finite"] else "  NON-FINITE!"),
                  flush=True)


if __name__ == "__main__":
    main()
