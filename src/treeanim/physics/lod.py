"""Levels of detail of the tree model (docs/design.md §17): a far tree is simulated with fewer
degrees of freedom, the rest of it riding rigidly on what still moves.

Each tree of a scene has a detail level (:data:`MAX_DETAIL` the coarsest):

* 0 — everything: every segment's joint and every leaf's petiole;
* 1 — the leaves and the twigs (branches that bear no branch) ride rigidly on their parents, a
  grass blade on its base joint;
* 2 — only the trunk and the limbs (the first two orders of branches) sway, the rest of the
  crown riding on them; a grass blade on its base joint, as at 1 (a blade has nothing to
  ride on, and grass bends far more for its height than a tree);
* 3 — the tree stands still.

:class:`Reduced` is the step's view of a scene with levels: the active bodies and leaves as a
:class:`~.structure.Structure` of their own (their parents renumbered), so every compiled pass
runs over them only. What rides rigidly on an active body joins its inertia (where it is when
frozen, so the reduced model's energy is the whole tree's) and its drag (one isotropic drag per
body, :func:`~.treestep._lump_force`); it keeps its shape relative to that body — its joints'
rotations as they were, no relative velocity — and is carried along by :func:`carry`. So a
switch never moves a node: going coarser drops only the relative velocities, going finer
starts the freed joints from their rigid ride.

:func:`choose_detail` picks the levels from the camera (each tree's height on the screen).
"""

from __future__ import annotations

import numbers
from dataclasses import fields

import numpy as np

from ..model.scene import object_trees
from .compiled import njit
from .kinematics import _place
from .structure import Structure
from .treestep import TreeState, Work

__all__ = ["MAX_DETAIL", "DETAIL_PIXELS", "Parts", "Reduced", "carry", "check_levels", "choose_detail",
           "tree_extents"]

#: The coarsest detail level.
MAX_DETAIL = 3
#: A tree's height on the screen (px) below which it takes detail level 1, 2 and 3.
DETAIL_PIXELS = (240.0, 80.0, 8.0)
#: A tree goes coarser only when it is this much under a level's height (no flicker at the edge).
HYSTERESIS = 0.15
#: The mean drag along the flow of a segment at a random angle to it, per ½ρC_d·d·ℓ:
#: ⟨sin³⟩ over the sphere, 3π/16.
SEGMENT_DRAG = 3.0 * np.pi / 16.0
#: The same of a lamina's normal force, ⟨cos²⟩ over the sphere.
LEAF_DRAG = 1.0 / 3.0
_BODY_STATE = ("Q", "w", "R", "P", "Om", "V", "leaf_F", "leaf_C", "leaf_K", "kick")  # TreeState's per-body arrays (the
# others are per leaf)


def check_levels(levels, n_trees: int) -> np.ndarray:
    """``levels`` (one integer per tree, or one for all) as an (n_trees,) int array, or one
    ValueError line."""
    if isinstance(levels, numbers.Integral) and not isinstance(levels, bool):
        levels = [levels] * n_trees
    try:
        a = np.asarray(levels)
    except (TypeError, ValueError):
        a = np.asarray([None])
    if a.dtype == bool or not np.issubdtype(a.dtype, np.integer) or a.shape != (n_trees,):
        raise ValueError(f"levels must be one integer per tree ({n_trees}), got {_brief(levels)}")
    if len(a) and (a.min() < 0 or a.max() > MAX_DETAIL):
        raise ValueError(f"levels must be in 0..{MAX_DETAIL}, got {int(a.min())}..{int(a.max())}")
    return a.astype(np.int64)


def _brief(x) -> str:
    s = repr(x)
    return s if len(s) <= 60 else s[:57] + "..."


class Parts:
    """Which bodies and leaves of a structure move at each detail level, worked out once (a
    level change then costs a gather and a few compiled passes over the bodies and leaves).

    Attributes
    ----------
    body_tree, leaf_tree : (B,) and (L,) int
        The tree of each body and leaf.
    body_levels : (B,) uint8
        Bit ``l`` set where the body moves at level ``l`` (a leaf moves at level 0 only).
    """

    def __init__(self, tree, s: Structure):
        trees = object_trees(tree)
        self.body_tree, self.leaf_tree = trees[s.obj], trees[s.leaf_obj]
        kind = np.asarray(tree.kind)
        par = np.asarray(tree.parent)
        bears = np.zeros(tree.n_objects, bool)  # bears a branch
        grows = (par >= 0) & (kind != "leaf")
        bears[par[grows]] = True
        blade = kind == "blade"
        limb = (kind == "branch") & (np.asarray(tree.level) <= 2)
        o = s.obj
        first = s.body_of_obj[o] == np.arange(len(o))  # (a blade's base joint)
        coarse = (bears | blade)[o] & (~blade[o] | first), (limb | blade)[o] & (~blade[o] | first)
        self.body_levels = (1 + 2 * coarse[0] + 4 * coarse[1]).astype(np.uint8)

    def active(self, levels: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(B,) bool bodies and (L,) bool leaves that move at the trees' detail ``levels``: a
        body's parent is always among them when it is."""
        return (self.body_levels >> levels[self.body_tree].astype(np.uint8)) & 1 == 1, levels[self.leaf_tree] == 0


@njit(cache=True, error_model="numpy")
def _anchors(parent, active):
    """(B,) each body's nearest active body on the way to the root, itself if active (−1:
    none, it stands on the ground); parents come first."""
    anc = np.empty(len(parent), np.int64)
    for b in range(len(parent)):
        p = parent[b]
        anc[b] = b if active[b] else (anc[p] if p >= 0 else -1)
    return anc


@njit(cache=True, fastmath=True, error_model="numpy")
def carry(bodies, parent, r0, Q, w, R, P, Om, V):
    """Place ``bodies`` (ascending: parents first) on their parents by their joints, as
    :func:`~.kinematics.forward_kinematics` does."""
    for b in bodies:
        _place(b, parent, r0, Q, w, R, P, Om, V)


@njit(cache=True, fastmath=True, error_model="numpy")
def _freeze(bodies, leaves, parent, r0, st_Q, st_w, st_R, st_P, st_Om, st_V, kick, leaf_F, leaf_C, leaf_K, thd):
    """Freeze the ``bodies`` (bool: no relative velocity nor change of it, placed on their
    parents; their leaves pass them no force) and the ``leaves`` (bool: at rest)."""
    for b in range(len(bodies)):
        if bodies[b]:
            st_w[b, :] = 0.0
            kick[b] = 0.0
            leaf_F[b, :] = 0.0
            leaf_C[b, :, :] = 0.0
            leaf_K[b, :, :] = 0.0
            _place(b, parent, r0, st_Q, st_w, st_R, st_P, st_Om, st_V)
    for q in range(len(leaves)):
        if leaves[q]:
            thd[q, :] = 0.0


@njit(cache=True, error_model="numpy")
def _start(bodies, rows, s_m0, s_h0, s_J0, p_m0, p_h0, p_J0, p_lump, m0, h0, J0, lump):
    """Each active body's inertia and the drag of what rides on it, to start from: as it was
    (``rows``: its row in the previous reduced structure, −1: none) or its own alone."""
    for r in range(len(bodies)):
        b, p = bodies[r], rows[r]
        if p >= 0:
            m0[r], h0[r], J0[r], lump[r] = p_m0[p], p_h0[p], p_J0[p], p_lump[p]
        else:
            m0[r], h0[r], J0[r], lump[r] = s_m0[b], s_h0[b], s_J0[b], 0.0


@njit(cache=True, error_model="numpy")
def _lump(todo, anc, index, parent, r0, Q, s_m0, s_h0, s_J0, mid0, cda, leaf_body, leaf_on, leaf_base0, leaf_rc0,
          leaf_cna, leaf_cauchy, C, d, m0, h0, J0, lump):
    """Lump what rides on each active body (``index``: its row in ``m0`` … ``lump``) into it,
    over the bodies ``todo`` and their leaves: a carried body's inertia into ``m0``, ``h0``,
    ``J0`` where its joints hold it (``C``, ``d``: each body's rotation and joint in its
    anchor's rest axes, by its joints from the anchor's — fixed while it rides, as its joints
    are), its drag and the riding leaves' (``leaf_on``: those that ride, present) into
    ``lump``: cd, cl, cl·cauchy, (cd + cl)·x."""
    CJ, hf = np.empty((3, 3)), np.empty(3)
    for f in range(len(parent)):
        a = anc[f]
        if not todo[f] or a < 0:  # (what stands on the ground holds nothing up)
            continue
        if a == f:
            C[f] = np.eye(3)
            d[f] = 0.0
            continue
        p, r = parent[f], index[a]
        for i in range(3):
            d[f, i] = d[p, i] + (C[p, i, 0] * r0[f, 0] + C[p, i, 1] * r0[f, 1] + C[p, i, 2] * r0[f, 2])
            for j in range(3):
                C[f, i, j] = C[p, i, 0] * Q[f, 0, j] + C[p, i, 1] * Q[f, 1, j] + C[p, i, 2] * Q[f, 2, j]
        for i in range(3):
            hf[i] = C[f, i, 0] * s_h0[f, 0] + C[f, i, 1] * s_h0[f, 1] + C[f, i, 2] * s_h0[f, 2]
            for j in range(3):
                CJ[i, j] = C[f, i, 0] * s_J0[f, 0, j] + C[f, i, 1] * s_J0[f, 1, j] + C[f, i, 2] * s_J0[f, 2, j]
        m, x = s_m0[f], d[f]
        cd = SEGMENT_DRAG * cda[f]
        shift = 2.0 * (x[0] * hf[0] + x[1] * hf[1] + x[2] * hf[2]) + m * (x[0] * x[0] + x[1] * x[1] + x[2] * x[2])
        m0[r] += m
        lump[r, 0] += cd
        for i in range(3):
            h0[r, i] += hf[i] + m * x[i]
            lump[r, 3 + i] += cd * (x[i] + (C[f, i, 0] * mid0[f, 0] + C[f, i, 1] * mid0[f, 1] + C[f, i, 2] * mid0[f, 2]))
            for n in range(3):  # C J Cᵀ about the anchor's joint
                Jf = CJ[i, 0] * C[f, n, 0] + CJ[i, 1] * C[f, n, 1] + CJ[i, 2] * C[f, n, 2]
                if i == n:
                    Jf += shift
                J0[r, i, n] += Jf - (x[i] * hf[n] + hf[i] * x[n] + m * x[i] * x[n])
    for q in range(len(leaf_body)):  # the leaves at their laminas
        t = leaf_body[q]
        a = anc[t]
        if not todo[t] or not leaf_on[q] or a < 0:
            continue
        r = index[a]
        cl = LEAF_DRAG * leaf_cna[q]
        lump[r, 1] += cl
        lump[r, 2] += cl * leaf_cauchy[q]
        for i in range(3):
            lump[r, 3 + i] += cl * (d[t, i] + (C[t, i, 0] * (leaf_base0[q, 0] + leaf_rc0[q, 0])
                                               + C[t, i, 1] * (leaf_base0[q, 1] + leaf_rc0[q, 1])
                                               + C[t, i, 2] * (leaf_base0[q, 2] + leaf_rc0[q, 2])))


class Reduced:
    """The active part of a tree (or scene) at its detail levels, and the state it steps.

    Building it freezes the rest in ``st`` (no relative velocity; the frozen leaves pass no
    force) and lumps what rides into the active bodies, in a few compiled passes over the
    bodies and leaves. It steps in the first rows of the whole structure's ``work``.
    :meth:`gather` copies the active part of a full state into :attr:`state`; :meth:`scatter`
    writes it back and carries the frozen part along.

    Parameters
    ----------
    parts : Parts
        Of ``s``.
    s : Structure
        The whole structure.
    st : TreeState
        The whole state (frozen where it does not move).
    levels : (T,) int
        The trees' detail levels.
    work : Work
        The whole structure's scratch.
    was : (T,) int or None
        The levels ``st`` was last stepped at (None: unknown). Only the trees whose level
        changed are frozen and lumped anew: the others' frozen parts are as a freeze leaves them
        (:meth:`scatter` carries them) and what rides on them is lumped as in ``prev``.
    prev : Reduced or None
        The one ``st`` was stepped with at ``was`` (None: every tree at level 0).

    Attributes
    ----------
    s : Structure
        The active bodies (parents renumbered) and leaves, with what rides on each.
    bodies, leaves : (B', ) and (L', ) int
        Their indices in the full structure; ``frozen`` the other bodies.
    body_index : (B,) int
        A body's index in :attr:`s` (−1: frozen).
    carried : (F,) int
        The frozen bodies that ride on an active one (the others stand still).
    lump : (B', 6) float
        The drag of what rides on each active body: cd, cl, cl·cauchy, (cd + cl)·x.
    moving : ((B″,) int, (L″,) int)
        The bodies and leaves that move: their nodes are all a pose after the first rewrites.
    last : (pos, rot) or None
        The last whole pose, kept by the simulation.
    """

    def __init__(self, parts: Parts, s: Structure, st: TreeState, levels: np.ndarray, work: Work,
                 was: np.ndarray | None = None, prev: Reduced | None = None):
        on, leaf_on = parts.active(levels)
        self.bodies, self.leaves = np.flatnonzero(on), np.flatnonzero(leaf_on)
        self.frozen = np.flatnonzero(~on)
        self.body_index = np.full(len(on), -1, np.int64)
        self.body_index[self.bodies] = np.arange(len(self.bodies))
        changed = np.ones(len(levels), bool) if was is None else levels != was
        todo = changed[parts.body_tree]
        _freeze(~on & todo, ~leaf_on & changed[parts.leaf_tree], s.parent, s.r0, st.Q, st.w, st.R, st.P, st.Om,
                st.V, st.kick, st.leaf_F, st.leaf_C, st.leaf_K, st.thd)
        anc = _anchors(s.parent, on)
        self.carried = self.frozen[anc[self.frozen] >= 0]  # (the rest stands still from now on)
        moving = anc >= 0
        self.moving = np.flatnonzero(moving), np.flatnonzero(moving[s.leaf_body])
        self.last = None  # the last whole pose (set by its simulation)
        n = len(self.bodies)
        m0, h0, J0, self.lump = np.empty(n), np.empty((n, 3)), np.empty((n, 3, 3)), np.empty((n, 6))
        new = m0, h0, J0, self.lump
        if was is None or prev is None:
            rows, old = np.full(n, -1), new
        else:  # what rides on the trees that kept their level, as it was
            rows, old = np.where(todo[self.bodies], -1, prev.body_index[self.bodies]), (prev.s.m0, prev.s.h0, prev.s.J0, prev.lump)
        _start(self.bodies, rows, s.m0, s.h0, s.J0, *old, *new)
        _lump(todo, anc, self.body_index, s.parent, s.r0, st.Q, s.m0, s.h0, s.J0, s.mid0, s.cda, s.leaf_body,
              s.leaf_on & ~leaf_on, s.leaf_base0, s.leaf_rc0, s.leaf_cna, s.leaf_cauchy, np.empty_like(st.Q),
              np.empty_like(st.P), *new)
        self.s = self._structure(s, m0, h0, J0)
        self.work = work.head(n)
        self.state = TreeState(time=st.time, **{f.name: np.empty((len(self._rows(f.name)),) + getattr(st, f.name).shape[1:])
                                                  for f in fields(TreeState) if f.name != "time"})

    def _rows(self, name: str) -> np.ndarray:
        return self.bodies if name in _BODY_STATE else self.leaves

    def _structure(self, s: Structure, m0: np.ndarray, h0: np.ndarray, J0: np.ndarray) -> Structure:
        """The active part of ``s``, with the inertia ``m0``, ``h0``, ``J0`` and the drag
        :attr:`lump` of what rides on each body."""
        bodies, lump = self.bodies, self.lump
        renumber = np.append(self.body_index, -1)  # (−1 stays −1)
        out = dict(m0=m0, h0=h0, J0=J0, parent=renumber[s.parent[bodies]], body_of_obj=renumber[s.body_of_obj],
                   leaf_body=self.body_index[s.leaf_body[self.leaves]],
                   leaf_nodes=s.leaf_nodes[:0], leaf_first=np.zeros(len(self.leaves) + 1, np.int64),
                   lump_cd=lump[:, 0].copy(), lump_cl=lump[:, 1].copy(),
                   lump_cauchy=lump[:, 2] / np.maximum(lump[:, 1], 1e-300),
                   lump_x0=lump[:, 3:] / np.maximum(lump[:, 0] + lump[:, 1], 1e-300)[:, None])
        for fl in fields(Structure):
            if fl.name not in out:
                out[fl.name] = np.take(getattr(s, fl.name), self.leaves if fl.name.startswith("leaf_") else bodies,
                                       axis=0)
        return Structure(**out)

    @property
    def dof(self) -> int:
        """The degrees of freedom stepped: three a joint and a petiole."""
        return 3 * (len(self.bodies) + len(self.leaves))

    def gather(self, st: TreeState) -> TreeState:
        """:attr:`state` as the active part of ``st``."""
        sub = self.state
        for f in fields(TreeState):
            if f.name != "time":
                np.take(getattr(st, f.name), self._rows(f.name), axis=0, out=getattr(sub, f.name))
        sub.time = st.time
        return sub

    def scatter(self, st: TreeState, full: Structure) -> None:
        """Write :attr:`state` into ``st`` and carry the frozen bodies along (``full``: the
        whole structure)."""
        sub = self.state
        for f in fields(TreeState):
            if f.name != "time":
                getattr(st, f.name)[self._rows(f.name)] = getattr(sub, f.name)
        st.time = sub.time
        carry(self.carried, full.parent, full.r0, st.Q, st.w, st.R, st.P, st.Om, st.V)


def tree_extents(tree) -> tuple[np.ndarray, np.ndarray]:
    """Each tree's root (T, 3) — the lowest of its nodes — and height (T,) above it (m)."""
    X = np.asarray(tree.rest_positions, float)
    owner = object_trees(tree)[tree.node_object]
    T = int(owner.max()) + 1 if len(owner) else 0
    low = np.full(T, np.inf)
    np.minimum.at(low, owner, X[:, 1])
    top = np.full(T, -np.inf)
    np.maximum.at(top, owner, X[:, 1])
    lowest = np.flatnonzero(X[:, 1] == low[owner])
    roots = np.empty((T, 3))
    roots[owner[lowest]] = X[lowest]
    return roots, top - low


def choose_detail(eye, roots: np.ndarray, heights: np.ndarray, focal_px: float, hero=(),
                  current: np.ndarray | None = None) -> np.ndarray:
    """Detail levels from the camera: a tree's height on the screen (px) against
    :data:`DETAIL_PIXELS`.

    Parameters
    ----------
    eye : (3,) float
        The camera's position.
    roots, heights : (T, 3), (T,) float
        Each tree's root and height (:func:`tree_extents`).
    focal_px : float
        Pixels a unit at unit distance spans on the screen: the viewport's height over
        2·tan(fov_y/2).
    hero : iterable of int
        Trees kept at full detail (the one grabbed or selected).
    current : (T,) int or None
        The levels now: a tree goes coarser only when :data:`HYSTERESIS` under a level's height.

    Returns
    -------
    (T,) int
        0 (full) … :data:`MAX_DETAIL`.
    """
    roots = np.asarray(roots, float)
    heights = np.asarray(heights, float)
    centre = roots + np.outer(0.5 * heights, [0.0, 1.0, 0.0])
    dist = np.maximum(np.linalg.norm(centre - np.asarray(eye, float), axis=1), 1e-6)
    px = heights * float(focal_px) / dist
    edges = np.asarray(DETAIL_PIXELS)
    levels = np.sum(px[:, None] < edges, axis=1)
    if current is not None:  # finer at once, coarser past the band
        levels = np.clip(np.asarray(current), np.sum(px[:, None] * (1.0 + HYSTERESIS) < edges, axis=1), levels)
    levels[np.asarray(list(hero), np.int64)] = 0
    return levels.astype(np.int64)
