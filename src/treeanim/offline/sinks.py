"""Where rendered frames go: a video (:class:`VideoSink`, one entry of :data:`VIDEO_FORMATS`
per file suffix), a folder of PNG frames (:class:`FrameSink`) or one PNG (:func:`write_png`).

:data:`SUFFIX_KINDS` says what an ``--out`` name's suffix makes (a new format is one entry in
:data:`VIDEO_FORMATS`), :data:`SINKS` which sink writes each kind's frames. Every sink has
``write(img)``, ``finish() -> kept``, ``abort()``, ``count``, ``size``, ``broken``,
``nbytes()`` and ``stale()``.
"""

from __future__ import annotations

import errno
import os
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import InputError
from ..files import atomic_path, remove_stale, temp_beside

#: Name pattern of the frames written into a folder.
FRAME_NAME = "frame_{:05d}.png"
#: Any frame file's name (whose stale temporary files a new run removes once, not per frame).
FRAME_RE = re.compile(r"frame_\d{5,}\.png")
#: The still's extension.
STILL_SUFFIX = ".png"


@dataclass(frozen=True)
class VideoFormat:
    """How imageio-ffmpeg encodes one video format.

    Attributes
    ----------
    codec, pix_fmt : str
        ffmpeg's encoder and output pixel format.
    params : tuple of str
        Further ffmpeg output options.
    even : bool
        The pixel format needs even sides: odd frames are padded (:func:`pad_even`).
    """

    codec: str
    pix_fmt: str
    params: tuple[str, ...]
    even: bool = False


#: Video formats by file suffix: H.264 MP4 (yuv420p, CRF 18, playable while it streams), and
#: GIF with one palette for the whole clip.
VIDEO_FORMATS = {
    ".mp4": VideoFormat("libx264", "yuv420p", ("-crf", "18", "-preset", "medium", "-movflags", "+faststart"),
                        even=True),
    ".gif": VideoFormat("gif", "pal8", ("-vf", "split[a][b];[a]palettegen=stats_mode=full[p];"
                                               "[b][p]paletteuse=dither=bayer:bayer_scale=4", "-loop", "0")),
}
#: What ``--out NAME.SUFFIX`` makes ('video' or 'still'); a folder (or a new name with no
#: suffix) is 'frames'.
SUFFIX_KINDS = {**dict.fromkeys(VIDEO_FORMATS, "video"), STILL_SUFFIX: "still"}


def pad_even(img: np.ndarray) -> np.ndarray:
    """``img`` (H, W, 3) padded to even sides by repeating its last row / column (yuv420p
    video needs even sizes)."""
    h, w = img.shape[:2]
    if h % 2 == 0 and w % 2 == 0:
        return img
    return np.pad(img, ((0, h % 2), (0, w % 2), (0, 0)), mode="edge")


class Encoder:
    """One ffmpeg process encoding raw RGB frames from its standard input into a file.

    ffmpeg's own messages go to a temporary file, never to our standard error: when it fails
    (a full disk) :meth:`reason` reads back why, and the caller says so in one line of its own.
    It runs in its own session, so a Ctrl-C at the terminal reaches only us.

    Parameters
    ----------
    path : Path
        The file ffmpeg writes (its suffix picks the container).
    size : (int, int)
        Width and height of every frame.
    fps : float
    fmt : VideoFormat
    """

    def __init__(self, path: Path, size: tuple[int, int], fps: float, fmt: VideoFormat) -> None:
        import subprocess
        import tempfile
        from fractions import Fraction

        import imageio_ffmpeg

        w, h = size
        cmd = [imageio_ffmpeg.get_ffmpeg_exe(), "-hide_banner", "-nostats", "-loglevel", "error", "-y",
               "-f", "rawvideo", "-vcodec", "rawvideo", "-s", f"{w}x{h}", "-pix_fmt", "rgb24",
               "-r", str(Fraction(float(fps)).limit_denominator()), "-i", "-", "-an",
               "-vcodec", fmt.codec, "-pix_fmt", fmt.pix_fmt, *fmt.params, str(path)]
        try:
            self.log = tempfile.TemporaryFile()
        except OSError:  # no room for even that: ffmpeg's messages are dropped
            self.log = None
        try:
            self.proc = subprocess.Popen(cmd, stdin=subprocess.PIPE, stdout=subprocess.DEVNULL,
                                         stderr=self.log if self.log is not None else subprocess.DEVNULL,
                                         start_new_session=True)
        except BaseException:
            self._close_log()
            raise

    def write(self, img: np.ndarray) -> bool:
        """Send one (height, width, 3) uint8 frame; False if ffmpeg is gone (it failed)."""
        try:
            self.proc.stdin.write(np.ascontiguousarray(img, np.uint8))
        except (OSError, ValueError):  # a broken pipe: ffmpeg exited
            return False
        return True

    def close(self) -> int:
        """End of input: wait for ffmpeg to finish the file; its exit status (0: done)."""
        try:
            self.proc.stdin.close()  # flushes: fails where ffmpeg has already gone
        except (OSError, ValueError):
            pass
        return self.proc.wait()

    def kill(self) -> None:
        """Stop ffmpeg at once (no trailer) and drop its messages."""
        self.proc.kill()
        try:
            self.proc.stdin.close()
        except (OSError, ValueError):
            pass
        self.proc.wait()
        self._close_log()

    def reason(self, most: int = 120) -> str:
        """ffmpeg's first message, without its ``[muxer @ 0x…]`` tag, on one line of at most
        ``most`` characters ('' if it said nothing)."""
        if self.log is None:
            return ""
        try:
            self.log.seek(0)
            text = self.log.read(16384).decode("utf-8", "replace")
        except (OSError, ValueError):
            return ""
        for line in text.splitlines():
            line = re.sub(r"^(\[[^\]]*\]\s*)+", "", line).strip()
            if line:
                return line if len(line) <= most else line[:most - 1] + "…"
        return ""

    def _close_log(self) -> None:
        if self.log is not None:
            self.log.close()
            self.log = None


class VideoSink:
    """Frames into an .mp4 (H.264, yuv420p, CRF 18) or a .gif (one palette for the whole clip)
    through ffmpeg (:class:`Encoder`), via a temporary file renamed over ``path`` by
    :meth:`finish`.

    The format is :data:`VIDEO_FORMATS` [the suffix]; frames of odd width or height are padded
    to even by repeating the last row/column where it needs even sides (MP4). ffmpeg's own
    messages never reach the terminal: a failure is one OSError naming ``path`` and ffmpeg's
    reason (``No space left on device``).

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
        self.path = Path(path)
        self.format = VIDEO_FORMATS.get(self.path.suffix.lower())
        if self.format is None:
            raise InputError(f"unknown video format {self.path.suffix!r}")
        self.count = 0
        self.broken = False
        even = self.format.even
        self.size = (width + width % 2, height + height % 2) if even else (width, height)
        self.tmp = temp_beside(self.path, self.path.suffix.lower())
        try:
            self._enc = Encoder(self.tmp, self.size, fps, self.format)
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
        OSError
            ffmpeg failed (naming ``path`` and why); the sink is then :attr:`broken` and its
            file is not kept.
        """
        if self.format.even:
            img = pad_even(img)
        if not self._enc.write(img):
            self._enc.close()
            raise self._failed(self._enc)
        self.count += 1

    def finish(self) -> bool:
        """Close the encoder; keep the file (renamed to ``path``) if it holds a frame. Returns
        whether it was kept."""
        if self.count == 0:
            self.abort()
            return False
        enc, self._enc = self._enc, None
        try:
            if enc is not None:
                if enc.close() != 0:  # ffmpeg gets EOF and writes the trailer (a playable file)
                    raise self._failed(enc)
                self._check(enc)
        except BaseException:
            self.tmp.unlink(missing_ok=True)
            raise
        finally:
            if enc is not None:
                enc.kill()  # (it has exited: this only drops its messages)
        os.replace(self.tmp, self.path)
        return True

    def nbytes(self) -> int:
        """Bytes of the file :meth:`finish` kept."""
        return self.path.stat().st_size

    def stale(self) -> int:
        """Older files this run left beside its own (none: a video replaces the file)."""
        return 0

    def _failed(self, enc: Encoder) -> OSError:
        """The one error of a failed encoder: the file named, ffmpeg's reason if it gave one."""
        self.broken = True
        why = enc.reason()
        what = f"the video encoder failed ({why})" if why else \
            "the video encoder could not finish it (is the disk full?)"
        return OSError(errno.EIO, f"{what}; any previous file is kept", str(self.path))

    def _check(self, enc: Encoder) -> None:
        """OSError unless the file ffmpeg wrote holds every frame (an encoder that exited 0
        yet wrote a truncated file)."""
        import imageio_ffmpeg

        try:
            frames, _ = imageio_ffmpeg.count_frames_and_secs(str(self.tmp))
        except Exception:  # noqa: BLE001 - ffmpeg cannot read it back: it is broken
            frames = -1
        if frames != self.count:
            raise self._failed(enc)

    def abort(self) -> None:
        """Stop the encoder and drop the file, quietly."""
        enc, self._enc = self._enc, None
        if enc is not None:
            enc.kill()
        self.tmp.unlink(missing_ok=True)


def write_png(path: Path, img: np.ndarray, clean: bool = True) -> None:
    """One PNG, written beside ``path`` and renamed over it (never a half-written file);
    ``clean``: first remove the stale temporary files of ``path`` (:func:`~treeanim.files.remove_stale`)."""
    import imageio.v3 as iio

    with atomic_path(path, ".png", clean=clean) as tmp:
        iio.imwrite(tmp, img, extension=".png")


class FrameSink:
    """Frames as ``frame_00000.png`` … in a folder (created if new; removed again if no frame
    was written into it)."""

    broken = False  # each frame file is complete once written: there is nothing to drop

    def __init__(self, folder: Path, width: int, height: int, fps: float = 0.0) -> None:
        self.path = Path(folder)
        self.size = (int(width), int(height))
        self.created = not self.path.exists()
        self.path.mkdir(exist_ok=True)
        remove_stale(self.path, FRAME_RE)  # once for every frame name (not a folder scan per frame)
        self.count = 0

    def write(self, img: np.ndarray) -> None:
        """Write ``img`` ((height, width, 3) uint8, row 0 at the top) as the next frame file."""
        write_png(self.path / FRAME_NAME.format(self.count), img, clean=False)
        self.count += 1

    def nbytes(self) -> int:
        """Bytes of the frame files written by this run."""
        return sum((self.path / FRAME_NAME.format(i)).stat().st_size for i in range(self.count))

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


#: The sink that writes the frames of each kind of target (a still is one :func:`write_png`).
SINKS = {"video": VideoSink, "frames": FrameSink}
