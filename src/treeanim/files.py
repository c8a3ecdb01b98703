"""Atomic file writes: a hidden temporary file beside the target, renamed over it when done.

The temporary file is named ``.NAME.PID.XXXXXXXX.part[.SUFFIX]`` (the target's name, the
writing process's id, eight random characters). A process killed mid-write (SIGKILL, a power
cut) leaves it behind; the next write of the same name removes those of its stale ones
(:func:`remove_stale`).
"""

from __future__ import annotations

import contextlib
import os
import re
import tempfile
import time
from pathlib import Path
from typing import Iterator

#: A temporary file is stale once the process that made it no longer runs and the file has
#: not changed for this long (s). The process id decides on this machine; the age guards a
#: writer whose id means nothing here (another machine or container sharing the folder): its
#: file grows as it writes, except a GIF being encoded (ffmpeg writes it only at the end).
STALE_AGE = 600.0


def _umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def _stem(path: Path) -> str:
    # The name's first 100 characters: a name near the 255-byte limit leaves room for the rest
    return path.name[:100]


def _alive(pid: int) -> bool:
    """Whether process ``pid`` runs on this machine (one of another user's counts as running)."""
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OverflowError, ValueError):
        return pid > 0
    return True


def remove_stale(folder: str | Path, name: str, now: float | None = None) -> int:
    """Remove the temporary files of :func:`temp_beside` left in ``folder`` by writers of
    ``name`` that were killed mid-write.

    Only files of our naming pattern for that name are touched, and only stale ones: the
    process that made it no longer runs (names without a process id, from before it was
    added, count as gone) and the file has not changed for :data:`STALE_AGE` seconds.
    Anything that cannot be listed or removed is left alone.

    Parameters
    ----------
    folder : str or Path
    name : str
        The target's file name, or a regular expression for it (a compiled ``re.Pattern``:
        e.g. every frame file of a folder).
    now : float, optional
        The time to judge ages by (default: the current time).

    Returns
    -------
    int
        How many files were removed.
    """
    stem = name.pattern if isinstance(name, re.Pattern) else re.escape(_stem(Path(name)))
    pattern = re.compile(rf"\.(?:{stem})\.(?:(\d{{1,10}})\.)?[a-z0-9_]{{8}}\.part(?:\.[A-Za-z0-9]{{1,8}})?")
    now = time.time() if now is None else now
    removed = 0
    try:
        entries = list(os.scandir(folder or "."))
    except OSError:
        return 0
    for entry in entries:
        m = pattern.fullmatch(entry.name)
        if m is None or (m.group(1) is not None and _alive(int(m.group(1)))):
            continue
        try:
            info = entry.stat(follow_symlinks=False)
            if entry.is_file(follow_symlinks=False) and now - info.st_mtime >= STALE_AGE:
                os.unlink(entry.path)
                removed += 1
        except OSError:
            pass
    return removed


def temp_beside(path: str | Path, suffix: str = "", clean: bool = True) -> Path:
    """A new hidden, empty file beside ``path`` (same folder, so a rename replaces ``path`` at
    once), with the permissions a plain new file would get.

    Parameters
    ----------
    path : str or Path
        The file it will replace.
    suffix : str
        Ending of the temporary name.
    clean : bool
        First remove the stale temporary files of ``path`` (:func:`remove_stale`).
    """
    path = Path(path)
    if clean:
        remove_stale(path.parent, path.name)
    fd, name = tempfile.mkstemp(prefix=f".{_stem(path)}.{os.getpid()}.", suffix=f".part{suffix}", dir=path.parent)
    try:
        os.fchmod(fd, 0o666 & ~_umask())
    finally:
        os.close(fd)
    return Path(name)


@contextlib.contextmanager
def atomic_path(path: str | Path, suffix: str = "", clean: bool = True) -> Iterator[Path]:
    """Yield a temporary path to write; on success it is renamed over ``path``, on any error
    (Ctrl-C included) it is removed, so ``path`` is never left half-written. An OSError of the
    write (a full disk) is raised again naming ``path``.

    Parameters
    ----------
    path : str or Path
        The file to (re)place.
    suffix : str
        Ending of the temporary name (some writers pick the format from it, e.g. ``'.mp4'``).
    clean : bool
        First remove the stale temporary files a killed writer of ``path`` left
        (:func:`remove_stale`).
    """
    tmp = temp_beside(path, suffix, clean=clean)
    try:
        yield tmp
        os.replace(tmp, path)
    except OSError as e:
        tmp.unlink(missing_ok=True)
        if e.filename is None or Path(e.filename) == tmp:  # name the file meant, not the temporary one
            raise OSError(e.errno, e.strerror or str(e), str(path)) from e
        raise
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise


def write_bytes(path: str | Path, data: bytes) -> None:
    """Write ``data`` to ``path`` atomically."""
    with atomic_path(path) as tmp:
        tmp.write_bytes(data)


def write_text(path: str | Path, text: str) -> None:
    """Write ``text`` (UTF-8) to ``path`` atomically."""
    write_bytes(path, text.encode("utf-8"))
