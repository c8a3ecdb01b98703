"""Atomic file writes: a hidden temporary file beside the target, renamed over it when done."""

from __future__ import annotations

import contextlib
import os
import tempfile
from pathlib import Path
from typing import Iterator


def _umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def temp_beside(path: str | Path, suffix: str = "") -> Path:
    """A new hidden, empty file beside ``path`` (same folder, so a rename replaces ``path`` at
    once), with the permissions a plain new file would get."""
    path = Path(path)
    # The name's first 100 characters: a name near the 255-byte limit leaves room for the rest
    fd, name = tempfile.mkstemp(prefix=f".{path.name[:100]}.", suffix=f".part{suffix}", dir=path.parent)
    try:
        os.fchmod(fd, 0o666 & ~_umask())
    finally:
        os.close(fd)
    return Path(name)


@contextlib.contextmanager
def atomic_path(path: str | Path, suffix: str = "") -> Iterator[Path]:
    """Yield a temporary path to write; on success it is renamed over ``path``, on any error
    (Ctrl-C included) it is removed, so ``path`` is never left half-written. An OSError of the
    write (a full disk) is raised again naming ``path``.

    Parameters
    ----------
    path : str or Path
        The file to (re)place.
    suffix : str
        Ending of the temporary name (some writers pick the format from it, e.g. ``'.mp4'``).
    """
    tmp = temp_beside(path, suffix)
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
