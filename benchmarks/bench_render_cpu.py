"""Render time per frame as wall time and as CPU time, for A/B comparisons on a busy machine.

A script, not a test::

    python benchmarks/bench_render_cpu.py [--frames 12] [--samples 0] [PRESET ...]

For each preset (``large_cherry@winter`` for the winter row) it does what ``treeanim bench``
does for its render column (1280×720, wind 5 m/s, the pose uploaded and the frame drawn and
read back, two frames skipped) and prints the median wall time and the median CPU time of a
frame. The CPU time is the whole process's (``time.process_time``): with a software rasteriser
such as Mesa's llvmpipe it counts the rasteriser's worker threads, and it hardly moves when
other jobs share the cores, where the wall time can double. On an idle machine the wall time
is roughly the vertex work (one thread) plus the rest shared among the worker threads.
``--orbit`` moves the camera every frame, as a user dragging the view does (the renderer then
draws its background cache again every frame).

It runs any version of treeanim on the import path, so an older commit checked out in a git
worktree can be measured against this one, alternately (``PYTHONPATH=that/src``; that
worktree needs ``src/treeanim/shaders`` and ``src/treeanim/presets`` linked to its
``shaders`` and ``assets/presets``).
"""

from __future__ import annotations

import argparse
import statistics
import time


def _this_version():
    """(the bench's rows, framed_camera) wherever this version of treeanim keeps them."""
    try:
        from treeanim.render.camera import framed_camera
        from treeanim.table1 import ROWS
    except ImportError:  # before issue #15: both in offline.py
        from treeanim import offline

        return getattr(offline, "ROWS", None) or offline.BENCH_ROWS, offline.framed_camera
    return ROWS, framed_camera


def measure(key: str, off, frames: int, orbit: float = 0.0, elevation: float | None = None,
            view=None) -> tuple[float, float]:
    """(median wall ms, median CPU ms) of ``frames`` frames of ``key``'s bench row, the camera
    ``elevation`` degrees up (None: this version's framing), at ``view`` = (distance, target
    x, y, z) if given, and turned by ``orbit`` degrees about the tree before each frame."""
    import treeanim as ta

    rows, framed_camera = _this_version()
    preset, season = rows.get(key, (key, 0.0))
    tree = ta.load_preset(preset)
    sim = ta.Simulation(tree, wind=ta.WindField(speed=5.0, seed=0), season=season, seed=0)
    for _ in range(5):
        sim.step(1 / 30)
    off.load(tree)
    if view is None:
        cam = framed_camera(tree, off.width, off.height, elevation=elevation, present=sim.present)
    else:  # the same camera in any version: distance and target given
        from treeanim.render.camera import OrbitCamera

        cam = OrbitCamera(target=view[1:], distance=view[0], elevation=elevation or 0.0)
    wall, cpu = [], []
    for k in range(frames + 2):
        sim.step(1 / 30)
        cam.azimuth += orbit
        t0, c0 = time.perf_counter(), time.process_time()
        off.update(sim.positions, sim.rotations, sim.shown)
        off.render(cam, season=season)
        if k >= 2:
            wall.append((time.perf_counter() - t0) * 1e3)
            cpu.append((time.process_time() - c0) * 1e3)
    return statistics.median(wall), statistics.median(cpu)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("presets", nargs="*", default=["small_cherry", "large_cherry", "large_cherry@winter",
                                                   "tulip_poplar", "grassland"])
    ap.add_argument("--frames", type=int, default=12, help="frames timed per preset (default 12)")
    ap.add_argument("--samples", type=int, default=0, help="MSAA samples (default 0, as the viewer on llvmpipe)")
    ap.add_argument("--orbit", type=float, default=0.0,
                    help="turn the camera by this many degrees a frame (default 0: still, as the bench)")
    ap.add_argument("--elevation", type=float, default=None,
                    help="the camera's degrees above the horizon (default: the version's own framing; "
                    "give one to compare versions whose framing differs)")
    ap.add_argument("--view", default=None, metavar="D,TX,TY,TZ",
                    help="the camera's distance and target (metres), the same in any version (one preset)")
    args = ap.parse_args(argv)

    from treeanim.render.offscreen import OffscreenRenderer

    off = OffscreenRenderer(1280, 720, samples=args.samples)
    try:
        for key in args.presets:
            view = None if args.view is None else [float(x) for x in args.view.split(",")]
            wall, cpu = measure(key, off, args.frames, args.orbit, args.elevation, view)
            print(f"{key}: wall {wall:.1f} ms, cpu {cpu:.1f} ms", flush=True)
    finally:
        off.release()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
