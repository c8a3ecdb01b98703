"""Assemble a :class:`Tree` from a list of objects, sorting them by level."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .geometry import perpendicular, unit
from .tree import Tree

__all__ = ["ObjectSpec", "assemble", "eq1_w", "perpendicular", "KIND_ORDER"]

#: Within a level objects sort by kind in this order (:func:`assemble`, and
#: :func:`treeanim.model.scene.merge_trees` over a whole scene).
KIND_ORDER = {"branch": 0, "blade": 1, "leaf": 2}


@dataclass
class ObjectSpec:
    """One object before assembly.

    Attributes
    ----------
    points : (n, 3) float
        Node positions root to tip (n >= 2).
    diameters : (n,) float
        Diameter at each node.
    kind : str
        'branch', 'leaf' or 'blade'.
    level : int
        Hierarchy level (1 = trunk).
    parent : int
        Index of the parent in the spec list (-1 for roots).
    attach : int
        Index of the parent's node (within the parent) that the base sits on.
    w : (3,) float or None
        Rest w axis; None computes Eq. 1 (P0Pn x v), or a fixed perpendicular when straight.
    lamina_length : float
        Lamina midrib length for leaves.
    """

    points: np.ndarray
    diameters: np.ndarray
    kind: str = "branch"
    level: int = 1
    parent: int = -1
    attach: int = 0
    w: np.ndarray | None = None
    lamina_length: float = 0.0


def eq1_w(points: np.ndarray) -> np.ndarray:
    """Eq. 1's w = P0Pn x v / |P0Pn x v| for one object; a fixed perpendicular when straight.

    Parameters
    ----------
    points : (n, 3) float
        The object's nodes, root to tip (n >= 2).

    Returns
    -------
    numpy.ndarray, (3,) float
        Unit w axis.
    """
    points = np.asarray(points, float)
    v = unit(points[1] - points[0])
    w = np.cross(points[-1] - points[0], v)
    n = np.linalg.norm(w)
    if n < 1e-6 * np.linalg.norm(points[-1] - points[0]) or n < 1e-12:
        return perpendicular(v)
    return w / n


def assemble(specs: list[ObjectSpec], **tree_kw) -> Tree:
    """Build a level-sorted :class:`Tree` from object specs.

    Objects are stably sorted by (level, kind order branch < blade < leaf) so each level is one
    contiguous slice; parents are remapped and attach nodes become global node indices.

    Parameters
    ----------
    specs : list of ObjectSpec
        Parents must have a lower level than their children.
    **tree_kw
        Passed to :class:`Tree` (name, lamina, physics, ...).

    Returns
    -------
    Tree
        The validated tree.

    Raises
    ------
    ValueError
        If the assembled tree breaks a structural invariant (:meth:`Tree.validate`).
    """
    order = sorted(range(len(specs)), key=lambda i: (specs[i].level, KIND_ORDER[specs[i].kind]))
    new_index = np.empty(len(specs), dtype=np.int64)
    new_index[order] = np.arange(len(specs))
    sorted_specs = [specs[i] for i in order]

    counts = np.array([len(s.points) for s in sorted_specs], dtype=np.int64)
    starts = np.concatenate([[0], np.cumsum(counts)[:-1]]).astype(np.int64)
    parent = np.array([new_index[s.parent] if s.parent >= 0 else -1 for s in sorted_specs], dtype=np.int64)
    attach = np.array(
        [starts[p] + s.attach if p >= 0 else -1 for s, p in zip(sorted_specs, parent)], dtype=np.int64
    )
    positions = np.concatenate([np.asarray(s.points, float) for s in sorted_specs])
    diam = np.concatenate([np.asarray(s.diameters, float) for s in sorted_specs])
    # The base node of a child repeats its parent's attach node exactly.
    has_parent = parent >= 0
    positions[starts[has_parent]] = positions[attach[has_parent]]
    rest_w = np.array(
        [s.w / np.linalg.norm(s.w) if s.w is not None else eq1_w(np.asarray(s.points, float)) for s in sorted_specs]
    ).reshape(-1, 3)
    kind = np.array([s.kind for s in sorted_specs], dtype="<U6")
    leaf = kind == "leaf"
    rank = np.full(len(specs), -1, dtype=np.int64)
    tree_seed = int(tree_kw.get("seed", 0))
    rank[leaf] = np.random.default_rng([tree_seed, 7]).permutation(int(leaf.sum()))
    tree = Tree(
        rest_positions=positions,
        node_diameter=diam,
        object_start=starts,
        object_count=counts,
        parent=parent,
        attach_node=attach,
        level=np.array([s.level for s in sorted_specs], dtype=np.int64),
        kind=kind,
        rest_w=rest_w,
        lamina_length=np.array([s.lamina_length for s in sorted_specs], float),
        leaf_drop_rank=rank,
        **tree_kw,
    )
    tree.validate()
    return tree
