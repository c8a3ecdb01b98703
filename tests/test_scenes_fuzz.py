"""Scene files by hypothesis: random keys, values, types and sizes in ``[[trees]]`` and
``[[scatter]]`` tables (NaN, ±inf, subnormal and huge floats, integers of hundreds of digits,
booleans, strings, arrays of any length, tables, unknown keys, missing keys) either load a scene
whose arrays are all finite or are refused with one SceneError line naming the file: never
another exception, never a traceback, never a NaN tree. Small trees keep it quick: the beam
preset, the woodland's light plants and the synthetic TreeQSM model."""

from __future__ import annotations

import json
import math
import warnings
from pathlib import Path

import numpy as np
from hypothesis import example, given, settings
from hypothesis import strategies as st

import treeanim as ta
from treeanim.errors import SceneError

ROOT = Path(__file__).resolve().parents[1]
PLANTS = ROOT / "assets" / "presets" / "scenes" / "plants"
QSM = ROOT / "assets" / "qsm" / "synthetic_broadleaf.txt"

#: What a table's ``tree`` may name: small presets by name and by file, a TreeQSM model, and
#: what is no tree (an unknown name, a missing file, a scene, a file of another kind).
TREES = ["beam", "beam", str(PLANTS / "sapling.toml"), str(PLANTS / "meadow.toml"), str(PLANTS / "shrub.toml"),
         str(QSM), "oak", "missing.toml", "other.toml", "scene.toml", "x.mat", ""]
#: Numbers at the edges of what the keys, floats and integers allow (no whole number between
#: 30 and 5,000: a count of them would grow thousands of trees and make the fuzz slow).
NUMBERS = [math.nan, math.inf, -math.inf, 0, 0.0, -0.0, -1, 1, 2, 0.04, 0.05, 0.5, 1.5, 5e-324, 1e-310, 2.2e-308,
           1e300, -1e300, 1.7976931348623157e308, 99.9, 100.0, 360.0, 3600.1, 5001, 9999.9, 10_000.0, 10_000.1,
           20_000.0, 2**31, 2**63 - 1, 2**63, -(2**63), 10**400, -(10**400), 20.0, 20.1]
LEAVES = ["cherry", "none", "tulip_poplar", "cherry:5", "cherry:0", "oak", ""]
TREE_KEYS = ["tree", "position", "heading", "scale", "seed", "leaves", "colour"]
SCATTER_KEYS = ["tree", "count", "area", "centre", "spacing", "pattern", "jitter", "heading", "scale", "seed",
                "leaves", "colour"]

number = st.sampled_from(NUMBERS) | st.integers(-3, 30) | st.floats(allow_nan=True, allow_infinity=True)
scalar = (number | number | st.booleans() | st.sampled_from(TREES + LEAVES + ["grid", "random", "hex"])
          | st.text(alphabet="abc .:/_-é", max_size=8))
value = st.recursive(scalar, lambda inner: st.lists(inner, max_size=4)
                     | st.dictionaries(st.sampled_from(["x", "y"]), inner, max_size=2), max_leaves=6)


def _toml(v) -> str:
    """A value as TOML (inline tables and arrays; floats with their exact repr)."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        return "nan" if math.isnan(v) else ("inf" if v > 0 else "-inf") if math.isinf(v) else repr(v)
    if isinstance(v, str):
        return json.dumps(v, ensure_ascii=False)
    if isinstance(v, list):
        return "[" + ", ".join(_toml(x) for x in v) + "]"
    return "{" + ", ".join(f"{k} = {_toml(x)}" for k, x in v.items()) + "}"


@st.composite
def table(draw, keys: list[str], base: dict) -> dict:
    """A usable table, then up to 3 of its keys (most often none) set to anything, or dropped."""
    t = dict(base)
    for _ in range(draw(st.sampled_from([0, 0, 0, 0, 1, 1, 2, 3]))):
        key = draw(st.sampled_from(keys))
        if draw(st.integers(0, 4)) == 0:
            t.pop(key, None)
        else:
            t[key] = draw(value | st.sampled_from(TREES) if key == "tree" else
                          value | st.sampled_from(LEAVES) if key == "leaves" else value)
    return t


@st.composite
def scenes(draw) -> str:
    """A scene file's text: a few placed trees and scatters, each usable before it is mutated."""
    lines = ['name = "fuzz"', 'type = "scene"']
    seed = draw(number) if draw(st.integers(0, 5)) == 0 else draw(st.sampled_from([None, 7]))
    if seed is not None:
        lines.append(f"seed = {_toml(seed)}")
    for i in range(draw(st.integers(0, 3))):
        base = {"tree": draw(st.sampled_from(TREES[:6])), "position": [6.0 * i, 0.0, draw(st.floats(-50, 50))]}
        t = draw(table(TREE_KEYS, base))
        lines += ["[[trees]]"] + [f"{k} = {_toml(v)}" for k, v in t.items()]
    for _ in range(draw(st.integers(0, 2))):
        base = {"tree": draw(st.sampled_from(TREES[:4])), "count": draw(st.integers(1, 12)),
                "area": [draw(st.floats(2, 60)), draw(st.floats(2, 60))], "centre": [0.0, 100.0],
                "spacing": draw(st.sampled_from([0.0, 1.0, 3.0])), "pattern": draw(st.sampled_from(["random", "grid"]))}
        t = draw(table(SCATTER_KEYS, base))
        lines += ["[[scatter]]"] + [f"{k} = {_toml(v)}" for k, v in t.items()]
    return "\n".join(lines) + "\n"


def _checked(path: Path):
    """Load ``path``: a scene whose arrays are all finite, or one SceneError line naming the file."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            scene = ta.load_tree(path)
    except SceneError as e:
        msg = str(e)
        assert "\n" not in msg and msg.startswith(f"{path}: ") and len(msg) < 600, msg[:800]
        return None
    assert isinstance(scene, ta.Scene) and scene.n_trees >= 1
    for name in ("rest_positions", "node_diameter", "rest_w", "lamina_length"):
        assert np.all(np.isfinite(getattr(scene, name))), name
    assert np.all(scene.node_diameter > 0) and np.abs(scene.rest_positions[:, [0, 2]]).max() < 10_100
    scene.validate()
    return scene


# Found by review: a seed of 400 digits (OverflowError in isfinite), a spacing of 1e-310
# (OverflowError making its grid or hash cells), a grid's jitter past 10 km (a bare ValueError)
@example(text='name = "x"\ntype = "scene"\nseed = ' + "9" * 400 + '\n[[trees]]\ntree = "beam"\nposition = [0, 0, 0]\n')
@example(text='name = "x"\ntype = "scene"\n[[scatter]]\ntree = "beam"\ncount = 2\narea = [1.0, 1.0]\n'
              'pattern = "grid"\nspacing = 1e-310\n')
@example(text='name = "x"\ntype = "scene"\n[[scatter]]\ntree = "beam"\ncount = 2\narea = [1.0, 1.0]\n'
              'spacing = 1e-310\n')
@example(text='name = "x"\ntype = "scene"\n[[scatter]]\ntree = "beam"\ncount = 3\narea = [10.0, 10.0]\n'
              'centre = [9995.0, 0.0]\npattern = "grid"\nspacing = 5.0\njitter = 100.0\n')
@settings(max_examples=300)
@given(text=scenes())
def loads_finite_or_refuses_in_one_line(tmp_path_factory, text):
    folder = tmp_path_factory.mktemp("scene")
    (folder / "other.toml").write_text('name = "o"\ntype = "scene"\n[[trees]]\ntree = "beam"\nposition = [0, 0, 0]\n')
    (folder / "x.mat").write_bytes(b"not a mat file")
    path = folder / "scene.toml"
    path.write_text(text, encoding="utf-8")
    _checked(path)


def test_a_random_scene_file_loads_a_finite_scene_or_is_refused_in_one_line(tmp_path_factory):
    loads_finite_or_refuses_in_one_line(tmp_path_factory)


def test_the_unmutated_scenes_load(tmp_path_factory):
    """The generator's scenes before mutation are scenes the loader builds (so the fuzz reaches
    past the checks, into the building)."""
    built = []

    @settings(max_examples=10)
    @given(n=st.integers(1, 3), count=st.integers(1, 12), pattern=st.sampled_from(["random", "grid"]))
    def every(n, count, pattern):
        folder = tmp_path_factory.mktemp("plain")
        trees = "".join(f'[[trees]]\ntree = "beam"\nposition = [{6.0 * i}, 0.0, 0.0]\n' for i in range(n))
        path = folder / "scene.toml"
        path.write_text(f'name = "p"\ntype = "scene"\n{trees}[[scatter]]\ntree = "{PLANTS / "sapling.toml"}"\n'
                        f'count = {count}\narea = [40.0, 40.0]\ncentre = [0.0, 100.0]\nspacing = 3.0\n'
                        f'pattern = "{pattern}"\n')
        built.append(_checked(path))

    every()
    assert len(built) == 10 and all(s is not None and s.n_trees >= 2 for s in built)
