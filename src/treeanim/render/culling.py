"""Drawing a scene of many trees tree by tree: each tree's triangles one contiguous range per
pass, a bounding sphere a tree, and the ranges of the trees a view (the camera's or the sun's)
can see merged into as few draws as runs of consecutive visible trees allow
(docs/design.md §17, Drawing).

Trees are put in draw order along a Morton (Z-order) curve over the ground, so trees near
each other are near in order, and the trees a frustum holds form few runs.
"""

from __future__ import annotations

import numpy as np

from ..model.scene import object_trees
from ..model.tree import Tree

#: A tree's sphere grows by this fraction of its height for sway, and the shadow map's box round
#: a lone tree by this fraction of its size (:meth:`~.shadow.ShadowMap.fit`).
SWAY_MARGIN = 0.15
#: The grass is drawn in squares of the ground this many metres a side (:func:`blade_cells`).
BLADE_CELL = 2.0


def morton_order(xz: np.ndarray) -> np.ndarray:
    """Indices sorting points ``xz`` (K, 2) along a Z-order curve over their box (16 bits an axis)."""
    xz = np.asarray(xz, float)
    if len(xz) < 2:
        return np.arange(len(xz))
    lo, span = xz.min(axis=0), np.ptp(xz, axis=0)
    q = ((xz - lo) / np.where(span > 0, span, 1.0) * 65535).astype(np.uint64)
    code = np.zeros(len(xz), np.uint64)
    for bit in range(16):
        for axis in (0, 1):
            code |= ((q[:, axis] >> np.uint64(bit)) & np.uint64(1)) << np.uint64(2 * bit + axis)
    return np.argsort(code, kind="stable")


def tree_spheres(tree: Tree, pad: float, groups: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Each placed tree's bounding sphere at rest, grown for its surface and its sway.

    Parameters
    ----------
    tree : Tree
        A scene (or one tree: one sphere).
    pad : float
        How far the surface reaches beyond the nodes (metres).
    groups : (M,) int or None
        The group of each object, when not its tree (:func:`~treeanim.model.scene.object_trees`):
        a sphere a group, round its objects' nodes; objects in group -1 belong to none.

    Returns
    -------
    centres : (K, 3) float
    radii : (K,) float
        The sphere round group k's nodes at rest (about its box's centre), grown by ``pad`` and
        by :data:`SWAY_MARGIN` of the group's height.
    """
    owner = np.repeat(object_trees(tree) if groups is None else groups, tree.object_count)
    P = np.asarray(tree.rest_positions, float)[owner >= 0]
    owner = owner[owner >= 0]
    K = int(owner.max(initial=-1)) + 1
    lo = np.full((K, 3), np.inf)
    hi = np.full((K, 3), -np.inf)
    np.minimum.at(lo, owner, P)
    np.maximum.at(hi, owner, P)
    centres = 0.5 * (lo + hi)
    radii = np.zeros(K)
    np.maximum.at(radii, owner, np.linalg.norm(P - centres[owner], axis=1))
    return centres, radii + pad + SWAY_MARGIN * (hi[:, 1] - lo[:, 1])


def blade_cells(tree: Tree, side: float = BLADE_CELL) -> np.ndarray:
    """(M,) int: the square of the ground, ``side`` metres a side, each grass blade roots in,
    numbered 0, 1, ... over the squares with blades; -1 for every other object."""
    blade = np.asarray(tree.kind) == "blade"
    cells = np.full(tree.n_objects, -1, np.int64)
    if blade.any():
        root = np.floor(np.asarray(tree.rest_positions)[tree.object_start[blade]][:, [0, 2]] / side)
        cells[blade] = np.unique(root, axis=0, return_inverse=True)[1].reshape(-1)
    return cells


def frustum_planes(view_proj: np.ndarray) -> np.ndarray:
    """(6, 4) planes (n, d), n unit, of the volume a view-projection keeps: a point p is inside
    where n·p + d ≥ 0 for all six.

    Parameters
    ----------
    view_proj : (4, 4) float
        World → clip, row-vector layout (``p @ view_proj``, GLSL's bytes).
    """
    m = np.asarray(view_proj, float).T  # column-vector: clip = m @ p
    planes = np.array([m[3] + m[0], m[3] - m[0], m[3] + m[1], m[3] - m[1], m[3] + m[2], m[3] - m[2]])
    return planes / np.linalg.norm(planes[:, :3], axis=1, keepdims=True)


def spheres_visible(planes: np.ndarray, centres: np.ndarray, radii: np.ndarray) -> np.ndarray:
    """(K,) bool: the spheres that reach inside all of ``planes`` (:func:`frustum_planes`)."""
    return np.all(centres @ planes[:, :3].T + planes[:, 3] >= -radii[:, None], axis=1)


class TreeRanges:
    """Where each tree's triangles lie in an index buffer that holds them tree after tree.

    Parameters
    ----------
    counts : (K,) int
        Each tree's index count, in draw order.
    first : int
        Where the first tree's begin (indices into the buffer).
    """

    def __init__(self, counts: np.ndarray, first: int = 0) -> None:
        self.count = np.asarray(counts, np.int64)
        self.first = first + np.concatenate([[0], np.cumsum(self.count)[:-1]]).astype(np.int64)

    @property
    def total(self) -> int:
        """Indices of all trees."""
        return int(self.count.sum())

    def runs(self, keep: np.ndarray) -> list[tuple[int, int]]:
        """(first, count) of each run of consecutive trees in ``keep`` (K,) bool, runs with no
        triangles left out: one draw a run."""
        idx = np.flatnonzero(keep)
        if not len(idx):
            return []
        cut = np.flatnonzero(np.diff(idx) != 1) + 1
        a, b = idx[np.r_[0, cut]], idx[np.r_[cut - 1, len(idx) - 1]]
        first, end = self.first[a], self.first[b] + self.count[b]
        return [(int(f), int(e - f)) for f, e in zip(first, end) if e > f]


def by_tree(triangles: np.ndarray, owner: np.ndarray, rank: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Triangles regrouped tree by tree in draw order.

    Parameters
    ----------
    triangles : (T, 3) int
    owner : (T,) int
        Each triangle's tree.
    rank : (K,) int
        Each tree's place in draw order.

    Returns
    -------
    triangles : (T, 3) int
        Stably sorted by their tree's rank (each tree's in their order before).
    counts : (K,) int
        Index count (3 a triangle) of each tree, in draw order.
    """
    r = rank[owner]
    order = np.argsort(r, kind="stable")
    return triangles[order], 3 * np.bincount(r, minlength=len(rank))


class TreeOrder:
    """A mesh's trees in draw order (:func:`morton_order` of their spheres' centres), their
    spheres, and the regrouping of any of the mesh's triangles tree by tree.

    Parameters
    ----------
    tree : Tree
    mesh : TreeMesh
        The tree's mesh.
    pad : float
        How far the surface reaches beyond the nodes (:func:`tree_spheres`).
    groups : (M,) int or None
        Groups of objects to order in place of the trees (:func:`tree_spheres`; the grass's
        :func:`blade_cells`): then only their objects' triangles can be regrouped.

    Attributes
    ----------
    centres : (K, 3) float
    radii : (K,) float
        The trees' (groups') spheres, in draw order.
    """

    def __init__(self, tree: Tree, mesh, pad: float, groups: np.ndarray | None = None) -> None:
        centres, radii = tree_spheres(tree, pad, groups)
        order = morton_order(centres[:, [0, 2]])
        self.centres, self.radii = centres[order], radii[order]
        self.rank = np.empty(len(order), np.int64)
        self.rank[order] = np.arange(len(order))
        self._vertex_tree = (object_trees(tree) if groups is None else groups)[mesh.object]

    @property
    def n_trees(self) -> int:
        """Number of trees."""
        return len(self.radii)

    def group(self, triangles: np.ndarray, first: int = 0) -> tuple[np.ndarray, TreeRanges]:
        """``triangles`` (T, 3) of the mesh tree by tree in draw order, and their ranges in a
        buffer where they begin at index ``first``."""
        t, counts = by_tree(triangles, self._vertex_tree[triangles[:, 0]], self.rank)
        return t, TreeRanges(counts, first)

    def visible(self, view_proj: np.ndarray) -> np.ndarray:
        """(K,) bool, draw order: the trees whose sphere reaches into ``view_proj``'s volume."""
        return spheres_visible(frustum_planes(view_proj), self.centres, self.radii)
