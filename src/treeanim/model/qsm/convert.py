"""A TreeQSM table into a :class:`~treeanim.model.tree.Tree`: checks, branch chains, z up to y up."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np

from ...errors import PresetError, QSMError
from ..build import ObjectSpec, assemble
from ..generate import place_leaves
from ..lamina import make_lamina
from ..params import WOOD_TYPES
from ..tree import Tree
from .leaves import DEFAULT_PRESET, _leaf_rule, _preset_spec, _scaled_ei_max, parse_leaves
from .read import COLUMNS, MAX_CYLINDERS, WIDTHS, _problem, _read_text, _widths_text, read_table

# ---------------------------------------------------------------------------- checking
#: A cylinder's radius and length (m): from a tenth of a millimetre (TreeQSM resolves a few
#: millimetres) to the largest trunks and the tallest trees' longest pieces.
MIN_RADIUS, MAX_RADIUS, MAX_LENGTH = 1e-4, 10.0, 150.0
#: How far from the origin a cylinder may start (m): georeferenced scans (UTM) lie within it.
MAX_COORDINATE = 1e7
#: How far apart a tree's cylinders may start (m).
MAX_SPAN = 1000.0
#: Largest branch number (every whole number up to it is exact in a float and fits an int64).
MAX_BRANCH = 2.0 ** 53


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
    for c, what, lo, hi in ((0, "radius", MIN_RADIUS, MAX_RADIUS), (1, "length", MIN_RADIUS, MAX_LENGTH)):
        k = np.flatnonzero(~((table[:, c] >= lo) & (table[:, c] <= hi)))
        if len(k):
            raise _problem(path, k[0], f"{what} is {float(table[k[0], c]):.6g}; expected {lo:g} to {hi:g} m",
                           lines)
    k = np.flatnonzero(np.abs(table[:, 2:5]).max(axis=1) > MAX_COORDINATE)
    if len(k):
        raise _problem(path, k[0], f"the start ({', '.join(f'{v:.6g}' for v in table[k[0], 2:5])}) is more than "
                                   f"{MAX_COORDINATE:g} m from the origin", lines)
    span = float(np.max(np.ptp(table[:, 2:5], axis=0)))
    if span > MAX_SPAN:
        raise QSMError(f"{path}: the cylinders' starts span {span:.6g} m; one tree spans at most {MAX_SPAN:g} m")
    # The axis is a direction: scaled by its largest component before its length is taken, so
    # that neither 1e300 (its square overflowed) nor a subnormal one loses it
    scale = np.abs(table[:, 5:8]).max(axis=1)
    k = np.flatnonzero(scale == 0)
    if len(k):
        raise _problem(path, k[0], "the axis is (0, 0, 0); expected a direction", lines)
    axis = table[:, 5:8] / scale[:, None]
    axis /= np.linalg.norm(axis, axis=1)[:, None]
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
    k = np.flatnonzero((branch != np.round(branch)) | (np.abs(branch) > MAX_BRANCH))
    if len(k):  # (1e300 is a whole number too, but none an int64 holds)
        raise _problem(path, k[0], f"branch {float(branch[k[0]])!r}; expected an integer of at most "
                                   f"{MAX_BRANCH:.0f} (a branch number)", lines)
    return table[:, 0], table[:, 1], table[:, 2:5], axis, parent, branch.astype(np.int64)

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

