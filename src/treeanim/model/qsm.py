"""TreeQSM cylinder models: read a scanned tree and build a :class:`Tree` from it.

A quantitative structure model (QSM, Raumonen et al. 2013) describes a tree as cylinders, one
a row: radius, length, start x y z, axis x y z, parent, extension, branch, branch order,
position in branch, added (14 columns; TreeQSM 2.4's text export adds mad and SurfCov before
``added`` and UnmodRadius after it: 16 or 17). Metres, z up; cylinders are numbered from 1 in
file order, ``parent`` 0 marks the stem's first cylinder. The table comes as text (whitespace-
or comma-separated, an optional header line, ``#`` or ``%`` comments) or as a MATLAB ``.mat``
file holding TreeQSM's ``cylinder`` struct (alone or inside a ``QSM`` struct) or a plain
matrix of those columns.

Each chain of cylinders of one branch becomes one curved beam object (docs/design.md §3): its
nodes are the cylinders' start points and the last one's end, its diameters the cylinders'
(averaged where two meet). A branch's base sits on the node of its parent cylinder nearest to
where it starts (its start or its end); the branch is moved by that small offset, with what
grows on it. Coordinates turn from z up to y up, (x, y, z) → (x, z, −y), and the stem's first
cylinder starts at the origin.

Every problem is one :class:`~treeanim.errors.QSMError` line naming the file, the row
and what was wrong.
"""

from __future__ import annotations

import dataclasses
import os
import re
import stat
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import PresetError, QSMError
from .build import ObjectSpec, assemble
from .generate import LeafSpec, place_leaves
from .lamina import make_lamina
from .params import WOOD_TYPES
from .tree import Tree

__all__ = ["SPECIES", "Species", "QSM_SUFFIXES", "read_table", "load_qsm", "load_file", "build_tree", "parse_leaves",
           "synthetic_table", "write_table"]

#: File suffixes read as TreeQSM models.
QSM_SUFFIXES = (".txt", ".csv", ".mat")
#: The columns used, in TreeQSM's order (0-based indices into a row).
COLUMNS = ("radius", "length", "start_x", "start_y", "start_z", "axis_x", "axis_y", "axis_z", "parent",
           "extension", "branch", "branch_order", "position_in_branch")
#: Accepted widths of a row and what follows the 13 columns above.
WIDTHS = {14: "added", 16: "mad, SurfCov, added", 17: "mad, SurfCov, added, UnmodRadius"}
#: A model file larger than this is refused unread (a 100,000-cylinder text table is ~15 MB).
MAX_QSM_BYTES = 64 << 20
#: Most cylinders a model may have (the preset size budget's 200,000 objects, in cylinders).
MAX_CYLINDERS = 200_000


@dataclass(frozen=True)
class Species:
    """Leaves added procedurally to a scanned tree (``--leaves NAME``).

    Attributes
    ----------
    preset : str
        Shipped preset whose lamina outline, leaf and petiole sizes, angles, bark and physics
        ranges the species takes.
    per_metre : float
        Leaves per metre of twig (of the model's twigs; a QSM resolves no shoot finer than
        a centimetre or two, so this counts the leaves of the unresolved shoots too).
    twig_diameter : float
        Branch segments at most this thick (m) bear leaves, and every free tip.
    wood : str
        A key of :data:`~treeanim.model.params.WOOD_TYPES`.
    """

    preset: str
    per_metre: float
    twig_diameter: float = 0.04
    wood: str = "hardwood"


#: The leaf table: one entry per species ``--leaves`` accepts.
SPECIES = {
    "cherry": Species("large_cherry", per_metre=40.0),
    "tulip_poplar": Species("tulip_poplar", per_metre=25.0),
}
#: The preset whose physics (f and ζ ranges, drag gains) and bark a leafless model takes.
DEFAULT_PRESET = "large_cherry"


# ---------------------------------------------------------------------------- reading
def _problem(path, row: int | None, what: str, lines: np.ndarray | None = None) -> QSMError:
    where = ""
    if row is not None:
        where = f" row {row + 1}" + (f" (line {int(lines[row])})" if lines is not None else "") + ":"
    return QSMError(f"{path}:{where} {what}")


def _read_bytes(path: Path) -> bytes:
    try:
        info = os.stat(path)
        if not stat.S_ISREG(info.st_mode):
            raise QSMError(f"{path}: not a regular file (a QSM must be a .txt, .csv or .mat file)")
        if info.st_size > MAX_QSM_BYTES:
            raise QSMError(f"{path}: {info.st_size:,} bytes; a QSM file may have at most {MAX_QSM_BYTES:,}")
        with open(path, "rb") as f:
            return f.read(MAX_QSM_BYTES + 1)
    except OSError as e:
        raise QSMError(f"{path}: cannot read QSM file ({e.strerror or e})") from None


_SPLIT = re.compile(r"[\s,;]+")


def _read_text(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """(N, width) float table and each row's line number."""
    try:
        text = _read_bytes(path).decode("utf-8-sig")
    except UnicodeDecodeError:
        raise QSMError(f"{path}: not a UTF-8 text file") from None
    rows, numbers, header = [], [], True
    for n, line in enumerate(text.splitlines(), 1):
        line = line.strip()
        if not line or line[0] in "#%":
            continue
        fields = _SPLIT.split(line.strip(" ,;"))
        if header and not _numeric(fields[0]):  # the first line of words: a header, skipped
            header = False
            continue
        header = False
        rows.append(fields)
        numbers.append(n)
    lines = np.array(numbers, np.int64)
    if not rows:
        raise QSMError(f"{path}: empty table: no cylinder rows")
    widths = np.array([len(r) for r in rows])
    width = int(widths[0])
    bad = np.flatnonzero((widths != width) | ~np.isin(widths, list(WIDTHS)))
    if len(bad):
        k = int(bad[0])
        raise _problem(path, k, f"{widths[k]} columns; expected {_widths_text()}", lines)
    try:
        table = np.array(rows, dtype=float)
    except ValueError:
        for k, r in enumerate(rows):
            for c, x in enumerate(r):
                if not _numeric(x):
                    raise _problem(path, k, f"column {c + 1} ({_column_name(c)}) is {x[:20]!r}, not a number",
                                   lines) from None
        raise  # pragma: no cover - np.array failed on numbers float() accepts
    return table, lines


def _numeric(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def _column_name(c: int) -> str:
    return COLUMNS[c] if c < len(COLUMNS) else "a trailing column"


def _widths_text() -> str:
    return "14 (radius, length, start x y z, axis x y z, parent, extension, branch, branch order, position in " \
           "branch, added), 16 or 17 (TreeQSM 2.4's text export)"


def _read_mat(path: Path) -> np.ndarray:
    """The cylinder table of a MATLAB file: a ``cylinder`` struct or an (N, 14/16/17) matrix."""
    from scipy.io import loadmat, matlab

    _read_bytes(path)  # the same checks as text (a regular file, its size)
    try:
        data = loadmat(path, simplify_cells=True)
    except NotImplementedError:
        raise QSMError(f"{path}: a MATLAB v7.3 (HDF5) file; save the QSM with save(..., '-v7')") from None
    except (ValueError, TypeError, OSError, matlab.miobase.MatReadError) as e:
        raise QSMError(f"{path}: not a readable MATLAB .mat file ({' '.join(str(e).split())[:100]})") from None
    values = {k: v for k, v in data.items() if not k.startswith("__")}
    for holder in (values, values.get("QSM"), values.get("qsm")):
        if isinstance(holder, (list, np.ndarray)) and len(holder) and isinstance(holder[0], dict):
            holder = holder[0]  # an array of QSMs: the first
        if isinstance(holder, dict) and isinstance(holder.get("cylinder"), dict):
            return _from_struct(path, holder["cylinder"])
    matrices = [v for v in values.values() if isinstance(v, np.ndarray) and v.ndim == 2
                and v.shape[1] in WIDTHS and np.issubdtype(v.dtype, np.number)]
    if len(matrices) != 1:
        raise QSMError(f"{path}: expected a TreeQSM 'cylinder' struct (alone or in a 'QSM' struct) or one "
                       f"matrix of {_widths_text()} columns; found variables {', '.join(sorted(values)) or 'none'}")
    return np.asarray(matrices[0], float)


def _from_struct(path: Path, cyl: dict) -> np.ndarray:
    need = {"radius": 1, "length": 1, "start": 3, "axis": 3, "parent": 1, "extension": 1, "branch": 1,
            "BranchOrder": 1, "PositionInBranch": 1}
    optional = ("extension", "BranchOrder", "PositionInBranch")  # not used to build the tree
    n = None
    cols = {}
    for name, width in need.items():
        if name not in cyl:
            if name in optional:
                continue
            raise QSMError(f"{path}: the cylinder struct has no field {name!r}; expected {', '.join(need)}")
        try:
            v = np.asarray(cyl[name], float).reshape(-1, width)
        except (TypeError, ValueError):
            raise QSMError(f"{path}: cylinder field {name!r} is not an array of {width} number(s) a row") from None
        n = len(v) if n is None else n
        if len(v) != n:
            raise QSMError(f"{path}: cylinder field {name!r} has {len(v)} rows; 'radius' has {n}")
        cols[name] = v
    return np.hstack([cols.get(name, np.zeros((n, 1))) for name in need] + [np.zeros((n, 1))])  # + added


def read_table(path: str | Path) -> np.ndarray:
    """Read a TreeQSM cylinder table from a text or MATLAB file.

    Parameters
    ----------
    path : str or Path
        ``.mat`` for MATLAB, anything else is read as text.

    Returns
    -------
    numpy.ndarray, (N, 14, 16 or 17) float
        One cylinder a row, in the file's order and units.

    Raises
    ------
    QSMError
        Unreadable file, an empty table, a wrong column count, a field that is not a number.
    """
    path = Path(path)
    if path.suffix.lower() == ".mat":
        table = _read_mat(path)
    else:
        table = _read_text(path)[0]
    if len(table) == 0:
        raise QSMError(f"{path}: empty table: no cylinder rows")
    return table


# ---------------------------------------------------------------------------- checking
def _jump(pointer: np.ndarray, steps: int) -> np.ndarray:
    """Follow ``pointer`` (a fixed point at each root) ``2**steps`` times, by doubling."""
    p = pointer.copy()
    for _ in range(steps):
        p = p[p]
    return p


def _depths(parent: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(depth, root reached) of every row of a parent array (-1: root), by pointer doubling.

    A row in (or below) a cycle never reaches a root: its root is -1.
    """
    n = len(parent)
    idx = np.arange(n)
    anc = np.where(parent >= 0, parent, idx)
    dist = (parent >= 0).astype(np.int64)
    for _ in range(max(1, int(np.ceil(np.log2(n + 1)))) + 1):
        dist = dist + dist[anc]
        anc = anc[anc]
    root_ok = parent[anc] < 0
    return dist, np.where(root_ok, anc, -1)


def _check(table: np.ndarray, path, lines) -> tuple[np.ndarray, ...]:
    """Validate the columns used; return radius, length, start, unit axis, parent (0-based, -1
    root) and branch."""
    n = len(table)
    if n > MAX_CYLINDERS:
        raise QSMError(f"{path}: {n:,} cylinders; a model may have at most {MAX_CYLINDERS:,}")
    used = table[:, :11]
    bad = ~np.isfinite(used)
    bad[:, 9] = False  # extension is not used
    if bad.any():
        k, c = np.argwhere(bad)[0]
        raise _problem(path, k, f"{COLUMNS[c]} is {float(table[k, c])!r}; expected a finite number", lines)
    for c, what in ((0, "radius"), (1, "length")):
        k = np.flatnonzero(table[:, c] <= 0)
        if len(k):
            raise _problem(path, k[0], f"{what} is {float(table[k[0], c])!r}; expected a positive number of metres", lines)
    axis = table[:, 5:8]
    norm = np.linalg.norm(axis, axis=1)
    k = np.flatnonzero(norm < 1e-9)
    if len(k):
        raise _problem(path, k[0], "the axis is (0, 0, 0); expected a direction", lines)
    parent_raw = table[:, 8]
    k = np.flatnonzero((parent_raw != np.round(parent_raw)) | (parent_raw < 0) | (parent_raw > n))
    if len(k):
        raise _problem(path, k[0], f"parent {parent_raw[k[0]]:g} names no cylinder (orphan); expected 0 (the stem's "
                                   f"base) or a row number 1..{n}", lines)
    parent = parent_raw.astype(np.int64) - 1
    k = np.flatnonzero(parent == np.arange(n))
    if len(k):
        raise _problem(path, k[0], "is its own parent (a cycle)", lines)
    roots = np.flatnonzero(parent < 0)
    if len(roots) == 0:
        raise QSMError(f"{path}: no cylinder has parent 0, so the parents form a cycle; the stem's first "
                       "cylinder must have parent 0")
    if len(roots) > 1:
        raise _problem(path, roots[1], f"parent 0 (no parent), but row {roots[0] + 1} already starts the stem; "
                                       "every other cylinder needs a parent (orphan)", lines)
    _, root = _depths(parent)
    k = np.flatnonzero(root < 0)
    if len(k):
        raise _problem(path, k[0], "its parents lead round a cycle and never reach the stem's base", lines)
    branch = table[:, 10]
    k = np.flatnonzero(branch != np.round(branch))
    if len(k):
        raise _problem(path, k[0], f"branch {float(branch[k[0]])!r}; expected an integer", lines)
    return table[:, 0], table[:, 1], table[:, 2:5], axis / norm[:, None], parent, branch.astype(np.int64)


# ---------------------------------------------------------------------------- building
def _z_up_to_y_up(p: np.ndarray) -> np.ndarray:
    return np.stack([p[..., 0], p[..., 2], -p[..., 1]], axis=-1)


def _chains(parent: np.ndarray, branch: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each cylinder's chain head (the first cylinder of its object) and position in it.

    A cylinder continues its parent's object when it has the parent's branch number (the first
    such child in row order, should a branch fork); otherwise it starts an object.
    """
    n = len(parent)
    idx = np.arange(n)
    same = (parent >= 0) & (branch == branch[np.maximum(parent, 0)])
    cand = idx[same]
    first = np.ones(len(cand), bool)
    if len(cand):
        order = np.lexsort((cand, parent[cand]))
        p_sorted = parent[cand][order]
        dup = np.concatenate([[False], p_sorted[1:] == p_sorted[:-1]])
        first[order[dup]] = False
    cont = np.zeros(n, bool)
    cont[cand[first]] = True
    pointer = np.where(cont, parent, -1)
    return _depths(pointer)[::-1]


def build_tree(table: np.ndarray, name: str = "qsm", source: str = "", leaves: str | None = None,
               seed: int = 0, lines: np.ndarray | None = None) -> Tree:
    """A :class:`Tree` from a TreeQSM cylinder table.

    Parameters
    ----------
    table : (N, 14+) float array
        One cylinder a row (:func:`read_table`), z up, metres.
    name, source : str
        The tree's name and the file it came from (for messages).
    leaves : str or None
        None for a leafless tree, or a species (:func:`parse_leaves`): leaves along the twigs.
    seed : int
        Seed of the leaves' placement and of their fall order.
    lines : (N,) int, optional
        Each row's line in a text file, for messages.

    Returns
    -------
    Tree
        Branch objects (one per branch chain), then leaves; physics ranges, bark and leaves
        from the species' preset (:data:`DEFAULT_PRESET` when leafless), its wood from
        :data:`~treeanim.model.params.WOOD_TYPES`, and ``modes='physical'``: a scanned
        tree's size is known, so its frequencies come from beam theory unless told otherwise.

    Raises
    ------
    QSMError
        A malformed table: non-finite or non-positive radii or lengths, orphans, cycles, a
        segment of zero length.
    """
    path = source or name
    table = np.asarray(table, float)
    if table.ndim != 2 or len(table) == 0:
        raise QSMError(f"{path}: empty table: no cylinder rows")
    if table.shape[1] not in WIDTHS:
        raise QSMError(f"{path}: {table.shape[1]} columns; expected {_widths_text()}")
    radius, length, start, axis, parent, branch = _check(table, path, lines)
    species = parse_leaves(leaves)
    preset = _preset_spec(species.preset if species else DEFAULT_PRESET)

    head, pos = _chains(parent, branch)
    heads = np.flatnonzero(head == np.arange(len(head)))
    obj = np.searchsorted(heads, head)  # object of each cylinder
    order = np.lexsort((pos, obj))  # cylinders object by object, base to tip
    n_cyl = np.bincount(obj, minlength=len(heads))
    count = n_cyl + 1
    first_node = np.concatenate([[0], np.cumsum(count)[:-1]])
    end = start + length[:, None] * axis
    node_of_cyl = first_node[obj] + pos  # each cylinder's start node
    N = int(count.sum())
    P = np.empty((N, 3))
    P[node_of_cyl] = start
    last = order[np.cumsum(n_cyl) - 1]  # the last cylinder of each object
    tip = first_node + n_cyl
    P[tip] = end[last]
    r = np.empty(N)
    r[node_of_cyl] = radius
    r[tip] = radius[last]
    inner = node_of_cyl[pos > 0]  # where two cylinders of one object meet: their mean
    r[inner] = 0.5 * (radius[pos > 0] + radius[parent[pos > 0]])
    seg = np.linalg.norm(np.diff(P, axis=0), axis=1)
    within = np.ones(N - 1, bool)
    within[tip[:-1]] = False
    k = np.flatnonzero(within & (seg <= 1e-9))
    if len(k):  # node k to k + 1: the cylinder starting at k ends where it starts
        o = int(np.searchsorted(first_node, k[0], side="right") - 1)
        cyl = int(order[int(np.sum(n_cyl[:o])) + int(k[0] - first_node[o])])
        raise _problem(path, cyl, "a zero-length segment: the next cylinder of its branch starts where it starts "
                                  "(or it is shorter than a nanometre)", lines)

    # Parents: the node of the parent cylinder nearest the branch's start (its start or end).
    p_cyl = parent[heads]
    has_parent = p_cyl >= 0
    par_obj = np.where(has_parent, obj[np.maximum(p_cyl, 0)], -1)
    pc = np.maximum(p_cyl, 0)
    d_start = np.linalg.norm(start[heads] - start[pc], axis=1)
    d_end = np.linalg.norm(start[heads] - end[pc], axis=1)
    attach = pos[pc] + np.where((d_start < d_end) & (pos[pc] > 0), 0, 1)
    level, _ = _depths(par_obj)
    level = level + 1
    # Move each branch (and what grows on it) onto its attach node, outermost last.
    offset = np.zeros((len(heads), 3))
    for lv in range(2, int(level.max()) + 1):
        o = np.flatnonzero(level == lv)
        offset[o] = offset[par_obj[o]] + P[first_node[par_obj[o]] + attach[o]] - P[first_node[o]]
    P += np.repeat(offset, count, axis=0)
    root = first_node[obj[np.flatnonzero(parent < 0)[0]]]
    P = _z_up_to_y_up(P - P[root]) + 0.0  # (no -0.0)

    specs = [ObjectSpec(P[a:a + c], 2.0 * r[a:a + c], "branch", int(lv), parent=int(p), attach=int(at))
             for a, c, lv, p, at in zip(first_node, count, level, par_obj, attach)]
    lamina, winter = None, 0
    if species is not None:
        rng = np.random.default_rng([int(seed), 0x71736D])  # "qsm": the leaves' own stream
        specs, lf, slots = _leaf_rule(species, preset.leaves, specs)
        specs += place_leaves(lf, specs, slots, rng)
        la = preset.lamina
        lamina = make_lamina(la.shape, la.outline, la.samples, la.teeth, la.tooth_depth, la.curl)
        winter = int(round(lf.count * preset.leaves.winter_count / max(preset.leaves.count, 1)))
    wood = WOOD_TYPES[species.wood if species else "hardwood"]
    physics = dataclasses.replace(preset.physics, ei_max=_scaled_ei_max(preset, 2.0 * float(r.max())), **wood)
    try:
        return assemble(specs, name=name, lamina=lamina, petiole_sides=preset.leaves.petiole_sides,
                        winter_leaves=winter, physics=physics, seed=int(seed), source=str(source), bark=preset.bark,
                        modes="physical")
    except ValueError as e:  # pragma: no cover - the checks above leave nothing for validate to find
        raise QSMError(f"{path}: {e}") from None


#: Most leaves per metre of twig ``--leaves NAME:PER_METRE`` accepts.
MAX_PER_METRE = 1000.0


def parse_leaves(leaves: str | None) -> Species | None:
    """The species of ``--leaves``: None or 'none' (leafless), ``NAME`` (a key of
    :data:`SPECIES`) or ``NAME:PER_METRE`` (its leaves per metre of twig overridden).

    Raises
    ------
    QSMError
        An unknown species or a count that is not a number in (0, :data:`MAX_PER_METRE`].
    """
    if leaves is None or leaves == "none":
        return None
    name, _, count = str(leaves).partition(":")
    if name not in SPECIES:
        raise QSMError(f"--leaves {leaves!r}: unknown species; expected none or one of {', '.join(SPECIES)} "
                       "(optionally NAME:LEAVES_PER_METRE)")
    species = SPECIES[name]
    if count:
        try:
            per_metre = float(count)
        except ValueError:
            per_metre = float("nan")
        if not 0 < per_metre <= MAX_PER_METRE:
            raise QSMError(f"--leaves {leaves!r}: expected leaves per metre of twig in (0, {MAX_PER_METRE:g}] "
                           f"after the colon, got {count!r}")
        species = dataclasses.replace(species, per_metre=per_metre)
    return species


def _preset_spec(name: str):
    from importlib import resources

    from .presets import read_spec

    with resources.as_file(resources.files("treeanim.presets") / f"{name}.toml") as p:
        return read_spec(p)


def _scaled_ei_max(preset, d_max: float) -> float:
    """The preset's EI_max (Eq. 10, the paper's model) scaled to this trunk as D⁴."""
    return float(min(preset.physics.ei_max * (d_max / preset.levels[0].diameter) ** 4, 1e12))


#: Longest stretch of twig (m) between leaf-bearing nodes: leaf-bearing cylinders are cut into
#: segments this long at most (straight, the same wood), so leaves spread along a twig instead
#: of bunching at cylinder joints half a metre apart.
LEAF_SPACING = 0.1


def _leaf_rule(species: Species, leaf: LeafSpec, branches: list[ObjectSpec]) -> tuple[list, LeafSpec, tuple]:
    """The branches with their leaf-bearing segments cut to :data:`LEAF_SPACING`, the leaf-bearing
    nodes (ends of segments at most ``twig_diameter`` thick, and free tips) and the species'
    leaves with a count of ``per_metre`` × the twig length they serve."""
    grown_on = {(s.parent, s.attach) for s in branches}
    cut, node_map = [], []
    for i, s in enumerate(branches):  # cut the leaf-bearing segments
        seg = np.linalg.norm(np.diff(s.points, axis=0), axis=1)
        bear = 0.5 * (s.diameters[1:] + s.diameters[:-1]) <= species.twig_diameter
        bear[-1] |= (i, len(seg)) not in grown_on
        k = np.where(bear, np.maximum(1, np.ceil(seg / LEAF_SPACING - 1e-9)).astype(int), 1)
        t = np.concatenate([np.arange(n) / n for n in k] + [[0.0]])
        a = np.append(np.repeat(np.arange(len(seg)), k), len(seg) - 1)
        t[-1] = 1.0
        pts = s.points[a] + t[:, None] * (s.points[np.minimum(a + 1, len(seg))] - s.points[a])
        dia = s.diameters[a] + t * (s.diameters[np.minimum(a + 1, len(seg))] - s.diameters[a])
        node_map.append(np.concatenate([[0], np.cumsum(k)]))
        cut.append((pts, dia, np.repeat(bear, k), np.repeat(np.arange(len(seg)) == len(seg) - 1, k)))
    out, b, j, served, free = [], [], [], [], []
    for i, (s, (pts, dia, bear, last)) in enumerate(zip(branches, cut)):
        attach = int(node_map[s.parent][s.attach]) if s.parent >= 0 else s.attach
        out.append(dataclasses.replace(s, points=pts, diameters=dia, attach=attach))
        nodes = np.flatnonzero(bear) + 1
        b.append(np.full(len(nodes), i))
        j.append(nodes)
        served.append(np.linalg.norm(pts[nodes] - pts[nodes - 1], axis=1))
        free.append((nodes == len(pts) - 1) & ((i, len(s.points) - 1) not in grown_on))
    slots = (np.concatenate(b).astype(np.int64), np.concatenate(j).astype(np.int64),
             np.concatenate(served).astype(float), np.concatenate(free).astype(bool))
    count = int(round(species.per_metre * float(slots[2].sum()) / max(1.0 - leaf.tip_share, 1e-9)))
    return out, dataclasses.replace(leaf, count=max(count, 1), levels=()), slots


def load_qsm(path: str | Path, leaves: str | None = None, seed: int = 0) -> Tree:
    """Read a TreeQSM model (text or ``.mat``) and build its tree.

    Parameters
    ----------
    path : str or Path
        ``.txt``, ``.csv`` (text) or ``.mat``.
    leaves : str or None
        None (leafless) or a species (:func:`parse_leaves`).
    seed : int
        Seed of the leaves.

    Returns
    -------
    Tree

    Raises
    ------
    QSMError
        One line naming the file, the row and what was wrong.
    """
    path = Path(path)
    lines = None
    if path.suffix.lower() == ".mat":
        table = read_table(path)
    else:
        table, lines = _read_text(path)
    try:
        return build_tree(table, name=path.stem, source=str(path), leaves=leaves, seed=seed, lines=lines)
    except QSMError:
        raise
    except PresetError as e:  # pragma: no cover - a shipped preset that does not read
        raise QSMError(f"{path}: {e}") from None


def load_file(path: str | Path, leaves: str | None = None) -> Tree:
    """A tree from a file: a TreeQSM model by its suffix (:data:`QSM_SUFFIXES`), else a preset
    TOML file (:func:`~treeanim.model.presets.load_tree`).

    Raises
    ------
    PresetError
        The file's one-line problem (a :class:`QSMError` for a model); ``leaves`` for a preset.
    """
    if str(path).lower().endswith(QSM_SUFFIXES):
        return load_qsm(path, leaves=leaves)
    if leaves not in (None, "none"):
        raise PresetError(f"{path}: --leaves is for TreeQSM models (.txt, .csv, .mat); a preset has its own leaves")
    from .presets import load_tree

    return load_tree(path)


# ---------------------------------------------------------------------------- writing, synthetic trees
def write_table(path: str | Path, table: np.ndarray, header: bool = True) -> None:
    """Write a cylinder table as TreeQSM-style text (14 columns, one cylinder a line).

    Parameters
    ----------
    path : str or Path
    table : (N, 14) float
    header : bool
        Write a header line of column names first.
    """
    names = "radius length start_x start_y start_z axis_x axis_y axis_z parent extension branch branch_order " \
            "position_in_branch added"
    fmt = ["%.6f"] * 8 + ["%d"] * 6
    np.savetxt(path, np.asarray(table), fmt=fmt, header=names if header else "", comments="")


def synthetic_table(height: float = 15.0, dbh: float = 0.4, limbs: int = 10, twigs: int = 4, sub_twigs: int = 0,
                    cylinder_length: float = 0.5, seed: int = 0) -> np.ndarray:
    """A TreeQSM-like table of a known, made-up broadleaf tree (z up, metres).

    A straight vertical stem of ``height`` in cylinders of about ``cylinder_length``, tapering
    linearly so that its diameter at 1.3 m is ``dbh``; ``limbs`` order-1 branches along its upper
    60 %, longest low down, each carrying ``twigs`` order-2 branches along its outer half, each of
    those ``sub_twigs`` order-3 ones. A branch starts at the end of its parent cylinder (so it
    imports with no offset) and its base radius is 0.6 (limbs) or 0.7 of its parent's there.

    Parameters
    ----------
    height, dbh : float
        Stem length (m) and diameter at breast height (m).
    limbs, twigs, sub_twigs : int
        Branches per level.
    cylinder_length : float
        Longest cylinder (m); each branch is cut into equal cylinders no longer than this.
    seed : int
        Seed of the small random turns of azimuth and elevation.

    Returns
    -------
    numpy.ndarray, (N, 14) float
        Columns as :data:`COLUMNS` plus ``added`` (0); parents and branches 1-based.
    """
    rng = np.random.default_rng(seed)
    rows: list[np.ndarray] = []
    taper = 0.9 / height
    r_stem = 0.5 * dbh / (1 - taper * 1.3)  # the stem's radius at its base

    def add(base, direction, length, r0, r1, parent_row, branch_no, order, bend):
        n = max(1, int(np.ceil(length / cylinder_length - 1e-9)))
        t = np.arange(n) / n
        up = np.array([0.0, 0.0, 1.0])
        d = np.asarray(direction, float)
        # Turn the branch upward along its length by ``bend`` radians (in the plane of d and z).
        side = np.cross(d, up)
        side = side / np.linalg.norm(side) if np.linalg.norm(side) > 1e-9 else np.array([1.0, 0.0, 0.0])
        ang = bend * (t + 0.5 / n)
        dirs = d * np.cos(ang)[:, None] + np.cross(side, d) * np.sin(ang)[:, None]
        dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
        h = length / n
        starts = base + np.concatenate([[np.zeros(3)], np.cumsum(dirs * h, axis=0)[:-1]])
        radii = r0 + (r1 - r0) * (t + 0.5 / n)
        first = len(rows) + 1
        for i in range(n):
            parent = parent_row if i == 0 else first + i - 1
            ext = first + i + 1 if i < n - 1 else 0
            rows.append(np.array([radii[i], h, *starts[i], *dirs[i], parent, ext, branch_no, order, i + 1, 0.0]))
        return first, n, starts, dirs, h, radii

    stem_first, n_stem, s_starts, _, s_h, s_r = add(np.zeros(3), (0, 0, 1), height, r_stem,
                                                    r_stem * (1 - taper * height), 0, 1, 0, 0.0)
    branch_no = 1
    level = [(stem_first, n_stem, s_starts, s_h, s_r, height)]
    counts = (limbs, twigs, sub_twigs)
    ranges = ((0.4, 0.95), (0.45, 0.95), (0.5, 0.95))
    for order, per in enumerate(counts, start=1):
        nxt = []
        for first, n, starts, h, radii, plen in level:
            if per <= 0:
                continue
            lo, hi = ranges[order - 1]
            cyl = np.unique(np.clip(np.round(np.linspace(lo, hi, per) * n - 1).astype(int), 0, n - 1))
            for k, c in enumerate(cyl):
                frac = (c + 1) / n
                az = rng.uniform(0, 2 * np.pi) if order > 1 else k * np.radians(137.5)
                elev = np.radians(rng.uniform(20, 40) if order == 1 else rng.uniform(0, 30))
                parent_dir = np.asarray(rows[first - 1 + c][5:8])
                horiz = np.array([np.cos(az), np.sin(az), 0.0])
                horiz -= parent_dir * (horiz @ parent_dir)
                horiz /= np.linalg.norm(horiz)
                d = horiz * np.cos(elev) + np.array([0.0, 0.0, 1.0]) * np.sin(elev)
                d /= np.linalg.norm(d)
                L = plen * (0.45 * (1.25 - frac) if order == 1 else 0.45 * (1.2 - 0.5 * frac))
                base = starts[c] + h * np.asarray(rows[first - 1 + c][5:8])
                r0 = radii[c] * (0.6 if order == 1 else 0.7)
                branch_no += 1
                got = add(base, d, L, r0, 0.3 * r0, first + c, branch_no, order, np.radians(15.0))
                nxt.append((got[0], got[1], got[2], got[4], got[5], L))
        level = nxt
    return np.array(rows)
