"""Checks of where ``treeanim render`` writes (``--out``) and of its ``--size``, before
anything is simulated: the kind of output from the name (:data:`.sinks.SUFFIX_KINDS`), and a
folder where files can really be created."""

from __future__ import annotations

import os
import re
import tempfile
from dataclasses import dataclass
from pathlib import Path

from ..errors import InputError
from .sinks import SUFFIX_KINDS, VIDEO_FORMATS

#: Image sides above this are refused (llvmpipe allows 16384, but memory runs out first).
MAX_SIDE = 8192

_SIZE = re.compile(r"^\s*(\d+)\s*[xX×]\s*(\d+)\s*$")


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
    """InputError unless ``path`` can be written as a file: ``text`` (the name as given) does
    not end in '/' (a folder's name, which ``Path`` would drop: ``x.gltf/`` wrote ``x.gltf``),
    its folder takes new files (:func:`check_folder`), its name fits the file system's limit,
    and it is not a folder."""
    path = Path(path)
    if text.endswith(("/", os.sep)):
        raise InputError(f"--out {text}: ends in '/', a folder's name; name a file (e.g. {path.name or 'out'})")
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
    kind = SUFFIX_KINDS.get(path.suffix.lower())
    if kind is None:
        videos = " or ".join(VIDEO_FORMATS)
        raise InputError(f"--out {text}: unknown extension {path.suffix or '(none)'!r}; expected {videos} "
                         f"(video), .png (one still) or a folder ending in / (PNG frames)")
    check_file(path, text)
    return Target(kind, path)
