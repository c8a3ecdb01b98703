"""Preset files: TOML in ``assets/presets/`` (shipped as ``treeanim.presets``), checked key by key.

Every problem is reported as one :class:`PresetError` line naming the file, the key and what
was expected.
"""

from __future__ import annotations

import dataclasses
import math
import os
import stat
import tomllib
from importlib import resources
from pathlib import Path

import numpy as np

from ..errors import PresetError
from .declare import SettingError, describe
from .generate import BeamSpec, CrownSpec, GrassSpec, LaminaSpec, LeafSpec, LevelSpec, TreeSpec, generate
from .look import Bark
from .params import PhysicsParams
from .tree import BRANCH_SIDES, PLURAL, Tree, curve_bands

#: Allowed ranges of the shape tables' numeric keys (inclusive); keys not listed must be finite
#: and >= 0. The [physics] table's are declared with :class:`PhysicsParams` itself.
BOUNDS: dict[str, tuple[float, float]] = {
    "segments": (1, 64),
    "length": (1e-4, 100.0),
    "diameter": (1e-5, 10.0),
    "taper": (0.0, 0.99),
    "attach": (0.0, 1.0),
    "down_angle": (0.0, 180.0),
    "down_var": (0.0, 90.0),
    "roll": (-360.0, 360.0),
    "roll_var": (0.0, 180.0),
    "curvature": (-180.0, 180.0),
    "gravity": (-90.0, 90.0),
    "up": (0.0, 1.0),
    "lean": (0.0, 60.0),
    "length_var": (0.0, 1.0),
    "cone": (0.0, 0.95),
    "count": (0.0, 100_000.0),
    "winter_count": (0.0, 100_000.0),
    "levels": (1, 32),
    "petiole_segments": (1, 32),
    "petiole_sides": (3, 32),
    "petiole_length": (1e-4, 1.0),
    "petiole_diameter": (1e-5, 0.1),
    "lamina_length": (1e-3, 2.0),
    "size_var": (0.0, 0.5),
    "droop": (-90.0, 90.0),
    "samples": (3, 512),
    "teeth": (0, 200),
    "tooth_depth": (0.0, 0.2),
    "curl": (-2.0, 2.0),
    "outline": (-2.0, 2.0),
    "size": (1e-3, 1000.0),
    "height": (1e-3, 100.0),
    "width": (1e-5, 1.0),
    "bend": (-180.0, 180.0),
    "edge": (0.0, 1.0),
    "edge_height": (0.0, 1.0),
    "wobble": (0.0, 0.5),
    "tip_share": (0.0, 1.0),
    "radius": (0.0, 100.0),
    "min_scale": (0.3, 1.0),
    "color": (0.0, 1.0),
    "furrows": (1.0, 64.0),
    "depth": (0.0, 1.0),
    "interlace": (0.0, 1.0),
    "lenticels": (0.0, 1.0),
    "tip_angle": (0.0, 180.0),
    "turn_var": (0.0, 90.0),
    "leader": (0.0, 1.0),
    "seed": (0, 2**63 - 1),
}

#: Longest string value (a name, a description, a shape).
MAX_STRING = 1000
#: Most control points of a lamina outline (it is resampled to ``samples`` points anyway).
MAX_OUTLINE = 1000

_PRESET_PKG = "treeanim.presets"


def _preset_dir():
    return resources.files(_PRESET_PKG)


def list_presets() -> list[str]:
    """Names of the shipped presets, sorted."""
    return sorted(p.name[:-5] for p in _preset_dir().iterdir() if p.name.endswith(".toml"))


def load_preset(name: str) -> Tree:
    """Generate the tree of a shipped preset.

    Parameters
    ----------
    name : str
        One of :func:`list_presets`.

    Raises
    ------
    PresetError
        Unknown name (the message lists the known ones) or a malformed preset.
    """
    known = list_presets()
    if name not in known:
        raise PresetError(f"unknown preset {name!r}; known presets: {', '.join(known)}")
    with resources.as_file(_preset_dir() / f"{name}.toml") as path:
        return read_tree(path)


def read_tree(path: str | Path, data: dict | None = None) -> Tree:
    """Read a preset TOML file and generate its tree (``treeanim.load_tree`` reads any tree
    file, scenes too: :func:`treeanim.model.load.load_tree`).

    Parameters
    ----------
    path : str or Path
    data : dict, optional
        The file's TOML already read (:func:`read_toml`), to read it once.

    Raises
    ------
    PresetError
        One line naming the file, the key and what was expected.
    """
    return tree_of(read_spec(path, data), path)


def tree_of(spec: TreeSpec, path) -> Tree:
    """Generate a checked spec's tree; a problem is one PresetError line naming ``path``."""
    try:
        tree = generate(spec)
    except ValueError as e:  # the generator names the key it could not use
        raise PresetError(f"{path}: {e}") from None
    for kind in np.unique(tree.kind):
        for season in ("summer", "winter"):
            if getattr(tree.physics, season).of(kind) is None:
                raise PresetError(f"{path}: key 'physics.{season}.{kind}': missing; the tree has {PLURAL[kind]}, "
                                  "so it needs their f and zeta ranges")
    return tree


#: A preset file larger than this is refused unread (the shipped ones are under 4 KB).
MAX_PRESET_BYTES = 1 << 20


def _read_text(path: Path) -> str:
    """The file's text: a regular file only (not a FIFO, a device or a directory, which could
    block or never end), at most :data:`MAX_PRESET_BYTES`, UTF-8."""
    try:
        info = os.stat(path)
        if not stat.S_ISREG(info.st_mode):
            raise PresetError(f"{path}: not a regular file (a preset must be a .toml text file)")
        if info.st_size > MAX_PRESET_BYTES:
            raise PresetError(f"{path}: {info.st_size:,} bytes; a preset file may have at most "
                              f"{MAX_PRESET_BYTES:,}")
        with open(path, "rb") as f:
            raw = f.read(MAX_PRESET_BYTES + 1)  # (it may have grown since)
    except OSError as e:
        raise PresetError(f"{path}: cannot read preset file ({e.strerror or e})") from None
    if len(raw) > MAX_PRESET_BYTES:
        raise PresetError(f"{path}: more than {MAX_PRESET_BYTES:,} bytes; a preset file may have at most that")
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError:
        raise PresetError(f"{path}: not a UTF-8 text file") from None


def read_toml(path: str | Path) -> dict:
    """A preset or scene file's TOML: a regular UTF-8 file of at most :data:`MAX_PRESET_BYTES`
    that parses (PresetError otherwise, one line naming the file)."""
    path = Path(path)
    text = _read_text(path)
    try:
        return tomllib.loads(text)
    except ValueError as e:  # TOMLDecodeError, or an integer of thousands of digits
        why = " ".join(str(e).split())
        raise PresetError(f"{path}: not valid TOML ({why if len(why) <= 120 else why[:117] + '...'})") from None
    except RecursionError:  # tomllib parses nested arrays and tables recursively
        raise PresetError(f"{path}: arrays or tables nested too deeply to be a preset") from None


def read_spec(path: str | Path, data: dict | None = None) -> TreeSpec:
    """Parse and check a preset file into a :class:`TreeSpec` (no generation); ``data``, the
    file's TOML if already read."""
    path = Path(path)
    if data is None:
        data = read_toml(path)
    try:
        spec = _tree_spec(data, str(path))
        _check_leaves(spec)
        _check_size(spec)
    except _KeyProblem as e:
        raise PresetError(f"{path}: key '{e.key}': {e.expected}") from None
    return spec


# ---------------------------------------------------------------------------- checking
class _KeyProblem(Exception):
    def __init__(self, key: str, expected: str):
        super().__init__(key, expected)
        self.key, self.expected = key, expected


def _number(value, key: str, integer: bool):
    name = key.rsplit(".", 1)[-1]
    lo, hi = BOUNDS.get(name, (0.0, math.inf))
    kind = "an integer" if integer else "a number"
    ok_type = isinstance(value, int) if integer else isinstance(value, (int, float))
    if isinstance(value, bool) or not ok_type:
        raise _KeyProblem(key, f"expected {kind} in [{lo:g}, {hi:g}], got {describe(value)}")
    if not math.isfinite(value) or not lo <= value <= hi:
        raise _KeyProblem(key, f"expected {kind} in [{lo:g}, {hi:g}], got {describe(value)}")
    return int(value) if integer else float(value) + 0.0  # (-0.0 is 0)


def _coerce(value, default, key: str):
    """Check ``value`` against the type of ``default`` and the bounds of ``key``."""
    if isinstance(default, str):
        if not isinstance(value, str):
            raise _KeyProblem(key, f"expected a string, got {describe(value)}")
        if len(value) > MAX_STRING:
            raise _KeyProblem(key, f"expected at most {MAX_STRING} characters, got {len(value):,}")
        return value
    if isinstance(default, (int, float)) and not isinstance(default, bool):
        return _number(value, key, integer=isinstance(default, int))
    if isinstance(default, tuple):
        name = key.rsplit(".", 1)[-1]
        if name == "outline":
            if not isinstance(value, list) or not 3 <= len(value) <= MAX_OUTLINE or not all(
                isinstance(p, list) and len(p) == 2 for p in value
            ):
                raise _KeyProblem(key, f"expected a list of 3 to {MAX_OUTLINE} [x, y] points, got {describe(value)}")
            return tuple(tuple(_number(c, key, False) for c in p) for p in value)
        if name == "color":
            if not isinstance(value, list) or len(value) != 3:
                raise _KeyProblem(key, f"expected an sRGB colour [r, g, b] in [0, 1], got {describe(value)}")
            return tuple(_number(c, key, False) for c in value)
        if name == "levels":
            if not isinstance(value, list):
                raise _KeyProblem(key, f"expected a list of level numbers, got {describe(value)}")
            return tuple(_number(v, key, True) for v in value)
        if not isinstance(value, list) or len(value) != 2:
            raise _KeyProblem(key, f"expected a pair [min, max], got {describe(value)}")
        lo, hi = (_number(v, key, False) for v in value)
        if lo > hi and name != "diameter":
            raise _KeyProblem(key, f"expected [min, max] with min <= max, got {describe(value)}")
        return lo, hi
    raise AssertionError(f"no rule for {key}")  # pragma: no cover - programming error


def _table(data, key: str) -> dict:
    if not isinstance(data, dict):
        raise _KeyProblem(key, f"expected a table, got {describe(data)}")
    return data


def _dataclass_from(cls, data: dict, prefix: str, required=()):
    """Fill dataclass ``cls`` from a TOML table, checking every key."""
    data = _table(data, prefix.rstrip("."))
    fields = {f.name: f for f in dataclasses.fields(cls)}
    defaults = cls()
    for k in data:
        if k not in fields:
            raise _KeyProblem(prefix + k, f"unknown key; expected one of {', '.join(sorted(fields))}")
    for k in required:
        if k not in data:
            raise _KeyProblem(prefix + k, "missing")
    return cls(**{k: _coerce(v, getattr(defaults, k), prefix + k) for k, v in data.items()})


def _physics(data) -> PhysicsParams:
    """The [physics] table, checked by the declarations of :class:`PhysicsParams`."""
    data = _table(data, "physics")
    for k in ("summer", "winter"):
        if k not in data:
            raise _KeyProblem(f"physics.{k}", "missing; expected a table of f and zeta ranges per kind")
    try:
        return PhysicsParams(**data)
    except SettingError as e:
        raise _KeyProblem(e.key, e.problem) from None


def _tree_spec(data: dict, source: str) -> TreeSpec:
    top = ("name", "description", "type", "seed", "trunk", "levels", "crown", "leaves", "lamina", "bark", "grass",
           "beam", "physics")
    if data.get("type") == "scene":
        raise _KeyProblem("type", "expected 'tree', 'grass' or 'beam', got 'scene' (a scene file: treeanim.load_scene "
                                  "reads it)")
    for k in data:
        if k not in top:
            raise _KeyProblem(k, f"unknown key; expected one of {', '.join(top)}")
    for k in ("name", "type", "physics"):
        if k not in data:
            raise _KeyProblem(k, "missing")
    name = _coerce(data["name"], "", "name")
    kind = _coerce(data["type"], "", "type")
    if kind not in ("tree", "grass", "beam"):
        raise _KeyProblem("type", f"expected 'tree', 'grass' or 'beam', got {kind!r}")
    if "description" in data:
        _coerce(data["description"], "", "description")
    kw = dict(name=name, type=kind, seed=_coerce(data.get("seed", 0), 0, "seed"),
              physics=_physics(data["physics"]), source=source)
    if kind == "tree":
        if "trunk" not in data:
            raise _KeyProblem("trunk", "missing; a tree needs a [trunk] table")
        levels = [_dataclass_from(LevelSpec, data["trunk"], "trunk.", required=("length", "diameter", "segments"))]
        raw_levels = data.get("levels", [])
        if not isinstance(raw_levels, list):
            raise _KeyProblem("levels", f"expected an array of tables [[levels]], got {describe(raw_levels)}")
        for i, lv in enumerate(raw_levels):
            levels.append(_dataclass_from(LevelSpec, lv, f"levels[{i}].", required=("count", "length")))
        kw["levels"] = tuple(levels)
        if "crown" in data:
            kw["crown"] = _dataclass_from(CrownSpec, data["crown"], "crown.", required=("height", "radius"))
        if "bark" in data:
            kw["bark"] = _dataclass_from(Bark, data["bark"], "bark.")
        if "leaves" in data:
            kw["leaves"] = _dataclass_from(LeafSpec, data["leaves"], "leaves.", required=("count", "levels"))
            if kw["leaves"].count > 0:
                if "lamina" not in data:
                    raise _KeyProblem("lamina", "missing; leaves need a [lamina] outline")
                kw["lamina"] = _dataclass_from(LaminaSpec, data["lamina"], "lamina.", required=("outline",))
    elif kind == "grass":
        if "grass" not in data:
            raise _KeyProblem("grass", "missing; a grass preset needs a [grass] table")
        kw["grass"] = _dataclass_from(GrassSpec, data["grass"], "grass.", required=("count",))
    else:
        kw["beam"] = _dataclass_from(BeamSpec, data.get("beam", {}), "beam.")
    return TreeSpec(**kw)


def _tube_triangles(segments):
    """Most triangles of a branch tube of ``segments`` segments (:meth:`Tree.triangles_per_object`)."""
    return 2 * BRANCH_SIDES * (segments * curve_bands(np.asarray(segments) + 1, np.pi) + 1)


def estimate_size(spec: TreeSpec) -> dict[str, float]:
    """An upper bound of the objects, nodes and triangles ``spec`` builds, from its counts alone
    (before building anything: crown pruning and rounding only remove).

    Returns
    -------
    dict
        ``objects``, ``nodes``, ``triangles``, and ``keys``: the keys that drive the largest.
    """
    if spec.type == "grass":
        g = spec.grass
        return {"objects": g.count, "nodes": g.count * (g.segments + 1), "triangles": g.count * (2 * g.segments + 1),
                "keys": "grass.count, grass.segments"}
    if spec.type == "beam":
        n = spec.beam.segments
        return {"objects": 1, "nodes": n + 1, "triangles": _tube_triangles(n), "keys": "beam.segments"}
    # The trunk, then each level: so many children per branch of the level above.
    per_level = np.cumprod([1.0] + [lv.count for lv in spec.levels[1:]])
    segments = np.array([lv.segments for lv in spec.levels])
    objects = float(per_level.sum())
    nodes = float(per_level @ (segments + 1))
    triangles = float(per_level @ _tube_triangles(segments))
    lf = spec.leaves
    if lf.count:
        la = spec.lamina
        outline = 2 * (la.samples + la.teeth * 2) if la is not None else 0
        objects += lf.count
        nodes += lf.count * (lf.petiole_segments + 1)
        triangles += lf.count * (2 * lf.petiole_sides * lf.petiole_segments + outline)
    return {"objects": objects, "nodes": nodes, "triangles": triangles,
            "keys": "levels[].count, levels[].segments, leaves.count, lamina.samples"}


#: Most objects, nodes and triangles a preset may build (about 30 times the large cherry's:
#: the mesh alone is then some hundreds of MB and building takes tens of seconds).
SIZE_BUDGET = {"objects": 200_000, "nodes": 1_000_000, "triangles": 25_000_000}


def _check_size(spec: TreeSpec) -> None:
    size = estimate_size(spec)
    for what, most in SIZE_BUDGET.items():
        if size[what] > most:
            raise _KeyProblem(size["keys"], f"these ask for about {size[what]:.3g} {what}; a preset may build at "
                                            f"most {most:,}")


def _check_leaves(spec: TreeSpec) -> None:
    if spec.type == "grass" and spec.grass.count < 1:
        raise _KeyProblem("grass.count", f"expected at least 1 blade, got {spec.grass.count}")
    if spec.grass.shape not in ("rect", "round"):
        raise _KeyProblem("grass.shape", f"expected 'rect' or 'round', got {spec.grass.shape!r}")
    crown = spec.crown
    if crown.radius > 0 and not crown.height[0] < crown.height[1]:
        raise _KeyProblem("crown.height", f"expected [bottom, top] with bottom < top, got {list(crown.height)}")
    lf = spec.leaves
    if lf.winter_count > lf.count:
        raise _KeyProblem("leaves.winter_count", f"expected at most leaves.count ({lf.count}), got {lf.winter_count}")
    n_levels = len(spec.levels)
    for lv in lf.levels:
        if spec.type == "tree" and lf.count > 0 and lv > n_levels:
            raise _KeyProblem("leaves.levels", f"expected levels between 1 and {n_levels}, got {list(lf.levels)}")
    la = spec.lamina
    if la is not None:
        if abs(la.outline[0][0]) > 1e-9 or abs(la.outline[-1][0]) > 1e-9:
            raise _KeyProblem("lamina.outline", "expected the first (base) and last (tip) points on the midrib, x = 0")
        if any(x < 0 for x, _ in la.outline):
            raise _KeyProblem("lamina.outline", "expected the right half of the blade, x >= 0")
