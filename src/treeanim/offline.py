"""Offline output for the command line: videos, PNG frames and stills (``treeanim render``),
pull-and-release tip traces (``treeanim trace``) and the Table 1 benchmark (``treeanim bench``).

Everything renders through :class:`treeanim.render.offscreen.OffscreenRenderer` (EGL, Mesa
llvmpipe where there is no GPU) and writes through imageio / imageio-ffmpeg.

Files are written safely (:mod:`treeanim.files`): a video goes to a hidden temporary file
beside the target and is renamed over it once finished (or once interrupted, if at least one
frame was encoded), and every PNG, CSV, plot and JSON file is written beside its name and
renamed, so an interrupted or failed run leaves either nothing or a complete, playable file.
"""

from __future__ import annotations

import contextlib
import errno
import math
import os
import platform
import re
import signal
import statistics
import tempfile
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .errors import GLUnavailable, InputError
from .files import atomic_path, temp_beside
from .files import write_text as write_text  # re-exported: the command line writes its JSON through it
from .table1 import ROWS, TABLE1, TABLE1_FPS

#: Image sides above this are refused (llvmpipe allows 16384, but memory runs out first).
MAX_SIDE = 8192
#: Seconds simulated before a still when no --seconds is given.
STILL_SECONDS = 2.0
#: Video and frame-folder extensions, and the still's.
VIDEO_SUFFIXES = (".mp4", ".gif")
STILL_SUFFIX = ".png"
#: Name pattern of the frames written into a folder.
FRAME_NAME = "frame_{:05d}.png"

_SIZE = re.compile(r"^\s*(\d+)\s*[xX×]\s*(\d+)\s*$")


@contextlib.contextmanager
def offscreen(width: int, height: int, samples: int):
    """An :class:`OffscreenRenderer` on its own EGL context, released on exit; GLUnavailable
    if there is no context to be had."""
    from .render.offscreen import OffscreenRenderer, create_egl_context

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


# ============================================================================ input
def parse_size(text: str) -> tuple[int, int]:
    """``'WxH'`` as two positive ints (at most :data:`MAX_SIDE`); InputError otherwise."""
    m = _SIZE.match(text)
    if not m:
        raise InputError(f"expected WIDTHxHEIGHT in pixels, e.g. 1280x720, got {text!r}")
    w, h = int(m.group(1)), int(m.group(2))
    if w < 1 or h < 1:
        raise InputError(f"width and height must be at least 1 pixel, got {text!r}")
    if w > MAX_SIDE or h > MAX_SIDE:
        raise InputError(f"width and height must be at most {MAX_SIDE} pixels, got {text!r}")
    return w, h


@dataclass(frozen=True)
class Target:
    """Where ``treeanim render`` writes: ``kind`` is 'video' (.mp4/.gif), 'frames' (a folder
    of PNG frames) or 'still' (one .png)."""

    kind: str
    path: Path


def check_folder(folder: Path, text: str) -> None:
    """InputError unless files can be created in ``folder`` (tried for real: permissions alone
    say nothing for root or on special file systems)."""
    folder = Path(folder) if str(folder) else Path(".")
    if not folder.is_dir():
        raise InputError(f"--out {text}: folder {folder} does not exist")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise InputError(f"--out {text}: folder {folder} is not writable")
    try:
        fd, probe = tempfile.mkstemp(prefix=".treeanim-probe.", dir=folder)
        os.close(fd)
        os.unlink(probe)
    except OSError as e:
        raise InputError(f"--out {text}: cannot create files in {folder} ({e.strerror or e})") from None


def _exists(path: Path, folder: bool = False) -> bool:
    """Whether ``path`` exists (as a folder), False where the name cannot be looked up (too long)."""
    try:
        return path.is_dir() if folder else path.exists()
    except OSError:
        return False


def check_file(path: Path, text: str) -> None:
    """InputError unless ``path`` can be written as a file: its folder takes new files
    (:func:`check_folder`), its name fits the file system's limit, and it is not a folder."""
    path = Path(path)
    folder = path.parent if str(path.parent) else Path(".")
    check_folder(folder, text)
    try:
        most = os.pathconf(folder, "PC_NAME_MAX")
    except (OSError, ValueError):
        most = 255
    size = len(os.fsencode(path.name))
    if size > most:
        raise InputError(f"--out {text[:60]}…: the file name is {size} bytes long; at most {most}")
    if _exists(path, folder=True):
        raise InputError(f"--out {text}: {path} is a folder; name a file")


def render_target(text: str) -> Target:
    """Classify and check ``--out``: a .mp4 or .gif video, a .png still, or a folder of frames
    (a path ending in '/', an existing folder, or a new name with no extension).

    Raises
    ------
    InputError
        Unknown extension, a missing or unwritable folder, or a file where a folder is meant.
    """
    if not text.strip():
        raise InputError("--out is empty")
    path = Path(text)
    exists, is_folder = _exists(path), _exists(path, folder=True)
    if text.endswith(("/", os.sep)) or is_folder or (path.suffix == "" and not exists):
        if exists and not is_folder:
            raise InputError(f"--out {text}: {path} exists and is not a folder")
        if is_folder:
            check_folder(path, text)
        else:
            check_folder(path.parent, text)
        return Target("frames", path)
    suffix = path.suffix.lower()
    if suffix not in VIDEO_SUFFIXES + (STILL_SUFFIX,):
        raise InputError(f"--out {text}: unknown extension {path.suffix or '(none)'!r}; expected .mp4 or .gif "
                         f"(video), .png (one still) or a folder ending in / (PNG frames)")
    check_file(path, text)
    return Target("video" if suffix in VIDEO_SUFFIXES else "still", path)


# ============================================================================ camera
def default_elevation(tree) -> float:
    """Degrees: low for trees (a person's view), higher for flat scenes such as grass."""
    P = tree.rest_positions
    ext = P.max(axis=0) - P.min(axis=0)
    return 25.0 if ext[1] < 0.3 * max(ext[0], ext[2]) else 2.0


def framed_camera(tree, width: int, height: int, azimuth: float = 0.0, elevation: float | None = None,
                  distance: float | None = None, present=None, margin: float = 1.12):
    """An :class:`OrbitCamera` looking at ``tree`` from ``azimuth`` / ``elevation`` (degrees).

    The target and distance are chosen so that the tree's rest nodes (those of the ``present``
    objects; leaves padded by their lamina) fill the ``width`` × ``height`` view, centred, with
    ``margin`` to spare; ``distance`` (metres) overrides the distance only.
    """
    from .render.camera import OrbitCamera

    if elevation is None:
        elevation = default_elevation(tree)
    cam = OrbitCamera(azimuth=azimuth, elevation=elevation)
    P = np.asarray(tree.rest_positions, float)
    pad = np.zeros(len(P))
    if len(getattr(tree, "lamina_length", ())):
        pad = np.asarray(tree.lamina_length, float)[tree.node_object]
    pad = pad + 0.5 * np.asarray(tree.node_diameter, float)
    if present is not None:
        keep = np.repeat(np.asarray(present, bool), tree.object_count)
        if keep.any():
            P, pad = P[keep], pad[keep]
    lo, hi = P.min(axis=0), P.max(axis=0)
    cam.target = 0.5 * (lo + hi)
    tan_y = math.tan(math.radians(cam.fov_y) / 2)
    tan_x = tan_y * width / max(height, 1)
    right, up, fwd = cam.right, cam.up, cam.forward
    D = float(np.max(hi - lo)) or 1.0
    for _ in range(6):
        rel = P - cam.target
        a, u, d = rel @ right, rel @ up, rel @ fwd
        need = np.maximum(margin * (np.abs(a) + pad) / tan_x, margin * (np.abs(u) + pad) / tan_y) - d
        D = max(float(need.max()), 1e-3)
        # Centre the tree's image: shift the target by the middle of its projected extents.
        depth = D + d
        x, y = a / (depth * tan_x), u / (depth * tan_y)
        px, py = pad / (depth * tan_x), pad / (depth * tan_y)
        sx = 0.5 * (float((x + px).max()) + float((x - px).min()))
        sy = 0.5 * (float((y + py).max()) + float((y - py).min()))
        if abs(sx) < 1e-4 and abs(sy) < 1e-4:
            break
        cam.target = cam.target + sx * D * tan_x * right + sy * D * tan_y * up
    cam.distance = float(distance) if distance is not None else D
    return cam


# ============================================================================ writers
def pad_even(img: np.ndarray) -> np.ndarray:
    """``img`` (H, W, 3) padded to even sides by repeating its last row / column (yuv420p
    video needs even sizes)."""
    h, w = img.shape[:2]
    if h % 2 == 0 and w % 2 == 0:
        return img
    return np.pad(img, ((0, h % 2), (0, w % 2), (0, 0)), mode="edge")


class _Abort(BaseException):
    """Thrown into imageio-ffmpeg's writer to make it kill ffmpeg rather than finish the file."""


class VideoSink:
    """Frames into an .mp4 (H.264, yuv420p, CRF 18) or a .gif (one palette for the whole clip)
    through imageio-ffmpeg, via a temporary file renamed over ``path`` by :meth:`finish`.

    MP4 frames of odd width or height are padded to even by repeating the last row/column.

    The temporary file comes from :func:`treeanim.files.temp_beside` rather than
    :func:`~treeanim.files.atomic_path`: an interrupted render keeps the frames encoded so far
    (:meth:`finish` renames them into place), which "remove on any error" would throw away.

    Attributes
    ----------
    path : Path
        The video's final name.
    tmp : Path
        The hidden temporary file ffmpeg writes to.
    size : (int, int)
        Width and height encoded (an MP4's odd sides padded to even).
    count : int
        Frames encoded so far.
    broken : bool
        ffmpeg failed: the file is dropped, never kept.
    """

    def __init__(self, path: Path, width: int, height: int, fps: float) -> None:
        import imageio_ffmpeg

        self.path = Path(path)
        self.format = self.path.suffix.lower()[1:]
        self.count = 0
        self.broken = False
        if self.format == "mp4":
            self.size = (width + width % 2, height + height % 2)
            kw = dict(codec="libx264", pix_fmt_out="yuv420p", quality=None,
                      output_params=["-crf", "18", "-preset", "medium", "-movflags", "+faststart"])
        elif self.format == "gif":
            self.size = (width, height)
            kw = dict(codec="gif", pix_fmt_out="pal8", quality=None,
                      output_params=["-vf", "split[a][b];[a]palettegen=stats_mode=full[p];"
                                            "[b][p]paletteuse=dither=bayer:bayer_scale=4", "-loop", "0"])
        else:
            raise InputError(f"unknown video format {self.path.suffix!r}")
        self.tmp = temp_beside(self.path, self.path.suffix.lower())
        try:
            self._gen = imageio_ffmpeg.write_frames(str(self.tmp), self.size, fps=float(fps), macro_block_size=1,
                                                    ffmpeg_log_level="error", **kw)
            self._gen.send(None)  # starts ffmpeg
        except BaseException:
            self.tmp.unlink(missing_ok=True)
            raise

    def write(self, img: np.ndarray) -> None:
        """Encode one frame.

        Parameters
        ----------
        img : (height, width, 3) uint8
            The frame, row 0 at the top, of the size given to the constructor (an MP4's odd
            side is padded here).

        Raises
        ------
        Exception
            Whatever ffmpeg's writer raised; the sink is then :attr:`broken` and its file is
            not kept.
        """
        if self.format == "mp4":
            img = pad_even(img)
        try:
            self._gen.send(np.ascontiguousarray(img))
        except Exception:
            self.broken = True  # ffmpeg failed: the file is not worth keeping
            raise
        self.count += 1

    def finish(self) -> bool:
        """Close the encoder; keep the file (renamed to ``path``) if it holds a frame. Returns
        whether it was kept."""
        if self.count == 0:
            self.abort()
            return False
        gen, self._gen = self._gen, None
        try:
            if gen is not None:
                gen.close()  # ffmpeg gets EOF and writes the trailer (a playable file)
            self._check()
        except BaseException:
            self.tmp.unlink(missing_ok=True)
            raise
        os.replace(self.tmp, self.path)
        return True

    def _check(self) -> None:
        """OSError unless the file ffmpeg wrote holds every frame: imageio-ffmpeg does not report
        an encoder that died on a write error (a full disk), which leaves a truncated file."""
        import imageio_ffmpeg

        try:
            frames, _ = imageio_ffmpeg.count_frames_and_secs(str(self.tmp))
        except Exception:  # noqa: BLE001 - ffmpeg cannot read it back: it is broken
            frames = -1
        if frames != self.count:
            self.broken = True
            raise OSError(errno.EIO, "the video encoder could not finish it (is the disk full?); "
                                     "any previous file is kept", str(self.path))

    def abort(self) -> None:
        """Stop the encoder and drop the file, quietly."""
        import logging

        gen, self._gen = self._gen, None
        if gen is not None:
            log = logging.getLogger("imageio_ffmpeg")
            level = log.level
            log.setLevel(logging.CRITICAL)  # not "no frames have been written"
            try:
                gen.throw(_Abort())  # a BaseException: imageio-ffmpeg kills ffmpeg, no trailer
            except BaseException:
                pass
            finally:
                log.setLevel(level)
        self.tmp.unlink(missing_ok=True)


def write_png(path: Path, img: np.ndarray) -> None:
    """One PNG, written beside ``path`` and renamed over it (never a half-written file)."""
    import imageio.v3 as iio

    with atomic_path(path, ".png") as tmp:
        iio.imwrite(tmp, img, extension=".png")


class FrameSink:
    """Frames as ``frame_00000.png`` … in a folder (created if new; removed again if no frame
    was written into it)."""

    def __init__(self, folder: Path) -> None:
        self.path = Path(folder)
        self.created = not self.path.exists()
        self.path.mkdir(exist_ok=True)
        self.count = 0
        self.format = "png"

    def write(self, img: np.ndarray) -> None:
        """Write ``img`` ((height, width, 3) uint8, row 0 at the top) as the next frame file."""
        write_png(self.path / FRAME_NAME.format(self.count), img)
        self.count += 1

    def stale(self) -> int:
        """Older frame files past the ones written by this run."""
        n = 0
        while (self.path / FRAME_NAME.format(self.count + n)).exists():
            n += 1
        return n

    def finish(self) -> bool:
        """End the run: a folder this sink created is removed again if no frame went into it.

        Returns
        -------
        bool
            Whether any frame was written (the frames are kept either way; each file is
            complete as soon as :meth:`write` returns).
        """
        if self.count == 0 and self.created:
            try:
                self.path.rmdir()
            except OSError:
                pass
            return False
        return self.count > 0

    abort = finish


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


# ============================================================================ render
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

    from . import scripted

    target = job.target
    with offscreen(job.width, job.height, job.samples) as off:
        off.load(tree)
        cam = framed_camera(tree, job.width, job.height, job.azimuth, job.elevation, job.distance,
                            present=sim.shown)

        def shoot() -> np.ndarray:
            off.update(sim.positions, sim.rotations, sim.shown)
            return off.render(cam, season=job.season)

        if target.kind == "still":
            T = job.start + job.seconds
            for _ in scripted.frames(sim, 2 * T, 1 / max(T, 1e-9), job.pulls):  # frames at 0 and T (T > 0)
                pass
            write_png(target.path, shoot())
            return RenderResult(1, 1, True, False, target.path, (job.width, job.height), target.path.stat().st_size)

        first, n = job.frame_range()
        sink = VideoSink(target.path, job.width, job.height, job.fps) if target.kind == "video" \
            else FrameSink(target.path)
        bar = tqdm(total=n, desc=f"rendering {target.path.name or target.path}", unit="frame",
                   disable=job.quiet, leave=False, dynamic_ncols=True)
        kept = False
        with StopRequest() as stop:
            try:
                for k in scripted.frames(sim, (first + n) / job.fps, job.fps, job.pulls):
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
                    if sink.count and not getattr(sink, "broken", False):
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
        size = sink.size if isinstance(sink, VideoSink) else (job.width, job.height)
        if not kept:
            nbytes = 0
        elif target.kind == "video":
            nbytes = target.path.stat().st_size
        else:
            nbytes = sum((target.path / FRAME_NAME.format(i)).stat().st_size for i in range(sink.count))
        if kept and isinstance(sink, FrameSink) and not interrupted and (stale := sink.stale()):
            log(f"note: {stale} older frame file(s) after {FRAME_NAME.format(sink.count - 1)} were left in "
                f"{target.path}")
        return RenderResult(sink.count, n, kept, interrupted, target.path, size, nbytes)


# ============================================================================ trace
@dataclass
class TraceResult:
    """A tip trace after release: ``times`` (T,) from 0 at release, ``tips`` (T, 3) world."""

    times: np.ndarray
    tips: np.ndarray
    rest: np.ndarray
    held: np.ndarray
    obj: int
    kind: str
    f: np.ndarray
    zeta: np.ndarray


def run_trace(sim, obj: int, force, hold: float, seconds: float, rate: float) -> TraceResult:
    """Pull object ``obj``'s tip with ``force`` (N, world) for ``hold`` seconds (the held object
    sits at its static deflection; the rest of the tree settles), let go, and record the tip
    for ``seconds`` at ``rate`` samples per second.

    Raises
    ------
    InputError
        ``seconds`` or ``rate`` not finite and positive, or so small that fewer than 2 samples
        would follow the release (checked before anything is simulated).
    """
    from .physics.simulation import trace_tips

    for name, value in (("--seconds", seconds), ("--rate", rate)):
        if not (math.isfinite(value) and value > 0):
            raise InputError(f"{name} {value:g}: expected a positive number")
    samples = int(round(seconds * rate)) + 1  # trace_tips records the release and every step after it
    if samples < 2:
        raise InputError(f"--seconds {seconds:g} at --rate {rate:g} Hz gives {samples} sample after release; "
                         f"a trace needs at least 2 samples")
    dt = 1.0 / rate
    tree = sim.tree
    tip = int(tree.object_start[obj] + tree.object_count[obj] - 1)
    sim.pull(obj, np.asarray(force, float))
    for _ in range(max(1, int(round(hold / dt)))):
        sim.step(dt)
    held = sim.tip_position(obj)
    sim.release()
    times, tips = trace_tips(sim, [obj], seconds, dt)
    return TraceResult(times - times[0], tips[:, 0], np.asarray(tree.rest_positions[tip], float), held, obj,
                       str(tree.kind[obj]), np.array(sim.modes.f[obj], float), np.array(sim.modes.zeta[obj], float))


def write_trace_csv(path: Path, trace: TraceResult) -> None:
    """``t,x,y,z`` (seconds after release, world metres), written beside ``path`` and renamed."""
    data = np.column_stack([trace.times, trace.tips])
    with atomic_path(path, ".csv") as tmp:
        np.savetxt(tmp, data, delimiter=",", header="t,x,y,z", comments="", fmt=["%.6f", "%.9f", "%.9f", "%.9f"])


def plot_trace(path: Path, trace: TraceResult, title: str = "") -> None:
    """The horizontal trace of the tip (x–z displacement from rest, equal aspect), coloured by
    time after release, in the manner of the paper's Figs. 1 and 4."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.collections import LineCollection

    d = trace.tips - trace.rest
    x, z = d[:, 0] * 100, d[:, 2] * 100  # cm
    pts = np.column_stack([x, z])
    segs = np.stack([pts[:-1], pts[1:]], axis=1)
    t = trace.times
    fig, ax = plt.subplots(figsize=(6.4, 6.0), dpi=150)
    age = t[:-1] / max(t[-1], 1e-9)
    cmap = plt.get_cmap("viridis")
    colors = cmap(age)
    colors[:, 3] = 1.0 - 0.65 * age  # fade as it dies away
    lc = LineCollection(segs, colors=colors, linewidths=1.1, capstyle="round")
    ax.add_collection(lc)
    ax.plot([0], [0], "+", color="0.2", ms=12, mew=1.5, label="rest")
    ax.plot([x[0]], [z[0]], "o", color=cmap(0.0), ms=6, label="release")
    span = max(np.ptp(x), np.ptp(z), 1e-6)
    cx, cz = 0.5 * (x.max() + x.min()), 0.5 * (z.max() + z.min())
    half = 0.55 * span
    ax.set_xlim(cx - half, cx + half)
    ax.set_ylim(cz - half, cz + half)
    ax.set_aspect("equal")
    ax.set_xlabel("tip displacement x (cm)")
    ax.set_ylabel("tip displacement z (cm)")
    ax.grid(True, color="0.9", lw=0.6)
    ax.legend(loc="upper right", frameon=False, fontsize=8)
    sm = plt.cm.ScalarMappable(cmap=cmap, norm=plt.Normalize(0, t[-1]))
    fig.colorbar(sm, ax=ax, fraction=0.046, pad=0.04, label="time after release (s)")
    f, z_ = trace.f, trace.zeta
    sub = (f"object {trace.obj} ({trace.kind}): f u,v,w = {f[0]:.3f}, {f[1]:.3f}, {f[2]:.3f} Hz; "
           f"ζ = {z_[0]:.3f}, {z_[1]:.3f}, {z_[2]:.3f}")
    ax.set_title((title + "\n" if title else "") + sub, fontsize=9)
    fig.tight_layout()
    suffix = Path(path).suffix.lower()
    try:
        with atomic_path(path, suffix) as tmp:
            fig.savefig(tmp, format=suffix[1:])
    finally:
        plt.close(fig)


#: What to install for plots (``trace --plot`` and the examples), from the repository.
PLOTS_HINT = "needs matplotlib: .venv/bin/pip install -e '.[plots]' (from the repository)"


def zero_crossing_frequency(t: np.ndarray, x: np.ndarray) -> float:
    """Frequency (Hz) of an oscillating signal from its mean zero-crossing interval."""
    x = np.asarray(x, float)
    s = np.signbit(x)
    i = np.flatnonzero(s[1:] != s[:-1])
    if len(i) < 3:
        return float("nan")
    tz = t[i] - x[i] * (t[i + 1] - t[i]) / (x[i + 1] - x[i])
    return float(1.0 / (2.0 * np.mean(np.diff(tz))))


# ============================================================================ bench


def machine_info() -> dict:
    """CPU model, cores, OS and Python of this machine."""
    cpu = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.lower().startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    try:
        load = [round(x, 2) for x in os.getloadavg()]
    except OSError:
        load = None
    return {"cpu": cpu, "cores": os.cpu_count(), "system": f"{platform.system()} {platform.release()}",
            "python": platform.python_version(), "numpy": np.__version__, "load_average": load}


def bench_row(key: str, off, width: int, height: int, frames: int, steps: int, wind: float = 5.0,
              dt: float = 1 / 30, progress=None) -> dict:
    """One row of the benchmark: our counts, the paper's, and the medians in milliseconds."""
    import treeanim as ta

    preset, season = ROWS.get(key, (key, 0.0))
    tree = ta.load_preset(preset)
    stats = tree.stats(season)
    try:
        wind_field = ta.WindField(speed=wind, seed=0)
    except ValueError as e:
        raise InputError(f"--wind {wind:g}: {' '.join(str(e).split())}") from None
    sim = ta.Simulation(tree, wind=wind_field, season=season, seed=0)
    for _ in range(5):
        sim.step(dt)
    sim_ms = []
    for _ in range(steps):
        t0 = time.perf_counter()
        sim.step(dt)
        sim_ms.append((time.perf_counter() - t0) * 1e3)
        if progress:
            progress()
    off.resize(width, height)
    off.load(tree)
    cam = framed_camera(tree, width, height, present=sim.present)
    ren_ms = []
    for k in range(frames + 2):
        sim.step(dt)
        t0 = time.perf_counter()
        off.update(sim.positions, sim.rotations, sim.shown)
        off.render(cam, season=season)  # draws, resolves and reads the pixels back: the GPU is done
        if k >= 2:  # the first frames compile and upload
            ren_ms.append((time.perf_counter() - t0) * 1e3)
        if progress:
            progress()
    paper = TABLE1.get(key, [])
    s_ms, r_ms = statistics.median(sim_ms), statistics.median(ren_ms)
    return {
        "key": key, "preset": preset, "season": season,
        "objects": stats["objects"], "nodes": stats["nodes"], "triangles": stats["triangles"],
        "paper_objects": sum(r[1] for r in paper) or None,
        "paper_nodes": sum(r[2] for r in paper) or None,
        "paper_triangles": sum(r[3] for r in paper) or None,
        "sim_ms": s_ms, "sim_ms_p90": float(np.percentile(sim_ms, 90)), "sim_steps": steps, "dt": dt,
        "sim_ms_min": min(sim_ms),
        "render_ms": r_ms, "render_ms_p90": float(np.percentile(ren_ms, 90)), "render_ms_min": min(ren_ms),
        "render_frames": frames,
        "fps": 1000.0 / (s_ms + r_ms),
        "sim_fps": 1000.0 / s_ms,
        "paper_fps": TABLE1_FPS.get(key),
    }


def run_bench(keys, width: int = 1280, height: int = 720, frames: int = 20, steps: int = 200, samples: int = 4,
              wind: float = 5.0, quiet: bool = False) -> dict:
    """The Table 1 benchmark over ``keys`` (see :data:`treeanim.table1.ROWS`): a dict with the machine,
    the GL renderer and one row per key.

    Raises
    ------
    InputError
        ``wind`` outside 0 … :data:`treeanim.physics.wind.MAX_SPEED` (checked before the GL
        context is made or any tree is loaded).
    GLUnavailable
        No OpenGL context to render with.
    """
    import datetime

    from tqdm import tqdm

    from .physics.wind import MAX_SPEED

    if not (math.isfinite(wind) and 0.0 <= wind <= MAX_SPEED):
        raise InputError(f"--wind {wind:g}: expected a wind speed from 0 to {MAX_SPEED:g} m/s")

    started = datetime.datetime.now().astimezone().isoformat(timespec="seconds")
    machine = machine_info()
    with offscreen(width, height, samples) as off:
        with off.ctx:
            info = dict(off.ctx.info)
        bar = tqdm(total=len(keys) * (steps + frames + 2), desc="bench", unit="step", disable=quiet, leave=False)
        rows = []
        try:
            for key in keys:
                bar.set_description(f"bench {key}")
                rows.append(bench_row(key, off, width, height, frames, steps, wind=wind, progress=bar.update))
        finally:
            bar.close()
        samples_used = off.samples
    return {
        "date": started,
        "machine": machine,
        "gl_renderer": info.get("GL_RENDERER"), "gl_version": info.get("GL_VERSION"),
        "gl_vendor": info.get("GL_VENDOR"),
        "size": [width, height], "samples": samples_used, "wind": wind,
        "paper_machine": "Core2 Duo 2.8 GHz, GeForce 9500 GT (2012)",
        "rows": rows,
    }


def format_bench(result: dict) -> str:
    """The benchmark as a Markdown table with its machine line."""
    m = result["machine"]
    w, h = result["size"]
    lines = [
        f"{result['date']} — {m['cpu']}, {m['cores']} cores"
        + (f" (load {m['load_average'][0]:.2f} at start)" if m.get("load_average") else "")
        + f"; GL: {result['gl_renderer']} ({result['gl_version']}); {w}×{h}, {result['samples']}× MSAA; "
        f"wind {result['wind']:g} m/s",
        "",
        "| preset | objects (ours / paper) | nodes (ours / paper) | triangles (ours / paper) "
        "| sim ms/step | render ms/frame | FPS (ours / paper) |",
        "|---|---:|---:|---:|---:|---:|---:|",
    ]

    def pair(a, b):
        return f"{a:,} / {b:,}" if b else f"{a:,} / —"

    for r in result["rows"]:
        name = r["key"].replace("@winter", " (winter)") if "@" in r["key"] else \
            r["key"] + (" (summer)" if r["key"] == "large_cherry" else "")
        pf = r["paper_fps"]
        lines.append(
            f"| {name} | {pair(r['objects'], r['paper_objects'])} | {pair(r['nodes'], r['paper_nodes'])} "
            f"| {pair(r['triangles'], r['paper_triangles'])} | {r['sim_ms']:.1f} | {r['render_ms']:.1f} "
            f"| {r['fps']:.1f} / {pf if pf is not None else '—'} |")
    return "\n".join(lines)
