"""Preset mutations by hypothesis (issue #14): a mutated preset either loads and simulates to a
finite tree, or is refused with one line naming the file — never a traceback, a hang or
gigabytes of memory."""

from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np
import pytest
import tomlkit
from hypothesis import given, settings
from hypothesis import strategies as st

import treeanim as ta
from treeanim import PresetError

GOOD = tomllib.loads(Path(ta.load_preset("small_cherry").source).read_text())


def _paths(node, prefix=()):
    """Every key path of a parsed TOML document (into tables and arrays of tables)."""
    if isinstance(node, dict):
        for k, v in node.items():
            yield prefix + (k,)
            yield from _paths(v, prefix + (k,))
    elif isinstance(node, list) and node and all(isinstance(x, dict) for x in node):
        for i, x in enumerate(node):
            yield from _paths(x, prefix + (i,))


PATHS = sorted(_paths(GOOD), key=str)

scalars = st.one_of(
    st.integers(-10**12, 10**12), st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from([0, -0.0, 1e-300, 1e300, 100_000, 64, 65, 0.5, -1]),
    st.text(max_size=20), st.booleans(),
)
values = st.one_of(scalars, st.lists(scalars, max_size=5), st.lists(st.lists(scalars, max_size=3), max_size=4),
                   st.dictionaries(st.sampled_from(["f", "zeta", "x", "count"]), scalars, max_size=3))


def mutated(path, how, value) -> dict:
    import copy

    doc = copy.deepcopy(GOOD)
    *parents, last = path
    node = doc
    for p in parents:
        node = node[p]
    if how == "delete":
        del node[last]
    elif how == "unknown":
        node[f"{last}_typo"] = value
    else:
        node[last] = value
    return doc


@settings(max_examples=200)
@given(path=st.sampled_from(PATHS), how=st.sampled_from(["replace", "replace", "replace", "delete", "unknown"]),
       value=values)
def loads_or_is_refused_in_one_line(tmp_path_factory, path, how, value):
    """A preset with one key mutated loads and simulates, or is refused in one line."""
    target = tmp_path_factory.mktemp("fuzz") / "mutated.toml"
    target.write_text(tomlkit.dumps(mutated(path, how, value)), encoding="utf-8")  # the save's writer
    try:
        tree = ta.load_tree(target)
    except PresetError as e:
        msg = str(e)
        # (600: an unknown key in [physics] lists the table's 24 known keys, 420 characters)
        assert msg.startswith(f"{target}: ") and "\n" not in msg and len(msg) < 600 + len(str(target)), msg[:700]
        return
    try:
        sim = ta.Simulation(tree, wind=ta.WindField(speed=12.0))
    except ValueError as e:  # a tree the simulation refuses (a kind with no f/zeta range): one line
        assert "\n" not in str(e)
        return
    for _ in range(3):
        sim.step(1 / 30)
    assert np.isfinite(sim.positions).all()


def _status_kb(field: str) -> int:
    """A memory figure of /proc/self/status (VmRSS, VmHWM: the peak since the last reset), kB."""
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith(field + ":"):
            return int(line.split()[1])
    raise AssertionError(f"no {field} in /proc/self/status")


def test_a_mutated_preset_loads_or_is_refused_in_one_line(tmp_path_factory):
    """The fuzzing, and the most memory the process took on during it: within 2 GB. The peak is
    reset first (/proc/self/clear_refs) and counted above what the process already held: its
    lifetime peak would count whatever ran before (after the scene renders it was 3 GB)."""
    Path("/proc/self/clear_refs").write_text("5")
    held = _status_kb("VmRSS")
    loads_or_is_refused_in_one_line(tmp_path_factory)
    grew = _status_kb("VmHWM") - held
    assert grew < 2 * 1024 * 1024, f"the fuzz took on {grew / 1024:.0f} MB"


def test_the_writer_writes_the_good_preset_back():
    assert tomllib.loads(tomlkit.dumps(GOOD)) == GOOD


@pytest.mark.parametrize("path", [("trunk", "segments"), ("levels", 0, "count"), ("physics", "summer", "leaf")])
def test_mutations_reach_nested_keys(path):
    assert path in PATHS
