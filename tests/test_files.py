"""Atomic writes (treeanim.files): the hidden temporary files a killed writer leaves behind are
removed by the next write of the same name, and nothing else is (issue 31)."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from treeanim import files
from treeanim.files import STALE_AGE, remove_stale, write_text


def _dead_pid() -> int:
    """A process id no process has: one past the kernel's largest."""
    try:
        return int(Path("/proc/sys/kernel/pid_max").read_text()) + 1
    except OSError:
        return 4_194_305  # Linux's largest pid_max, plus one


def _leave(folder: Path, name: str, age: float) -> Path:
    """A file named ``name`` in ``folder``, last changed ``age`` seconds ago."""
    p = folder / name
    p.write_bytes(b"half a file")
    t = time.time() - age
    os.utime(p, (t, t))
    return p


OLD = STALE_AGE + 60


def test_only_our_stale_temporary_files_of_that_name_are_removed(tmp_path):
    dead, me = _dead_pid(), os.getpid()
    stale = [
        _leave(tmp_path, f".x.gltf.{dead}.ab_cd012.part", OLD),  # its writer is gone, long unchanged
        _leave(tmp_path, f".x.gltf.{dead}.zz9zz9zz.part.png", OLD),  # with a writer's suffix
        _leave(tmp_path, ".x.gltf.k3j4h5g6.part", OLD),  # named before the pid was added
    ]
    kept = [
        _leave(tmp_path, f".x.gltf.{dead}.abcdefgh.part", 5.0),  # changed a moment ago: may be written elsewhere
        _leave(tmp_path, f".x.gltf.{me}.abcdefgh.part", OLD),  # its writer runs (this process)
        _leave(tmp_path, f".y.gltf.{dead}.abcdefgh.part", OLD),  # another target's
        _leave(tmp_path, ".x.gltf.notes", OLD),  # the user's own hidden files
        _leave(tmp_path, f".x.gltf.{dead}.abcdefgh.part.bak~", OLD),
        _leave(tmp_path, f"x.gltf.{dead}.abcdefgh.part", OLD),  # not hidden: not ours
        _leave(tmp_path, "x.gltf", OLD),
    ]
    (tmp_path / f".x.gltf.{dead}.abcdefgh.part.d").mkdir()  # a folder is never removed
    kept.append(tmp_path / f".x.gltf.{dead}.abcdefgh.part.d")
    assert remove_stale(tmp_path, "x.gltf") == len(stale)
    assert not any(p.exists() for p in stale)
    assert all(p.exists() for p in kept)
    assert remove_stale(tmp_path / "missing", "x.gltf") == 0  # a folder that cannot be listed: nothing


def test_the_next_write_removes_what_a_killed_writer_left(tmp_path):
    """A writer killed (SIGKILL) inside atomic_path leaves its temporary file; the next write of
    that name, once the file is old, removes it."""
    target = tmp_path / "settings.toml"
    code = ("import os, signal, sys\nfrom treeanim.files import atomic_path\n"
            "with atomic_path(sys.argv[1], '.toml') as tmp:\n"
            "    tmp.write_text('half')\n    os.kill(os.getpid(), signal.SIGKILL)\n")
    res = subprocess.run([sys.executable, "-c", code, str(target)], timeout=120)
    assert res.returncode == -signal.SIGKILL
    left = [p for p in tmp_path.iterdir()]
    assert len(left) == 1 and left[0].name.startswith(".settings.toml.") and left[0].name.endswith(".part.toml")
    write_text(target, "fresh\n")  # a minute later: kept (its age is the guard)
    assert left[0].exists()
    os.utime(left[0], (time.time() - OLD,) * 2)
    write_text(target, "again\n")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["settings.toml"]
    assert target.read_text() == "again\n"


def test_a_write_in_progress_is_never_removed(tmp_path):
    target = tmp_path / "a.csv"
    with files.atomic_path(target, ".csv") as tmp:
        tmp.write_text("mine")
        os.utime(tmp, (time.time() - OLD,) * 2)  # however old: this process writes it
        write_text(target, "another writer's\n")
        assert tmp.exists() and str(os.getpid()) in tmp.name
    assert target.read_text() == "mine"


def test_a_frames_folder_and_a_gltf_buffer_clean_their_own(tmp_path):
    import pygltflib as gl

    from treeanim.export import write_gltf
    from treeanim.offline.sinks import FrameSink

    dead = _dead_pid()
    frame_part = _leave(tmp_path, f".frame_00007.png.{dead}.abcdefgh.part.png", OLD)
    other = _leave(tmp_path, f".notes.png.{dead}.abcdefgh.part.png", OLD)
    sink = FrameSink(tmp_path, 4, 2)
    sink.write(np.zeros((2, 4, 3), np.uint8))
    assert sink.finish() and not frame_part.exists() and other.exists()

    bin_part = _leave(tmp_path, f".tree-0123abcd.bin.{dead}.abcdefgh.part", OLD)  # a killed export's buffer
    doc = gl.GLTF2(buffers=[gl.Buffer(byteLength=3)])
    written = write_gltf(tmp_path / "tree.gltf", doc, b"abc")
    assert not bin_part.exists() and all(p.exists() for p in written)


@pytest.mark.parametrize("name", ["a" * 250 + ".png", "plain"])
def test_the_temporary_name_fits_and_carries_the_pid(tmp_path, name):
    tmp = files.temp_beside(tmp_path / name, ".png")
    assert len(tmp.name) < 255 and f".{os.getpid()}." in tmp.name and tmp.name.endswith(".part.png")
    os.utime(tmp, (time.time() - OLD,) * 2)
    assert remove_stale(tmp_path, name) == 0  # ours, and we run
