"""``treeanim render``: simulate a tree and render it offscreen into a video, a folder of PNG
frames or one PNG still (:func:`run_render`).

Everything renders through :class:`treeanim.render.offscreen.OffscreenRenderer` (EGL, Mesa
llvmpipe where there is no GPU), as the viewer draws: a scene's trees out of view culled, far
ones coarse (docs/design.md §17, Drawing), and simulated at the detail the viewer would step
them at from the same camera (:func:`viewer_detail`). Ctrl-C stops after the current frame and
keeps what was rendered (:class:`StopRequest`); the sinks (:mod:`.sinks`) write every file
safely.
"""

from __future__ import annotations

import contextlib
import signal
import threading
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import GLUnavailable
from ..model.scene import object_trees
from ..physics.lod import choose_detail, tree_extents
from ..render.camera import OrbitCamera, framed_camera
from .sinks import FRAME_NAME, SINKS, write_png
from .target import Target

#: Seconds simulated before a still when no --seconds is given.
STILL_SECONDS = 2.0


@contextlib.contextmanager
def offscreen(width: int, height: int, samples: int):
    """An :class:`OffscreenRenderer` on its own EGL context, released on exit; GLUnavailable
    if there is no context to be had."""
    from ..render.offscreen import OffscreenRenderer, create_egl_context

    try:
        ctx = create_egl_context()
    except RuntimeError as e:
        raise GLUnavailable(str(e)) from None
    try:
        off = OffscreenRenderer(width, height, samples=samples, ctx=ctx)
        try:
            yield off
        finally:
            off.release()
    finally:
        ctx.release()


class StopRequest:
    """While active, the first Ctrl-C (SIGINT) only sets :attr:`requested`, so the current frame
    finishes and the output is closed properly; a further Ctrl-C raises KeyboardInterrupt,
    except inside :meth:`deferred` blocks (writing a frame, closing the file), where it only
    sets the flag. Outside the main thread it does nothing (signals only reach the main one).
    """

    def __init__(self) -> None:
        self.requested = False
        self._soft = 0
        self._old = None

    def _handler(self, signum, frame) -> None:
        if self.requested and not self._soft:
            raise KeyboardInterrupt
        self.requested = True

    def __enter__(self) -> "StopRequest":
        if threading.current_thread() is threading.main_thread():
            self._old = signal.signal(signal.SIGINT, self._handler)
        return self

    def __exit__(self, *exc) -> None:
        if self._old is not None:
            signal.signal(signal.SIGINT, self._old)
            self._old = None

    @contextlib.contextmanager
    def deferred(self):
        """A block no Ctrl-C interrupts (it is remembered in :attr:`requested`)."""
        self._soft += 1
        try:
            yield
        finally:
            self._soft -= 1


@dataclass
class RenderJob:
    """What ``treeanim render`` does (see :func:`run_render`)."""

    target: Target
    width: int
    height: int
    fps: float
    seconds: float
    start: float = 0.0
    season: float = 0.0
    pulls: list = field(default_factory=list)
    azimuth: float = 0.0
    elevation: float | None = None
    distance: float | None = None
    samples: int = 4
    quiet: bool = False

    def frame_range(self) -> tuple[int, int]:
        """(first, count): frame k of the clip is simulated time (first + k) / fps."""
        first = int(round(self.start * self.fps))
        return first, int(round(self.seconds * self.fps))


def viewer_detail(sim, tree, camera: OrbitCamera, height: int) -> None:
    """Simulate a scene's trees at the detail the viewer steps them at from ``camera`` in a
    picture ``height`` pixels high (:func:`~treeanim.physics.lod.choose_detail`: by each tree's
    height on the screen; a tree holding a pull stays whole); a lone tree, or the paper's
    model, is left whole."""
    if int(object_trees(tree).max(initial=0)) > 0 and sim.model == "tree":
        focal = height / (2.0 * np.tan(np.radians(camera.fov_y) / 2.0))
        sim.set_detail(choose_detail(camera.eye, *tree_extents(tree), focal))


@dataclass
class RenderResult:
    """What :func:`run_render` did.

    Attributes
    ----------
    frames : int
        Frames written (1 for a still).
    total : int
        Frames the job asked for.
    kept : bool
        Whether the output was kept (False: nothing was written, nothing is left behind).
    interrupted : bool
        Whether Ctrl-C stopped the run early (the frames so far are kept).
    path : Path
        The video, still or folder.
    size : (int, int)
        Width and height of the frames written (an MP4's odd sides padded to even).
    bytes : int
        Size of what was kept, in bytes (a folder: its frame files).
    """

    frames: int
    total: int
    kept: bool
    interrupted: bool
    path: Path
    size: tuple[int, int]
    bytes: int = 0


def run_render(job: RenderJob, tree, sim, log=print) -> RenderResult:
    """Simulate ``sim`` and render it to ``job.target``.

    A still is the state at ``start + seconds``; a video or folder holds frames at
    ``start + k / fps`` for k < ``seconds * fps``. Ctrl-C stops after the current frame and
    keeps what was rendered (see :class:`StopRequest`); so does an error after the first frame
    (other than the encoder's own), before it is raised again.
    """
    from tqdm import tqdm

    from .. import scripted

    target = job.target
    with offscreen(job.width, job.height, job.samples) as off:
        off.load(tree)
        cam = framed_camera(tree, job.width, job.height, job.azimuth, job.elevation, job.distance,
                            present=sim.shown)
        viewer_detail(sim, tree, cam, job.height)

        def shoot() -> np.ndarray:
            off.update(sim.positions, sim.rotations, sim.shown, wind=sim.wind, time=sim.time)
            return off.render(cam, season=job.season)

        if target.kind == "still":
            T = job.start + job.seconds
            for _ in scripted.frames(sim, 2, 1 / max(T, 1e-9), job.pulls):  # frames at 0 and T (T > 0)
                pass
            write_png(target.path, shoot())
            return RenderResult(1, 1, True, False, target.path, (job.width, job.height), target.path.stat().st_size)

        first, n = job.frame_range()
        sink = SINKS[target.kind](target.path, job.width, job.height, job.fps)
        bar = tqdm(total=n, desc=f"rendering {target.path.name or target.path}", unit="frame",
                   disable=job.quiet, leave=False, dynamic_ncols=True)
        kept = False
        with StopRequest() as stop:
            try:
                for k in scripted.frames(sim, first + n, job.fps, job.pulls):
                    if stop.requested:
                        break
                    if k < first:
                        continue
                    img = shoot()
                    with stop.deferred():
                        sink.write(img)
                    bar.update()
            except KeyboardInterrupt:  # a second Ctrl-C during a long frame
                stop.requested = True
            except BaseException:
                with stop.deferred():
                    bar.close()
                    if sink.count and not sink.broken:
                        sink.finish()
                        log(f"kept {sink.count} frame(s) in {target.path} before the error")
                    else:
                        sink.abort()
                raise
            with stop.deferred():
                bar.close()
                try:
                    kept = sink.finish()
                except BaseException:
                    sink.abort()
                    raise
            interrupted = stop.requested
        if kept and not interrupted and (stale := sink.stale()):
            log(f"note: {stale} older frame file(s) after {FRAME_NAME.format(sink.count - 1)} were left in "
                f"{target.path}")
        return RenderResult(sink.count, n, kept, interrupted, target.path, sink.size, sink.nbytes() if kept else 0)
