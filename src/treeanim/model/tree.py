"""The tree as structure-of-arrays (docs/design.md §3).

A tree is a set of *objects* (curved beams: branches, leaf petioles, grass blades), each a
run of >= 2 contiguous *nodes* ordered root to tip. Objects are sorted by hierarchy level,
so each level is one contiguous slice of the object arrays (and of the node arrays).
"""

from __future__ import annotations

import numbers
from dataclasses import dataclass, field

import numpy as np

from ..validate import finite_float
from .geometry import polygon_area
from .look import Bark
from .params import PhysicsParams

KINDS = ("branch", "leaf", "blade")
#: Each kind's plural: the keys of :meth:`Tree.stats`' counts.
PLURAL = {"branch": "branches", "leaf": "leaves", "blade": "blades"}

#: Sides of a branch tube: 2 x 16 triangles per band of the tube plus a 16-triangle fan at
#: each end (the paper's 32 triangles per node when every segment is one band).
BRANCH_SIDES = 16

#: A branch's tube has at least this many bands along its length, so that a bent branch is
#: drawn as a curve however few segments it has (see :func:`curve_bands`) ...
CURVE_BANDS = 4
#: ... and enough bands a segment that its rings turn at most this many degrees from one to the
#: next where its chords turn at a joint at rest (the rest curve shares a joint's turn out
#: evenly, render/skinning.py) ...
CURVE_TURN = 4.0
#: ... but at most this many.
CURVE_MOST = 6
#: A fork's leader, which continues its parent's tube, turns at most this many degrees from it
#: (see :meth:`Tree.fork_leaders`; a fork may have several).
FORK_LEAD = 75.0


def curve_bands(object_count: np.ndarray, turn: np.ndarray | float = 0.0) -> np.ndarray:
    """Bands per segment of a branch tube with ``object_count`` nodes whose chords turn at most
    ``turn`` radians at a joint (:meth:`Tree.joint_turn`): max(⌈4 / segments⌉, ⌈turn / 4°⌉),
    the latter at most 6.

    A one-segment twig is drawn in four bands along the beam's deflection curve, a straight limb
    of four or more segments in one band per segment, a crooked one in more.
    """
    segments = np.maximum(np.asarray(object_count) - 1, 1)
    crooked = np.minimum(np.ceil(np.degrees(turn) / CURVE_TURN - 1e-6), CURVE_MOST).astype(np.int64)
    return np.maximum(-(-CURVE_BANDS // segments), crooked)


@dataclass(frozen=True)
class Lamina:
    """A species' leaf blade, triangulated once, in leaf-local units.

    Attributes
    ----------
    outline : (K, 2) float
        Closed outline, counter-clockwise; x across the blade (along the leaf's u axis),
        y along the midrib (the leaf's v axis, petiole tip at y = 0). The midrib length is 1;
        each leaf scales it by its own ``lamina_length``.
    triangles : (T, 3) int
        Indices into ``outline``.
    curl : float
        Cross-curl of the blade: a vertex at x is lifted along the normal by ``curl * x**2``.
    """

    shape: str
    outline: np.ndarray
    triangles: np.ndarray
    curl: float = 0.0

    @property
    def area(self) -> float:
        """Area of the unit lamina (midrib length 1), in units of length squared."""
        return polygon_area(self.outline)


@dataclass(eq=False)
class Tree:
    """A tree (or a grass patch, or a single beam) as numpy arrays.

    Attributes
    ----------
    name : str
        Preset name.
    rest_positions : (N, 3) float
        Node positions at rest, world metres, y up.
    node_diameter : (N,) float
        Diameter at each node (for blades: the blade's width).
    object_start, object_count : (M,) int
        Node range of each object: nodes ``object_start[i] : object_start[i] + object_count[i]``.
    parent : (M,) int
        Parent object, -1 for roots.
    attach_node : (M,) int
        Global index of the parent's node that this object's base sits on (-1 for roots).
    level : (M,) int
        Hierarchy level, 1 = trunk (and grass blades); a leaf is one level below its twig.
        Non-decreasing over objects.
    kind : (M,) str
        ``'branch'``, ``'leaf'`` or ``'blade'``.
    rest_w : (M, 3) float
        The object's w axis at rest: for leaves the lamina normal (Fig. 6); for branches and
        blades Eq. 1's w = P0Pn x v, or a fixed perpendicular for straight objects.
    lamina_length : (M,) float
        Midrib length of each leaf's lamina in metres (0 for other kinds).
    leaf_drop_rank : (M,) int
        Order in which leaves fall as the season turns to winter (0 falls first); -1 for
        other kinds.
    winter_leaves : int
        Leaves left at season 1.
    lamina : Lamina or None
        The species' lamina, shared by every leaf.
    petiole_sides : int
        Sides of a petiole tube (for triangle counts and meshes).
    physics : PhysicsParams
        Modal ranges (summer and winter) and material constants.
    seed : int
        Seed the tree was generated with.
    source : str
        File the tree was loaded from.
    bark : Bark
        The bark's look.
    modes : str
        Where a :class:`~treeanim.physics.simulation.Simulation` takes the modal parameters
        from unless told: ``'paper'`` (Eqs. 20–22) or ``'physical'`` (beam theory).
    """

    name: str
    rest_positions: np.ndarray
    node_diameter: np.ndarray
    object_start: np.ndarray
    object_count: np.ndarray
    parent: np.ndarray
    attach_node: np.ndarray
    level: np.ndarray
    kind: np.ndarray
    rest_w: np.ndarray
    lamina_length: np.ndarray
    leaf_drop_rank: np.ndarray
    winter_leaves: int = 0
    lamina: Lamina | None = None
    petiole_sides: int = 4
    physics: PhysicsParams = field(default_factory=PhysicsParams)
    seed: int = 0
    source: str = ""
    bark: Bark = field(default_factory=Bark)
    modes: str = "paper"

    # ------------------------------------------------------------------ sizes
    @property
    def n_nodes(self) -> int:
        """Number of nodes N."""
        return len(self.rest_positions)

    @property
    def n_objects(self) -> int:
        """Number of objects M."""
        return len(self.object_start)

    @property
    def node_object(self) -> np.ndarray:
        """(N,) int: the object each node belongs to."""
        return np.repeat(np.arange(self.n_objects), self.object_count)

    def _chords(self) -> np.ndarray:
        """(N - 1, 3): unit vectors from each node to the next."""
        chord = np.diff(self.rest_positions, axis=0)
        return chord / np.maximum(np.linalg.norm(chord, axis=1, keepdims=True), 1e-12)

    def fork_leaders(self) -> tuple[np.ndarray, np.ndarray]:
        """The forks' leaders: the branches on a branch's tip that turn at most ``FORK_LEAD``°
        from its last segment (the renderer draws each as the parent's tube running on, so an
        even fork's branches grow out of one crotch; a branch turning more keeps its collar).

        Returns
        -------
        leader : (L,) int
            The leaders (their parents: ``parent[leader]``; an even fork's parent has several).
        turn : (L,) float
            The angle between the parent's last chord and the leader's first, radians.
        """
        child = np.flatnonzero((np.asarray(self.kind) == "branch") & (self.parent >= 0))
        tip = self.object_start[self.parent[child]] + self.object_count[self.parent[child]] - 1
        on_tip = self.attach_node[child] == tip
        child, tip = child[on_tip], tip[on_tip]
        chord = self._chords()
        turn = np.arccos(np.clip(np.sum(chord[tip - 1] * chord[self.object_start[child]], axis=1), -1.0, 1.0))
        lead = turn <= np.radians(FORK_LEAD)
        return child[lead], turn[lead]

    def joint_turn(self) -> np.ndarray:
        """(M,) float: the largest angle between consecutive chords of each object at rest, and
        for a fork's leader (:meth:`fork_leaders`) between its parent's last chord and its first,
        radians."""
        chord = self._chords()
        k, n = self.node_index, self.object_count[self.node_object]
        inner = np.flatnonzero((k > 0) & (k < n - 1))
        turn = np.zeros(self.n_objects)
        cos = np.clip(np.sum(chord[inner - 1] * chord[inner], axis=1), -1.0, 1.0)
        np.maximum.at(turn, self.node_object[inner], np.arccos(cos))
        leader, fork = self.fork_leaders()
        np.maximum.at(turn, leader, fork)
        return turn

    @property
    def node_index(self) -> np.ndarray:
        """(N,) int: each node's index within its object (0 = base)."""
        return np.arange(self.n_nodes) - np.repeat(self.object_start, self.object_count)

    def object_nodes(self, i: int) -> np.ndarray:
        """Global node indices of object ``i``, root to tip.

        Parameters
        ----------
        i : int
            Object index in ``range(n_objects)``.

        Returns
        -------
        numpy.ndarray, (object_count[i],) int

        Raises
        ------
        ValueError
            If ``i`` is not an integer or is out of range.
        """
        if isinstance(i, bool) or not isinstance(i, numbers.Integral):
            raise ValueError(f"object index i must be an integer, got {i!r}")
        i = int(i)
        if not 0 <= i < self.n_objects:
            raise ValueError(f"object index i={i} is out of range: the tree has {self.n_objects} objects")
        s = int(self.object_start[i])
        return np.arange(s, s + int(self.object_count[i]))

    def level_slices(self) -> list[slice]:
        """Contiguous object slices, one per hierarchy level, root level first."""
        bounds = np.flatnonzero(np.diff(self.level)) + 1
        edges = [0, *bounds.tolist(), self.n_objects]
        return [slice(a, b) for a, b in zip(edges[:-1], edges[1:])]

    # ------------------------------------------------------------------ seasons
    def leaves_present(self, season: float) -> np.ndarray:
        """(M,) bool: objects shown at ``season`` (0 summer .. 1 winter).

        Leaves fall in the fixed seeded order ``leaf_drop_rank`` from the summer count down to
        ``winter_leaves``; branches and blades are always present.

        Parameters
        ----------
        season : float
            Finite; values outside [0, 1] are clipped to it.

        Returns
        -------
        numpy.ndarray, (M,) bool

        Raises
        ------
        ValueError
            If ``season`` is not a finite real number.
        """
        season = min(max(finite_float("season", season), 0.0), 1.0)
        n_leaves = int(np.count_nonzero(self.kind == "leaf"))
        keep = int(round(n_leaves + (self.winter_leaves - n_leaves) * season))
        fallen = n_leaves - keep
        return (self.kind != "leaf") | (self.leaf_drop_rank >= fallen)

    # ------------------------------------------------------------------ statistics
    def triangles_per_object(self) -> np.ndarray:
        """(M,) int: triangles the renderer draws for each object.

        Branch: a 16-sided tube in :func:`curve_bands` bands per segment, closed by a fan at
        each end (32 per node for branches of four or more segments, as the paper's tubes), but
        none where a fork's leader runs on from its parent (:meth:`fork_leaders`).
        Leaf: a petiole tube (``petiole_sides``) plus the lamina triangulation.
        Blade: a two-sided strip over its segments plus a tip triangle.
        """
        n = self.object_count
        lamina_tris = 0 if self.lamina is None else len(self.lamina.triangles)
        fans = np.full(self.n_objects, 2)
        leader = self.fork_leaders()[0]
        fans[leader] -= 1
        fans[self.parent[leader]] -= 1
        return np.select(
            [self.kind == "branch", self.kind == "leaf"],
            [BRANCH_SIDES * (2 * (n - 1) * curve_bands(n, self.joint_turn()) + fans),
             2 * self.petiole_sides * (n - 1) + lamina_tris],
            2 * (n - 1) + 1,
        )

    def stats(self, season: float = 0.0) -> dict:
        """Counts in the paper's Table 1 terms, for the leaves present at ``season``.

        Returns
        -------
        dict
            ``branches, branch_nodes, branch_triangles, leaves, leaf_nodes, leaf_triangles,
            blades, blade_nodes, blade_triangles, objects, nodes, triangles``.
        """
        present = self.leaves_present(season)
        tris = self.triangles_per_object()
        out: dict = {}
        for k in KINDS:
            m = present & (self.kind == k)
            out[PLURAL[k]] = int(m.sum())
            out[f"{k}_nodes"] = int(self.object_count[m].sum())
            out[f"{k}_triangles"] = int(tris[m].sum())
        out["objects"] = int(present.sum())
        out["nodes"] = int(self.object_count[present].sum())
        out["triangles"] = int(tris[present].sum())
        return out

    # ------------------------------------------------------------------ checks
    def validate(self) -> None:
        """Raise ``ValueError`` if a structural invariant does not hold.

        Every object has >= 2 nodes; node ranges are contiguous; levels are sorted; every
        base sits on its parent's attach node, which belongs to the parent; parents come
        before children; no segment has zero length; all arrays are finite.
        """
        M, N = self.n_objects, self.n_nodes
        if np.any(self.object_count < 2):
            raise ValueError("an object has fewer than 2 nodes")
        if not np.array_equal(self.object_start, np.concatenate([[0], np.cumsum(self.object_count)[:-1]])):
            raise ValueError("object node ranges are not contiguous")
        if int(self.object_count.sum()) != N:
            raise ValueError("node count does not match object ranges")
        if np.any(np.diff(self.level) < 0):
            raise ValueError("objects are not sorted by level")
        if not (np.all(np.isfinite(self.rest_positions)) and np.all(np.isfinite(self.node_diameter))):
            raise ValueError("non-finite node data")
        has_parent = self.parent >= 0
        if np.any(self.parent[has_parent] >= np.arange(M)[has_parent]):
            raise ValueError("a parent does not come before its child")
        attach = self.attach_node[has_parent]
        par = self.parent[has_parent]
        if np.any(self.node_object[attach] != par):
            raise ValueError("an attach node does not belong to the parent object")
        base = self.rest_positions[self.object_start[has_parent]]
        if not np.allclose(base, self.rest_positions[attach], atol=1e-9):
            raise ValueError("an object's base does not sit on its parent's attach node")
        seg = np.linalg.norm(np.diff(self.rest_positions, axis=0), axis=1)
        within = np.ones(N - 1, bool)
        within[(self.object_start[1:] - 1)] = False  # differences across object boundaries
        if np.any(seg[within] <= 1e-9):
            raise ValueError("a segment has zero length")
