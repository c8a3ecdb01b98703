"""Scenes: many trees placed in one simulation (docs/design.md §17).

A :class:`Scene` *is* a :class:`~treeanim.model.tree.Tree`: the objects of every placed tree
concatenated (parents and attach nodes offset, then sorted by level as every tree is), so the
simulation, the renderer, picking and export take it as they take one tree, and the tree
model steps all of its trees together in one call (a hierarchy with many roots, as a meadow's
blades already are). What a scene adds is which tree each object belongs to
(:attr:`Scene.object_tree`) and where each tree stands (:attr:`Scene.placements`).

:func:`place_tree` moves one tree: scaled about its root, turned about +y by its heading and
set down at its position. :func:`merge_trees` joins placed trees into a scene;
:func:`make_scene` does both. Scene files (TOML) are read by :mod:`treeanim.model.scene_file`.
"""

from __future__ import annotations

import dataclasses
import numbers
from dataclasses import dataclass, field

import numpy as np

from ..validate import finite_float, finite_vector3
from .build import KIND_ORDER
from .params import PhysicsParams, SeasonModes
from .tree import KINDS, Tree

__all__ = ["Placement", "Scene", "MergeError", "object_trees", "place_tree", "merge_trees", "make_scene", "heading_matrix",
           "same_lamina", "MAX_SCALE", "MIN_SCALE", "MAX_COORDINATE"]

#: The least and largest scale a tree may be placed at (a seedling of a preset to a giant).
MIN_SCALE, MAX_SCALE = 0.05, 20.0
#: How far from the origin a tree may stand (m): a landscape of 20 km.
MAX_COORDINATE = 10_000.0


class MergeError(ValueError):
    """:func:`merge_trees`' refusal of one of its trees; ``index`` is that tree's place in the
    list (a scene file's reader names its table with it)."""

    def __init__(self, message: str, index: int):
        super().__init__(message)
        self.index = index


@dataclass(frozen=True)
class Placement:
    """Where one tree of a scene stands and what it is.

    Attributes
    ----------
    tree : str
        What was placed: a preset's name or a file (a preset .toml or a TreeQSM model).
    position : (float, float, float)
        Its root's world position (m, y up).
    heading : float
        Its turn about +y (degrees, counter-clockwise seen from above).
    scale : float
        Its size relative to the tree as generated.
    seed : int
        The seed it was generated with (a TreeQSM model: its leaves' seed).
    leaves : str or None
        A TreeQSM model's leaves (None: a preset, or the model as scanned).
    """

    tree: str
    position: tuple[float, float, float] = (0.0, 0.0, 0.0)
    heading: float = 0.0
    scale: float = 1.0
    seed: int = 0
    leaves: str | None = None


@dataclass(eq=False)
class Scene(Tree):
    """Trees placed together: one :class:`Tree` of all their objects, and which is whose.

    Attributes
    ----------
    object_tree : (M,) int
        The placed tree each object belongs to, ``0 .. n_trees - 1``.
    placements : tuple of Placement
        Each tree's position, heading, scale and seed, in tree order.
    description : str
        What the scene is (its file's ``description``).

    Notes
    -----
    Objects are sorted by level over the whole scene, so one tree's objects (and nodes) are not
    contiguous: :meth:`tree_nodes` and :meth:`tree_objects` give their indices. A scene holds
    one :class:`~treeanim.model.params.PhysicsParams`, one lamina and one bark
    (:func:`merge_trees`).
    """

    object_tree: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    placements: tuple[Placement, ...] = ()
    description: str = ""

    @property
    def n_trees(self) -> int:
        """Number of placed trees."""
        return len(self.placements)

    @property
    def node_tree(self) -> np.ndarray:
        """(N,) int: the placed tree each node belongs to."""
        return np.repeat(self.object_tree, self.object_count)

    def _tree_index(self, k) -> int:
        if isinstance(k, bool) or not isinstance(k, numbers.Integral):
            raise ValueError(f"tree index k must be an integer, got {k!r}")
        if not 0 <= int(k) < self.n_trees:
            raise ValueError(f"tree index k={int(k)} is out of range: the scene has {self.n_trees} trees")
        return int(k)

    def tree_objects(self, k: int) -> np.ndarray:
        """Object indices of tree ``k``, in object order (its trunk first).

        Raises
        ------
        ValueError
            If ``k`` is not an integer in ``range(n_trees)``.
        """
        return np.flatnonzero(self.object_tree == self._tree_index(k))

    def tree_nodes(self, k: int) -> np.ndarray:
        """Node indices of tree ``k`` (rows of ``rest_positions`` and ``Simulation.positions``),
        in node order.

        Raises
        ------
        ValueError
            If ``k`` is not an integer in ``range(n_trees)``.
        """
        objs = self.tree_objects(k)  # each object's nodes are contiguous, in object order
        count = np.asarray(self.object_count)[objs]
        first = np.asarray(self.object_start)[objs] - (np.cumsum(count) - count)
        return (np.repeat(first, count) + np.arange(int(count.sum()))).astype(np.int64)

    def validate(self) -> None:
        """:meth:`Tree.validate`, and every object in a tree whose parent is in the same tree."""
        super().validate()
        ot = np.asarray(self.object_tree)
        if ot.shape != (self.n_objects,) or (len(ot) and (ot.min() < 0 or ot.max() >= self.n_trees)):
            raise ValueError("object_tree does not give every object a tree of the scene")
        has = self.parent >= 0
        if np.any(ot[has] != ot[self.parent[has]]):
            raise ValueError("an object's parent belongs to another tree")


def object_trees(tree: Tree) -> np.ndarray:
    """(M,) int: the placed tree each object belongs to (:attr:`Scene.object_tree`; all 0 for a
    single tree)."""
    return tree.object_tree if isinstance(tree, Scene) else np.zeros(tree.n_objects, np.int64)


def heading_matrix(heading: float) -> np.ndarray:
    """(3, 3) rotation by ``heading`` degrees about +y (counter-clockwise seen from above: +x
    turns toward -z)."""
    a = np.radians(heading)
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def place_tree(tree: Tree, position=(0.0, 0.0, 0.0), heading: float = 0.0, scale: float = 1.0) -> Tree:
    """A copy of ``tree`` scaled about the origin (its root), turned by ``heading`` about +y and
    moved to ``position``.

    A node at rest position p goes to ``position + R @ (scale * p)``, R :func:`heading_matrix`;
    diameters and lamina lengths scale, the leaves' and beams' w axes turn with R.

    Parameters
    ----------
    tree : Tree
    position : (3,) float
        World metres, each within :data:`MAX_COORDINATE`. The ground stays at y = 0 (the drawn
        ground and the branches' contact floor, ``physics.structure``, are absolute): a y other
        than 0 lifts the tree off it or sinks it in (scene files refuse one).
    heading : float
        Degrees about +y.
    scale : float
        In [:data:`MIN_SCALE`, :data:`MAX_SCALE`].

    Returns
    -------
    Tree
        A new tree (the input is not changed); a Scene input is refused.

    Raises
    ------
    ValueError
        A non-finite or out-of-range position, heading or scale.
    """
    if not isinstance(tree, Tree) or isinstance(tree, Scene):
        raise ValueError(f"tree must be a treeanim Tree (not a scene), got {type(tree).__name__}")
    pos = finite_vector3("position", position)
    if np.abs(pos).max() > MAX_COORDINATE:
        raise ValueError(f"position must lie within {MAX_COORDINATE:g} m of the origin, got {pos.tolist()}")
    heading = finite_float("heading", heading)
    scale = finite_float("scale", scale)
    if not MIN_SCALE <= scale <= MAX_SCALE:
        raise ValueError(f"scale must be in [{MIN_SCALE:g}, {MAX_SCALE:g}], got {scale!r}")
    R = heading_matrix(heading)
    return dataclasses.replace(
        tree,
        rest_positions=pos + (scale * np.asarray(tree.rest_positions, float)) @ R.T,
        rest_w=np.asarray(tree.rest_w, float) @ R.T,
        node_diameter=scale * np.asarray(tree.node_diameter, float),
        lamina_length=scale * np.asarray(tree.lamina_length, float),
    )


def same_lamina(a, b) -> bool:
    """Whether two laminas are the same leaf shape (outline, triangles and curl)."""
    return (a.curl == b.curl and np.array_equal(a.outline, b.outline)
            and np.array_equal(a.triangles, b.triangles))


def _scene_physics(trees: list[Tree]) -> PhysicsParams:
    """The first tree's physics, each season's f/ζ range of a kind taken from the first tree
    that has the kind."""
    first = trees[0].physics
    seasons = {}
    for season in ("summer", "winter"):
        ranges = {}
        for kind in KINDS:
            ranges[kind] = next((getattr(t.physics, season).of(kind) for t in trees
                                 if getattr(t.physics, season).of(kind) is not None), None)
        seasons[season] = SeasonModes(**ranges)
    return dataclasses.replace(first, **seasons)


def merge_trees(trees: list[Tree], placements=None, name: str = "scene", seed: int = 0, source: str = "",
                description: str = "", labels=None) -> Scene:
    """Join placed trees into one :class:`Scene`.

    Objects are concatenated (parents and attach nodes offset) and stably sorted by level and
    kind over the whole scene, so each level is one slice as in every tree. The scene takes the
    first tree's physics (its wood, leaves and air: the tree model's settings, the same in
    every shipped preset), with each kind's f/ζ ranges from the first tree that has the kind;
    its bark and petiole sides from the first tree; the leaves' lamina from the first leafy
    tree, which every leafy tree must share (the renderer draws one leaf shape). Leaves fall
    in each tree's own order, interleaved so every tree loses the same share with the season.

    Parameters
    ----------
    trees : list of Tree
        Placed trees (:func:`place_tree`), at least one; no Scene among them.
    placements : list of Placement, optional
        One per tree (default: each at the origin, its own seed).
    name, seed, source, description :
        The scene's.
    labels : list of str, optional
        What to call each tree in a message (default ``'tree k'``; a scene file's reader
        passes each tree's table, ``'scatter[0] tree 17'``).

    Returns
    -------
    Scene

    Raises
    ------
    MergeError
        A scene among the trees, or a leafy tree whose lamina is not the first leafy tree's;
        its ``index`` is that tree's.
    ValueError
        No trees, or placements or labels that do not match the trees.
    """
    trees = list(trees)
    if not trees:
        raise ValueError("a scene needs at least one tree")
    for k, t in enumerate(trees):
        if not isinstance(t, Tree) or isinstance(t, Scene):
            raise MergeError(f"trees[{k}] must be a treeanim Tree (not a scene), got {type(t).__name__}", k)
    if placements is None:
        placements = [Placement(t.name, seed=int(t.seed)) for t in trees]
    placements = tuple(placements)
    labels = [f"tree {k}" for k in range(len(trees))] if labels is None else list(labels)
    if not len(placements) == len(labels) == len(trees):
        raise ValueError(f"{len(placements)} placements and {len(labels)} labels for {len(trees)} trees")
    leafy = [k for k, t in enumerate(trees) if t.lamina is not None and np.any(t.kind == "leaf")]
    lamina = trees[leafy[0]].lamina if leafy else next((t.lamina for t in trees if t.lamina is not None), None)
    for k in leafy[1:]:
        if trees[k].lamina is not lamina and not same_lamina(trees[k].lamina, lamina):
            first = leafy[0]
            raise MergeError(f"{labels[k]} ({placements[k].tree}) has leaves of another shape "
                             f"({trees[k].lamina.shape!r}) than {labels[first]} ({placements[first].tree}: "
                             f"{lamina.shape!r}); a scene's leaves share one outline (the renderer draws one "
                             "leaf shape)", k)

    counts = [t.n_objects for t in trees]
    node_off = np.cumsum([0] + [t.n_nodes for t in trees])
    obj_off = np.cumsum([0] + counts)
    cat = np.concatenate
    start = cat([t.object_start + node_off[k] for k, t in enumerate(trees)])
    count = cat([t.object_count for t in trees])
    parent = cat([np.where(t.parent >= 0, t.parent + obj_off[k], -1) for k, t in enumerate(trees)])
    attach = cat([np.where(t.attach_node >= 0, t.attach_node + node_off[k], -1) for k, t in enumerate(trees)])
    level = cat([t.level for t in trees])
    kind = cat([t.kind for t in trees]).astype("<U6")
    owner = np.repeat(np.arange(len(trees)), counts)
    # the leaves' drop order: each tree's own, interleaved by the share of its leaves fallen
    rank = cat([t.leaf_drop_rank for t in trees])
    n_leaves = np.array([int(np.count_nonzero(t.kind == "leaf")) for t in trees])
    leaf = kind == "leaf"
    share = (rank[leaf] + 0.5) / np.maximum(n_leaves[owner[leaf]], 1)
    global_rank = np.full(len(rank), -1, np.int64)
    global_rank[np.flatnonzero(leaf)[np.lexsort((owner[leaf], share))]] = np.arange(int(leaf.sum()))

    # sort objects by (level, kind) over the scene, stably (tree order within a key)
    key = level * 3 + np.vectorize(KIND_ORDER.get, otypes=[np.int64])(kind) if len(kind) else level
    order = np.argsort(key, kind="stable")
    M, N = len(order), int(node_off[-1])
    inv = np.empty(M, np.int64)
    inv[order] = np.arange(M)
    new_count = count[order]
    new_start = cat([[0], np.cumsum(new_count)[:-1]]).astype(np.int64)
    old_node = np.repeat(start[order] - new_start, new_count) + np.arange(N)  # new node j was old_node[j]
    new_node = np.empty(N, np.int64)
    new_node[old_node] = np.arange(N)
    par = parent[order]
    att = attach[order]
    scene = Scene(
        name=name,
        rest_positions=cat([t.rest_positions for t in trees])[old_node],
        node_diameter=cat([t.node_diameter for t in trees])[old_node],
        object_start=new_start,
        object_count=new_count.astype(np.int64),
        parent=np.where(par >= 0, inv[np.maximum(par, 0)], -1).astype(np.int64),
        attach_node=np.where(att >= 0, new_node[np.maximum(att, 0)], -1).astype(np.int64),
        level=level[order].astype(np.int64),
        kind=kind[order],
        rest_w=cat([t.rest_w for t in trees])[order],
        lamina_length=cat([t.lamina_length for t in trees])[order],
        leaf_drop_rank=global_rank[order],
        winter_leaves=int(sum(t.winter_leaves for t in trees)),
        lamina=lamina,
        petiole_sides=trees[0].petiole_sides,
        physics=_scene_physics(trees),
        seed=int(seed),
        source=str(source),
        bark=trees[0].bark,
        modes="paper",
        object_tree=owner[order].astype(np.int64),
        placements=placements,
        description=str(description),
    )
    scene.validate()
    return scene


def make_scene(trees, positions=None, headings=None, scales=None, name: str = "scene", seed: int = 0) -> Scene:
    """Place trees and join them into a :class:`Scene` (:func:`place_tree`, :func:`merge_trees`).

    Parameters
    ----------
    trees : list of Tree
        The trees as generated (each at the origin).
    positions : (K, 3) float, optional
        Each tree's root position (default: all at the origin).
    headings, scales : (K,) float, optional
        Degrees about +y (default 0) and sizes (default 1).
    name, seed :
        The scene's.

    Returns
    -------
    Scene

    Raises
    ------
    ValueError
        Lengths that differ, a bad position, heading or scale (:func:`place_tree`), or what
        :func:`merge_trees` refuses.
    """
    trees = list(trees)
    K = len(trees)
    positions = [(0.0, 0.0, 0.0)] * K if positions is None else list(positions)
    headings = [0.0] * K if headings is None else list(headings)
    scales = [1.0] * K if scales is None else list(scales)
    if not len(positions) == len(headings) == len(scales) == K:
        raise ValueError(f"{K} trees need {K} positions, headings and scales, got {len(positions)}, "
                         f"{len(headings)} and {len(scales)}")
    placed, where = [], []
    for k, (t, p, h, s) in enumerate(zip(trees, positions, headings, scales)):
        try:
            placed.append(place_tree(t, p, h, s))
        except ValueError as e:
            raise ValueError(f"trees[{k}]: {e}") from None
        where.append(Placement(t.name, tuple(float(v) for v in np.asarray(p, float)), float(h), float(s),
                               int(t.seed)))
    return merge_trees(placed, where, name=name, seed=seed)
