"""Frame time of a scene (``orchard``, ``woodland``) on this machine's GL, from a low viewer's
camera among the trees and from an overview, for before/after comparisons of the renderer.

A script, not a test::

    python benchmarks/bench_scene_render.py [--frames 6] [--size 960x540] [--samples 0] [SCENE ...]

Per scene: load, 5 steps in a 5 m/s wind, then for each camera ``frames`` frames of pose upload,
draw and read back (one skipped; with ``--turf`` the wind on the turf too); prints the median wall and CPU ms a frame (CPU counts a
software rasteriser's worker threads), the shadow map's texel, and, where the renderer counts
them, the trees and triangles it drew (``Renderer.drawn``). It runs any version of treeanim on the import path.
"""

from __future__ import annotations

import argparse
import statistics
import time


def cameras(scene, width: int, height: int) -> dict:
    """The two views: ``low`` (eye 1.6 m up, 12 m from the scene's centre, looking across it) and
    ``overview`` (the whole scene framed from 30° up)."""
    import numpy as np

    from treeanim.render.camera import OrbitCamera, framed_camera

    P = scene.rest_positions
    centre = 0.5 * (P.min(axis=0) + P.max(axis=0))
    low = OrbitCamera(target=(centre[0], 1.2, centre[2]), distance=12.0, azimuth=35.0, elevation=float(np.degrees(np.arcsin(0.4 / 12.0))))
    return {"low": low, "overview": framed_camera(scene, width, height, azimuth=35.0, elevation=30.0)}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scenes", nargs="*", default=["orchard", "woodland"])
    ap.add_argument("--frames", type=int, default=6)
    ap.add_argument("--size", default="960x540")
    ap.add_argument("--samples", type=int, default=0)
    ap.add_argument("--turf", action="store_true", help="the wind on the turf too (Renderer.update's wind)")
    ap.add_argument("--save", default="", help="folder to save each view's last frame as SCENE_VIEW.png")
    a = ap.parse_args()
    import treeanim as ta
    from treeanim.render.offscreen import OffscreenRenderer

    w, h = (int(v) for v in a.size.split("x"))
    with OffscreenRenderer(w, h, samples=a.samples) as off:
        for name in a.scenes:
            scene = ta.load_scene(name)
            sim = ta.Simulation(scene, wind=ta.WindField(speed=5.0, seed=0), seed=0)
            for _ in range(5):
                sim.step(1 / 30)
            off.load(scene)
            for view, cam in cameras(scene, w, h).items():
                wall, cpu = [], []
                for i in range(a.frames + 1):
                    sim.step(1 / 30)
                    t0, c0 = time.perf_counter(), time.process_time()
                    turf = {"wind": sim.wind, "time": sim.time} if a.turf else {}
                    off.update(sim.positions, sim.rotations, sim.present, **turf)
                    img = off.render(cam)
                    if i:
                        wall.append(1e3 * (time.perf_counter() - t0))
                        cpu.append(1e3 * (time.process_time() - c0))
                drawn = getattr(off.renderer, "drawn", None)
                print(f"{name:9s} {view:9s} wall {statistics.median(wall):7.0f} ms  cpu {statistics.median(cpu):7.0f} ms"
                      f"  shadow texel {100 * off.renderer.shadow.texel:.1f} cm" + (f"  drawn {drawn}" if drawn is not None else ""),
                      flush=True)
                if a.save:
                    from PIL import Image

                    Image.fromarray(img).save(f"{a.save}/{name}_{view}.png")


if __name__ == "__main__":
    main()
