"""Scene files: TOML that places trees (docs/design.md §17), checked key by key as presets are.

A scene file has ``type = "scene"``, a ``name``, an optional ``description`` and ``seed``, and
any number of ``[[trees]]`` (one tree each, at a position) and ``[[scatter]]`` tables (``count``
trees of one kind over a rectangle, at random with a least spacing or on a grid). A tree is a
preset's name or a file: a preset ``.toml`` or a TreeQSM model (``.txt``, ``.csv``, ``.mat``),
relative to the scene file. A placed tree is its preset's own tree (the preset's seed) unless
it gives a ``seed``, so two ``[[trees]]`` of one preset without seeds are alike; a scattered
tree is grown with a seed drawn, without repeats, from the scene's and the scatter's seeds, so
no two of a scatter are alike (a TreeQSM model's seed grows its leaves; its wood is the
scan's). Every problem is one :class:`~treeanim.errors.SceneError` line naming the file, the
key and what was expected.

Shipped scenes live in ``assets/presets/scenes/`` (package data ``treeanim.presets``).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

import numpy as np

from ..errors import PresetError, SceneError
from .declare import describe
from .presets import estimate_size, list_presets, read_spec, read_toml, tree_of
from .qsm.convert import load_qsm
from .qsm.leaves import LEAVES_FOR_QSM_ONLY
from .qsm.read import QSM_SUFFIXES
from .scene import MAX_COORDINATE, MAX_SCALE, MIN_SCALE, MergeError, Placement, Scene, merge_trees, place_tree
from .tree import Tree

__all__ = ["list_scenes", "load_scene", "read_scene", "scene_summary", "grow_placed", "MAX_TREES", "SCENE_BUDGET", "MIN_SPACING"]

#: Most trees one scene may place.
MAX_TREES = 5000
#: Most objects, nodes and triangles a scene may build, counted before any tree is generated:
#: about 2.5 times the orchard's triangles (whose mesh alone takes some 2 GB to draw).
SCENE_BUDGET = {"objects": 500_000, "nodes": 2_000_000, "triangles": 15_000_000}
#: A scatter's area may be at most this wide and deep (m).
MAX_AREA = 2 * MAX_COORDINATE
#: Candidate positions tried per tree before a random scatter gives up.
TRIES_PER_TREE = 60
#: The least spacing a scatter may ask for (m; 0, the default, is none for a random scatter):
#: closer than the thinnest shipped trunk's width. With it a grid over the widest area has at
#: most :data:`MAX_AREA` / MIN_SPACING + 1 = 400,001 columns and rows.
MIN_SPACING = 0.05
_TOP = ("name", "description", "type", "seed", "trees", "scatter")
_TREE_KEYS = ("tree", "position", "heading", "scale", "seed", "leaves")
_SCATTER_KEYS = ("tree", "count", "area", "centre", "spacing", "pattern", "jitter", "heading", "scale", "seed",
                 "leaves")
_FILE_SUFFIXES = (".toml", *QSM_SUFFIXES)


def _scene_dir():
    return resources.files("treeanim.presets") / "scenes"


def list_scenes() -> list[str]:
    """Names of the shipped scenes, sorted."""
    d = _scene_dir()
    return sorted(p.name[:-5] for p in d.iterdir() if p.name.endswith(".toml")) if d.is_dir() else []


def load_scene(name_or_path: str | Path) -> Scene:
    """A shipped scene by name (:func:`list_scenes`) or a scene file by path.

    Raises
    ------
    SceneError
        An unknown name (the message lists the known ones) or a file that is not a usable scene.
    """
    text = str(name_or_path)
    if text in list_scenes():
        with resources.as_file(_scene_dir() / f"{text}.toml") as path:
            return read_scene(path)
    if not text.lower().endswith(".toml"):
        raise SceneError(f"unknown scene {text!r}; known scenes: {', '.join(list_scenes())} (or a scene .toml file)")
    return read_scene(text)


# ---------------------------------------------------------------------------- checking
class _Bad(Exception):
    def __init__(self, key: str, expected: str):
        super().__init__(key, expected)
        self.key, self.expected = key, expected


def _num(value, key: str, lo: float, hi: float, integer: bool = False) -> float:
    kind = "an integer" if integer else "a number"
    ok = isinstance(value, int) if integer else isinstance(value, (int, float))
    # (an int is compared exactly, never made a float first: 10**400 is no float at all)
    if isinstance(value, bool) or not ok or not (isinstance(value, int) or math.isfinite(value)) \
            or not lo <= value <= hi:
        raise _Bad(key, f"expected {kind} in [{lo:g}, {hi:g}], got {describe(value)}")
    return int(value) if integer else float(value) + 0.0


def _nums(value, key: str, n: int, lo: float, hi: float, what: str) -> tuple[float, ...]:
    if not isinstance(value, list) or len(value) != n:
        raise _Bad(key, f"expected {what}, got {describe(value)}")
    try:
        return tuple(_num(v, key, lo, hi) for v in value)
    except _Bad:
        raise _Bad(key, f"expected {what}, each a finite number in [{lo:g}, {hi:g}], got {describe(value)}") from None


def _pair(value, key: str, lo: float, hi: float, unit: str) -> tuple[float, float]:
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        value = [value, value]  # one number: that value for every tree
    a, b = _nums(value, key, 2, lo, hi, f"a number or a range [min, max]{unit}")
    if a > b:
        raise _Bad(key, f"expected [min, max] with min <= max, got {describe(value)}")
    return a, b


def _string(value, key: str) -> str:
    if not isinstance(value, str) or not 0 < len(value) <= 1000:
        raise _Bad(key, f"expected a string of 1 to 1000 characters, got {describe(value)}")
    return value


def _keys(table, key: str, allowed: tuple[str, ...], required: tuple[str, ...]) -> dict:
    if not isinstance(table, dict):
        raise _Bad(key, f"expected a table, got {describe(table)}")
    for k in table:
        if k not in allowed:
            raise _Bad(f"{key}.{k}" if key else k, f"unknown key; expected one of {', '.join(allowed)}")
    for k in required:
        if k not in table:
            raise _Bad(f"{key}.{k}" if key else k, "missing")
    return table


def _tables(data: dict, key: str) -> list:
    value = data.get(key, [])
    if not isinstance(value, list):
        raise _Bad(key, f"expected an array of tables [[{key}]], got {describe(value)}")
    return value


@dataclass(frozen=True)
class _Kind:
    """What a table places: a preset (by name or file) or a TreeQSM model, and its leaves."""

    tree: str
    path: Path | None  # a file (None: a shipped preset)
    leaves: str | None


def _kind(table: dict, key: str, folder: Path) -> _Kind:
    name = _string(table["tree"], f"{key}.tree")
    leaves = table.get("leaves")
    if leaves is not None:
        leaves = _string(leaves, f"{key}.leaves")
    if name.lower().endswith(_FILE_SUFFIXES):
        path = Path(name) if Path(name).is_absolute() else folder / name
        if leaves is not None and not name.lower().endswith(QSM_SUFFIXES):
            raise _Bad(f"{key}.leaves", LEAVES_FOR_QSM_ONLY)
        return _Kind(name, path, leaves)
    if name not in list_presets():
        raise _Bad(f"{key}.tree", f"unknown preset {name!r}; expected one of {', '.join(list_presets())} or a "
                                  f"file ({', '.join(_FILE_SUFFIXES)})")
    if leaves is not None:
        raise _Bad(f"{key}.leaves", LEAVES_FOR_QSM_ONLY)
    return _Kind(name, None, None)


@dataclass
class _Plan:
    """The trees a scene file places, checked, before any is generated."""

    kinds: list[_Kind]
    keys: list[str]  # the table each kind is first named in ('trees[0]', 'scatter[2]')
    where: list[tuple[int, tuple[float, float, float], float, float, int | None]]  # kind, position, heading, scale, seed
    labels: list[str]  # each tree's table ('trees[3]', 'scatter[0] tree 17')


def _plan(data: dict, path: Path) -> _Plan:
    _keys(data, "", _TOP, ("name", "type"))
    if data["type"] != "scene":
        raise _Bad("type", f"expected 'scene', got {describe(data['type'])}")
    _string(data["name"], "name")
    if "description" in data:
        _string(data["description"], "description")
    seed = _num(data.get("seed", 0), "seed", 0, 2**63 - 1, integer=True)
    folder = path.parent
    kinds: dict[_Kind, int] = {}
    plan = _Plan([], [], [], [])

    def kind_index(k: _Kind, key: str) -> int:
        if k not in kinds:
            kinds[k] = len(plan.kinds)
            plan.kinds.append(k)
            plan.keys.append(key)
        return kinds[k]

    trees, scatters = _tables(data, "trees"), _tables(data, "scatter")
    if len(trees) > MAX_TREES:
        raise _Bad("trees", f"{len(trees):,} trees; a scene may place at most {MAX_TREES:,}")
    for i, t in enumerate(trees):
        key = f"trees[{i}]"
        _keys(t, key, _TREE_KEYS, ("tree", "position"))
        k = kind_index(_kind(t, key, folder), key)
        pos = _nums(t["position"], f"{key}.position", 3, -MAX_COORDINATE, MAX_COORDINATE,
                    "a position [x, y, z] in metres")
        if pos[1] != 0.0:  # the drawn ground and the branches' contact floor are flat at y = 0
            raise _Bad(f"{key}.position", f"expected y = 0 (trees stand on the ground, which is flat at y = 0), "
                                          f"got {describe(t['position'])}")
        heading = _num(t.get("heading", 0.0), f"{key}.heading", -3600.0, 3600.0)
        scale = _num(t.get("scale", 1.0), f"{key}.scale", MIN_SCALE, MAX_SCALE)
        own = _num(t["seed"], f"{key}.seed", 0, 2**63 - 1, integer=True) if "seed" in t else None
        plan.where.append((k, pos, heading, scale, own))
        plan.labels.append(key)
    for i, t in enumerate(scatters):
        key = f"scatter[{i}]"
        _keys(t, key, _SCATTER_KEYS, ("tree", "count", "area"))
        k = kind_index(_kind(t, key, folder), key)
        count = _num(t["count"], f"{key}.count", 1, MAX_TREES, integer=True)
        if len(plan.where) + count > MAX_TREES:
            raise _Bad(f"{key}.count", f"the scene would place {len(plan.where) + count:,} trees; a scene may "
                                       f"place at most {MAX_TREES:,}")
        rng = np.random.default_rng([seed, i, _num(t.get("seed", 0), f"{key}.seed", 0, 2**63 - 1, integer=True)])
        for xz, heading, scale, own in _scatter(t, key, count, rng, plan.where):
            plan.where.append((k, (xz[0], 0.0, xz[1]), heading, scale, own))
        plan.labels += [f"{key} tree {j}" for j in range(count)]
    if not plan.where:
        raise _Bad("trees", "missing; a scene places at least one tree ([[trees]] or [[scatter]])")
    return plan


def _scatter(t: dict, key: str, count: int, rng: np.random.Generator, placed) -> list:
    """Positions (x, z), headings, scales and seeds of one [[scatter]]'s trees."""
    area = _nums(t["area"], f"{key}.area", 2, 1e-3, MAX_AREA, "an area [width, depth] in metres")
    centre = _nums(t.get("centre", [0.0, 0.0]), f"{key}.centre", 2, -MAX_COORDINATE, MAX_COORDINATE,
                   "a centre [x, z] in metres")
    spacing = _num(t.get("spacing", 0.0), f"{key}.spacing", 0.0, 1000.0)
    if 0.0 < spacing < MIN_SPACING:
        raise _Bad(f"{key}.spacing", f"expected 0 (none) or a number in [{MIN_SPACING:g}, 1000] (m), got "
                                     f"{describe(spacing)}")
    pattern = _string(t.get("pattern", "random"), f"{key}.pattern")
    jitter = _num(t.get("jitter", 0.0), f"{key}.jitter", 0.0, 100.0)
    if max(abs(c) + 0.5 * a for c, a in zip(centre, area)) + (jitter if pattern == "grid" else 0.0) > MAX_COORDINATE:
        raise _Bad(f"{key}.area", f"reaches more than {MAX_COORDINATE:g} m from the origin"
                                  + (f" with its jitter of {jitter:g} m" if jitter and pattern == "grid" else ""))
    heading = _pair(t.get("heading", [0.0, 360.0]), f"{key}.heading", -3600.0, 3600.0, " in degrees")
    scale = _pair(t.get("scale", 1.0), f"{key}.scale", MIN_SCALE, MAX_SCALE, "")
    lo, size = np.array(centre) - 0.5 * np.array(area), np.array(area)
    if pattern == "grid":
        if spacing <= 0:
            raise _Bad(f"{key}.spacing", f"expected the grid's spacing, a number in [{MIN_SPACING:g}, 1000] (m)")
        cols, rows = (int(a // spacing) + 1 for a in area)
        if count > cols * rows:
            raise _Bad(f"{key}.count", f"{count:,} trees do not fit a grid of {cols} × {rows} at spacing "
                                       f"{spacing:g} m over {area[0]:g} × {area[1]:g} m")
        cell = np.arange(count)
        grid = np.stack([cell % cols - 0.5 * (cols - 1), cell // cols - 0.5 * (rows - 1)], axis=1) * spacing
        xz = np.array(centre) + grid + rng.uniform(-jitter, jitter, (count, 2))
    elif pattern == "random":
        xz = _darts(rng, count, lo, size, spacing, np.array([w[1][::2] for w in placed]).reshape(-1, 2))
        if len(xz) < count:
            raise _Bad(f"{key}.count", f"only {len(xz):,} of {count:,} trees fit {area[0]:g} × {area[1]:g} m at "
                                       f"spacing {spacing:g} m; lower the count or the spacing, or widen the area")
    else:
        raise _Bad(f"{key}.pattern", f"expected 'random' or 'grid', got {describe(pattern)}")
    headings = rng.uniform(*heading, count)
    scales = rng.uniform(*scale, count)
    seeds = rng.choice(2**31, size=count, replace=False)
    return [(p, float(h), float(s), int(sd)) for p, h, s, sd in zip(xz.tolist(), headings, scales, seeds)]


def _darts(rng, count: int, lo: np.ndarray, size: np.ndarray, spacing: float, taken: np.ndarray) -> np.ndarray:
    """Up to ``count`` random points in the rectangle, each at least ``spacing`` from the
    others and from ``taken`` (dart throwing on a hash grid of cells ``spacing`` wide)."""
    if spacing <= 0:
        return lo + rng.random((count, 2)) * size
    cells: dict[tuple[int, int], list] = {}

    def key(p):
        return int(math.floor(p[0] / spacing)), int(math.floor(p[1] / spacing))

    for p in taken:
        cells.setdefault(key(p), []).append(p)
    out = []
    s2 = spacing * spacing
    candidates = lo + rng.random((TRIES_PER_TREE * count, 2)) * size
    for p in candidates:
        cx, cz = key(p)
        if all((q[0] - p[0]) ** 2 + (q[1] - p[1]) ** 2 >= s2 for i in (-1, 0, 1) for j in (-1, 0, 1)
               for q in cells.get((cx + i, cz + j), ())):
            cells.setdefault((cx, cz), []).append(p)
            out.append(p)
            if len(out) == count:
                break
    return np.array(out).reshape(-1, 2)


# ---------------------------------------------------------------------------- building
def _base(kind: _Kind, key: str):
    """A kind's spec (a preset) or its first tree (a TreeQSM model), to estimate its size."""
    try:
        if kind.path is None:
            with resources.as_file(resources.files("treeanim.presets") / f"{kind.tree}.toml") as p:
                return read_spec(p)
        if str(kind.path).lower().endswith(QSM_SUFFIXES):
            return load_qsm(kind.path, leaves=kind.leaves, seed=0)
        data = read_toml(kind.path)
        if data.get("type") == "scene":
            raise _Bad(key, f"{kind.tree} is a scene; a scene places trees, not scenes")
        return read_spec(kind.path, data)
    except PresetError as e:
        raise _Bad(key, str(e)) from None


def _check_size(plan: _Plan, bases: list) -> None:
    total = {w: 0.0 for w in SCENE_BUDGET}
    n = np.bincount([w[0] for w in plan.where], minlength=len(plan.kinds))
    share = {w: np.zeros(len(bases)) for w in SCENE_BUDGET}
    for i, (base, times) in enumerate(zip(bases, n)):
        if isinstance(base, Tree):
            stats = base.stats(0.0)
            size = {w: stats[w] for w in SCENE_BUDGET}
        else:
            size = estimate_size(base)
        for w in SCENE_BUDGET:
            share[w][i] = times * size[w]
            total[w] += times * size[w]
    for w, most in SCENE_BUDGET.items():
        if total[w] > most:
            key = plan.keys[int(np.argmax(share[w]))]
            raise _Bad(f"{key}.count" if key.startswith("scatter") else key,
                       f"the scene's {len(plan.where):,} trees ask for about {total[w]:.3g} {w}; a scene may build "
                       f"at most {most:,}")


def _grow(kind: _Kind, base, seed: int | None) -> Tree:
    """One tree of a kind: a preset's spec grown with ``seed`` (None: its own), or a TreeQSM
    model's leaves grown with it (a leafless model is the scan as it is)."""
    if isinstance(base, Tree):  # a TreeQSM model: its seed grows the leaves
        return base if seed in (None, 0) or kind.leaves in (None, "none") else load_qsm(
            kind.path, leaves=kind.leaves, seed=seed)
    return tree_of(base if seed is None else dataclasses.replace(base, seed=seed), kind.path or kind.tree)


def grow_placed(scene: Scene, placement: Placement) -> Tree:
    """The tree a scene file's ``placement`` placed, as generated: at the origin, heading 0,
    scale 1 (a file is found beside ``scene.source``).

    Raises
    ------
    SceneError
        The tree's source can no longer be read.
    """
    table = {"tree": placement.tree} | ({"leaves": placement.leaves} if placement.leaves else {})
    try:
        kind = _kind(table, "tree", Path(scene.source).parent)
        return _grow(kind, _base(kind, "tree"), placement.seed)
    except _Bad as e:
        raise SceneError(f"{scene.source}: {placement.tree}: {e.expected}") from None


def _table(label: str) -> str:
    """The table a tree's label names ('scatter[2] tree 17' -> 'scatter[2]')."""
    return label.split(" ")[0]


def _check_trunks(scene: Scene, labels: list[str]) -> None:
    """No two trunks stand inside each other (their bases closer than the sum of their radii)."""
    from scipy.spatial import cKDTree

    roots = np.flatnonzero((scene.parent < 0) & (scene.kind == "branch"))
    if len(roots) < 2:
        return
    base = scene.rest_positions[scene.object_start[roots]][:, [0, 2]]
    radius = 0.5 * scene.node_diameter[scene.object_start[roots]]
    pairs = cKDTree(base).query_pairs(2.0 * float(radius.max()), output_type="ndarray")
    if len(pairs):
        gap = np.linalg.norm(base[pairs[:, 0]] - base[pairs[:, 1]], axis=1)
        bad = np.flatnonzero(gap < radius[pairs[:, 0]] + radius[pairs[:, 1]])
        if len(bad):
            a, b = pairs[bad[0]]
            ta, tb = scene.object_tree[roots[a]], scene.object_tree[roots[b]]
            raise _Bad(labels[min(ta, tb)], f"its trunk overlaps that of {labels[max(ta, tb)]} ({gap[bad[0]]:.3g} m "
                                            "apart); move them apart or give the scatter a spacing")


def read_scene(path: str | Path, data: dict | None = None) -> Scene:
    """Read a scene file and build its :class:`Scene`.

    Parameters
    ----------
    path : str or Path
    data : dict, optional
        The file's TOML already read.

    Raises
    ------
    SceneError
        One line naming the file, the key and what was expected.
    """
    path = Path(path)
    try:
        if data is None:
            data = read_toml(path)
        plan = _plan(data, path)
        bases = [_base(k, f"{key}.tree") for k, key in zip(plan.kinds, plan.keys)]
        _check_size(plan, bases)
        trees, placements = [], []
        for (k, pos, heading, scale, own), label in zip(plan.where, plan.labels):
            kind = plan.kinds[k]
            try:
                tree = _grow(kind, bases[k], own)
            except PresetError as e:
                raise _Bad(_table(label) + ".tree", str(e)) from None
            try:  # (the checks above leave it nothing to refuse: a guard, in one line)
                trees.append(place_tree(tree, pos, heading, scale))
            except ValueError as e:
                raise _Bad(_table(label), f"{label}: {e}") from None
            placements.append(Placement(kind.tree, pos, heading, scale, int(tree.seed), kind.leaves))
        try:  # (it refuses leaves of another outline than the first leafy tree's)
            scene = merge_trees(trees, placements, name=data["name"], seed=int(data.get("seed", 0)),
                                source=str(path), description=" ".join(str(data.get("description", "")).split()),
                                labels=plan.labels)
        except MergeError as e:
            raise _Bad(f"{_table(plan.labels[e.index])}.tree", str(e)) from None
        except ValueError as e:  # (a guard: nothing else in it is left to refuse a checked plan)
            raise _Bad("trees", str(e)) from None
        _check_trunks(scene, plan.labels)
    except _Bad as e:
        raise SceneError(f"{path}: key '{e.key}': {e.expected}") from None
    except PresetError as e:
        raise SceneError(str(e) if str(e).startswith(str(path)) else f"{path}: {e}") from None
    return scene


def scene_summary(path: str | Path) -> tuple[int, dict[str, int], str]:
    """A scene file's trees without building them: (number of trees, trees per kind, description).

    Raises
    ------
    SceneError
        As :func:`read_scene`: a file that cannot be read or is not TOML, or what the file
        says (its trees are not read).
    """
    path = Path(path)
    try:
        data = read_toml(path)
        plan = _plan(data, path)
    except _Bad as e:
        raise SceneError(f"{path}: key '{e.key}': {e.expected}") from None
    except PresetError as e:  # read_toml's, which names the file
        raise SceneError(str(e)) from None
    per: dict[str, int] = {}
    for k, *_ in plan.where:
        per[plan.kinds[k].tree] = per.get(plan.kinds[k].tree, 0) + 1
    return len(plan.where), per, " ".join(str(data.get("description", "")).split())
