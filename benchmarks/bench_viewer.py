"""Frame rates of the interactive viewer, and its CPU time per frame outside the simulation.

A script, not a test. It needs a display (use ``xvfb-run -a -s "-screen 0 1280x720x24"`` on a
machine without one)::

    python benchmarks/bench_viewer.py [--size 1280x720] [--frames 40] [--samples N] [--step] [--json FILE]

For every preset (and the large cherry in winter) it opens the viewer with its panel in a
window of ``--size``, wind 5 m/s, runs ``--warmup`` frames, then times ``--frames`` frames of
the real main loop (advance by the elapsed time, draw, imgui, swap) and reports medians of

* ``FPS`` and ``frame``: wall time of a whole frame, swap included;
* ``sim``: the simulation's sub-steps (``Viewer.advance``, building the pose included);
* ``draw``: everything else the viewer does on the CPU in a frame: the pose upload
  (``Renderer.update``), the draw calls (``Renderer.draw``), the panel (``Panel.draw``) and
  imgui's rendering; ``driver``: the part of it spent inside the draw calls of the tree's
  parts, the ground, the sky and the background's copy: a software rasteriser such as Mesa
  llvmpipe shades every vertex inside the draw call, a GPU driver only queues it; ``ours`` =
  ``draw`` − ``driver``;
* ``cpu``: the thread's CPU time in ``draw`` (less disturbed by other processes than the wall
  clock; on llvmpipe it excludes the rasteriser's worker threads);
* ``update``, ``panel``, ``imgui``: wall times of the pose upload, building the panel, and
  imgui's OpenGL rendering.

Under Xvfb there is no vertical sync, so ``FPS`` is what the renderer sustains. To see the
viewer's own CPU cost with no rasterising at all, run it on Mesa's no-op driver, which accepts
every GL call and draws nothing (``--step`` advances 1/60 s each frame, one simulation step a
frame, since no-op frames come far faster than 60 a second)::

    GALLIUM_NOOP=1 xvfb-run -a -s "-screen 0 1280x720x24" python benchmarks/bench_viewer.py --step
"""

from __future__ import annotations

import argparse
import json
import platform
import sys
import time

import numpy as np

ROWS = ("small_cherry", "large_cherry", "large_cherry@winter", "tulip_poplar", "grassland", "beam")


class _Timer:
    """Accumulates wall and thread-CPU seconds of the calls it wraps."""

    def __init__(self) -> None:
        self.wall = self.cpu = 0.0

    def reset(self) -> None:
        self.wall = self.cpu = 0.0

    def wrap(self, fn):
        def timed(*a, **kw):
            w, c = time.perf_counter(), time.thread_time()
            try:
                return fn(*a, **kw)
            finally:
                self.wall += time.perf_counter() - w
                self.cpu += time.thread_time() - c

        return timed


class _TimedVao:
    """A moderngl VertexArray whose render() calls are timed."""

    def __init__(self, inner, timer: _Timer) -> None:
        self._inner = inner
        self.render = timer.wrap(inner.render)

    def __getattr__(self, name):
        return getattr(self._inner, name)


def bench_row(win, row: str, frames: int, warmup: int, step: bool = False) -> dict:
    import treeanim as ta
    from treeanim.app.viewer import Viewer

    name, _, season = row.partition("@")
    tree = ta.load_preset(name)
    v = Viewer(win, tree, season=1.0 if season == "winter" else 0.0, wind_speed=5.0)
    try:
        win.connect(v)
        for _ in range(warmup):
            win.poll()
            v.frame(1 / 60 if step else None)
            win.swap()
        t = {k: _Timer() for k in ("sim", "draw", "driver", "update", "panel", "imgui")}
        r = v.renderer
        progs = r.tree_pass.programs
        for key, (prog, vao) in progs.items():
            if vao is not None:
                progs[key] = (prog, _TimedVao(vao, t["driver"]))
        r.sky_pass.vao = _TimedVao(r.sky_pass.vao, t["driver"])
        r.background.vao = _TimedVao(r.background.vao, t["driver"])
        r.ground_pass.vaos = [_TimedVao(v, t["driver"]) for v in r.ground_pass.vaos]
        v.advance = t["sim"].wrap(v.advance)
        v.draw = t["draw"].wrap(v.draw)
        r.update = t["update"].wrap(r.update)
        v.panel.draw = t["panel"].wrap(v.panel.draw)
        v.gui.render = t["imgui"].wrap(v.gui.render)
        rec = {k: [] for k in ("frame", "sim", "draw", "driver", "ours", "cpu", "update", "panel", "imgui")}
        last = time.perf_counter()
        for _ in range(frames):
            for x in t.values():
                x.reset()
            win.poll()
            v.frame(1 / 60 if step else None)
            win.swap()
            now = time.perf_counter()
            rec["frame"].append(now - last)
            last = now
            for k in ("sim", "draw", "driver", "update", "panel", "imgui"):
                rec[k].append(t[k].wall)
            rec["ours"].append(t["draw"].wall - t["driver"].wall)
            rec["cpu"].append(t["draw"].cpu)
        st = tree.stats(v.sim.season)
        out = {k: 1e3 * float(np.median(x)) for k, x in rec.items()}
        out.update(row=row, objects=st["objects"], nodes=st["nodes"], triangles=st["triangles"],
                   fps=1e3 / out["frame"], ours_p90=1e3 * float(np.percentile(rec["ours"], 90)))
        return out
    finally:
        v.release()


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--size", default="1280x720", help="window size WxH (default 1280x720)")
    ap.add_argument("--frames", type=int, default=40, help="frames timed per preset (default 40)")
    ap.add_argument("--warmup", type=int, default=8, help="frames before timing (default 8)")
    ap.add_argument("--samples", type=int, default=None, help="MSAA samples (default: the viewer's choice)")
    ap.add_argument("--rows", nargs="+", default=list(ROWS), help=f"presets (default: {' '.join(ROWS)})")
    ap.add_argument("--step", action="store_true",
                    help="advance 1/60 s every frame whatever the clock says (one simulation step a frame)")
    ap.add_argument("--json", default=None, help="also write the figures to this file")
    args = ap.parse_args(argv)
    w, h = (int(x) for x in args.size.lower().split("x"))

    from treeanim.app.window import ViewerUnavailable, Window

    try:
        win = Window.open(w, h, "treeanim bench", samples=args.samples, vsync=False)
    except ViewerUnavailable as e:
        print(f"bench_viewer: {e}", file=sys.stderr)
        return 2
    try:
        info = win.ctx.info
        print(f"{platform.processor() or platform.machine()}, {info.get('GL_RENDERER')}, "
              f"window {w}x{h}, MSAA {win.samples or 'off'}, Python {platform.python_version()}"
              + (", one 1/60 s step a frame" if args.step else ""))
        print(f"{'preset':<21}{'objects':>8}{'triangles':>10}{'FPS':>7}{'frame':>7}{'sim':>7}{'draw':>7}"
              f"{'driver':>7}{'ours':>6}{'p90':>6}{'cpu':>6}{'update':>7}{'panel':>6}{'imgui':>6}  (ms, medians)")
        rows = []
        for row in args.rows:
            r = bench_row(win, row, args.frames, args.warmup, args.step)
            rows.append(r)
            print(f"{row:<21}{r['objects']:>8,}{r['triangles']:>10,}{r['fps']:>7.1f}{r['frame']:>7.1f}"
                  f"{r['sim']:>7.2f}{r['draw']:>7.2f}{r['driver']:>7.2f}{r['ours']:>6.2f}{r['ours_p90']:>6.2f}"
                  f"{r['cpu']:>6.2f}{r['update']:>7.2f}{r['panel']:>6.2f}{r['imgui']:>6.2f}", flush=True)
        if args.json:
            with open(args.json, "w") as f:
                json.dump({"renderer": info.get("GL_RENDERER"), "size": [w, h], "samples": win.samples,
                           "step": args.step, "rows": rows}, f, indent=1)
    finally:
        win.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
