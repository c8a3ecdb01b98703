"""Scene simulation speed: steps per second of the orchard and the woodland, fully simulated and
with levels of detail from a viewer's camera (docs/design.md §17). A script, not a test::

    python benchmarks/bench_scene.py [--steps 60] [--scenes orchard woodland]

Per scene, one thread, a 5 m/s turbulent wind, steps of 1/30 s, each timed with the pose
(``positions`` and ``rotations``, what the viewer uploads every frame):

* ``full``: every tree at detail level 0;
* ``framed``: levels from :func:`~treeanim.physics.lod.choose_detail` for the viewer's opening
  camera at 960×540 (the whole scene framed, :func:`~treeanim.render.camera.framed_camera`);
* ``close``: the same 12 m from the scene's centre, 10° up (a walk among the trees).

It reports the stepped degrees of freedom, the trees at each level, the median wall and thread
CPU milliseconds per step (the CPU time is what a busy shared machine disturbs least) and steps
per second of CPU time (issue 28's targets, reported, not asserted: the orchard at full
detail and the woodland with levels of detail at 30 steps a second or more).

Then what a change of levels costs (``sim.set_detail``, median thread CPU ms; and the step with
its pose after a switch back to ``framed``, to read against that row): one tree a level finer
than ``framed`` (a different tree each time, and back), and ``close`` ↔ ``framed`` (the many
trees a walk into the scene changes).
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ[_var] = "1"

import argparse  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

SIZE = (960, 540)


def _cameras(scene):
    """The viewer's opening camera and a close one."""
    from treeanim.render.camera import framed_camera

    framed = framed_camera(scene, *SIZE)
    close = framed_camera(scene, *SIZE, elevation=10.0, distance=12.0)
    return {"framed": framed, "close": close}


def _time(sim, steps: int, warmup: int) -> tuple[float, float]:
    """Median wall and thread CPU seconds of a step with its pose."""
    for _ in range(warmup):
        sim.step(1 / 30)
        sim.positions, sim.rotations
    wall, cpu = [], []
    for _ in range(steps):
        t, c = time.perf_counter(), time.thread_time()
        sim.step(1 / 30)
        sim.positions, sim.rotations
        wall.append(time.perf_counter() - t)
        cpu.append(time.thread_time() - c)
    return float(np.median(wall)), float(np.median(cpu))


def _switch(sim, pairs) -> tuple[float, float]:
    """Median thread CPU seconds of ``set_detail`` over the switches ``pairs`` (levels, and
    back), and of the step with its pose after each switch back."""
    put, after = [], []
    for pair in pairs:
        for levels in pair:
            c = time.thread_time()
            sim.set_detail(levels)
            put.append(time.thread_time() - c)
            c = time.thread_time()
            sim.step(1 / 30)
            sim.positions, sim.rotations
        after.append(time.thread_time() - c)
    return float(np.median(put)), float(np.median(after))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=60)
    ap.add_argument("--warmup", type=int, default=10)
    ap.add_argument("--scenes", nargs="+", default=["orchard", "woodland"])
    ap.add_argument("--switches", type=int, default=15, help="level changes timed of each kind")
    a = ap.parse_args()
    import treeanim as ta
    from treeanim.physics.lod import choose_detail, tree_extents
    from treeanim.physics.wind import WindField

    print("| scene | camera | DOF stepped | trees at levels 0/1/2/3 | step + pose, wall / cpu (ms) | steps/s (cpu) |")
    print("|---|---|---|---|---|---|")
    switches = []
    for name in a.scenes:
        scene = ta.load_scene(name)
        sim = ta.Simulation(scene, wind=WindField(speed=5.0))
        roots, heights = tree_extents(scene)
        runs = {"full": np.zeros(scene.n_trees, np.int64)}
        for cam_name, cam in _cameras(scene).items():
            focal = SIZE[1] / (2.0 * np.tan(np.radians(cam.fov_y) / 2.0))
            runs[cam_name] = choose_detail(cam.eye, roots, heights, focal)
        for cam_name, levels in runs.items():
            sim.set_detail(levels)
            wall, cpu = _time(sim, a.steps, a.warmup)
            counts = "/".join(str(int(np.sum(levels == k))) for k in range(4))
            print(f"| {name} | {cam_name} | {sim.active_dof:,} | {counts} | {1e3 * wall:.1f} / {1e3 * cpu:.1f} "
                  f"| {1 / cpu:.0f} |", flush=True)
        framed, close = runs["framed"], runs["close"]
        finer = [framed.copy() for _ in range(a.switches)]
        for k, levels in zip(np.random.default_rng(0).choice(scene.n_trees, a.switches, replace=False), finer):
            levels[k] = max(levels[k] - 1, 0)
        sim.set_detail(framed)
        for what, pairs in (("one tree", [(f, framed) for f in finer]), ("close ↔ framed", [(close, framed)] * a.switches)):
            changed = int(np.sum(pairs[0][0] != framed))
            switches.append(f"| {name} | {what} | {changed} | " + " | ".join(f"{1e3 * x:.1f}" for x in _switch(sim, pairs)) + " |")
    print("\n| scene | switch | trees changed | set_detail, cpu (ms) | step + pose after it, cpu (ms) |")
    print("|---|---|---|---|---|")
    print("\n".join(switches))


if __name__ == "__main__":
    main()
