"""Welded junctions (docs/design.md §10): where a child branch's tube meets its parent's, its
base ring is a collar on the parent's surface (or, for a branch turning sharply from a
parent's tip, on the parent's end ring) and its base cap a cone sunk inside the parent; but a
fork's leaders, the branches on a parent's tip that turn less, continue the parent's tube, so
an even fork's branches part in one crotch. Used by :mod:`treeanim.render.mesh`."""

from __future__ import annotations

import numpy as np

from ..model.geometry import perpendicular as _perpendicular
from ..model.geometry import unit as _unit
from ..model.tree import Tree
from .skinning import hermite

#: A child branch's collar rim is this many times its base radius, at least and at most...
COLLAR_FLARE = (1.15, 1.5)
#: ... and, along a parent, at most this fraction of the parent's radius (it fits inside).
COLLAR_FIT = 0.95
#: Where a child sits on its parent's tip, its collar's apex lies this many parent radii below
#: the parent's end (at most half the parent's last segment).
COLLAR_SINK = 2.0
#: A child on its parent's tip forks from the parent's end ring, tilted towards the child by as
#: much as the child turns from the parent's direction beyond this angle (degrees).
COLLAR_FORK = 70.0


def leaders(tree: Tree, nodes: np.ndarray, tangent: np.ndarray) -> np.ndarray:
    """The forks' leaders (:meth:`Tree.fork_leaders`) and their tangents. Each leader starts
    with its parent's tangent at the fork, set in ``tangent`` (unit, one row per node of
    ``nodes``, which holds every branch's): the rest curve runs on through the fork, the leader
    turning in its first segment (its bands: :meth:`Tree.joint_turn`), the parent as drawn
    without it; the leader's base ring, the parent's end ring, needs no collar.

    Returns
    -------
    (M,) bool
    """
    child = tree.fork_leaders()[0]
    row = np.zeros(tree.n_nodes, np.int64)
    row[nodes] = np.arange(len(nodes))
    tangent[row[tree.object_start[child]]] = tangent[row[tree.attach_node[child]]]
    lead = np.zeros(tree.n_objects, bool)
    lead[child] = True
    return lead


def tube_radius(tree: Tree) -> np.ndarray:
    """(N,) float: the tubes' radius at each node as drawn, metres: a fork's leader
    (:func:`leaders`) starts at its parent's end radius."""
    r = 0.5 * np.asarray(tree.node_diameter, float)
    lead = tree.fork_leaders()[0]
    r[tree.object_start[lead]] = r[tree.attach_node[lead]]
    return r


def outward(q: np.ndarray, axis: np.ndarray) -> np.ndarray:
    """Unit directions of points ``q`` (C, K, 3) away from the lines through 0 along ``axis`` (C, 3)."""
    m = axis[:, None, :]
    return _unit(q - np.sum(q * m, axis=2, keepdims=True) * m, np.broadcast_to(m, q.shape))


def _leave(d: np.ndarray, u: np.ndarray, axis: np.ndarray, R: np.ndarray) -> np.ndarray:
    """(C, K): the largest s at which s·d + u meets the cylinder of radius R (C, K) about
    ``axis`` (C, 1 or K, 3) through 0 (d (C, 3), u (C, K, 3))."""
    dm = d[:, None, :]
    d_off = dm - np.sum(dm * axis, axis=2, keepdims=True) * axis
    u_off = u - np.sum(u * axis, axis=2, keepdims=True) * axis
    qa = np.sum(d_off * d_off, axis=2)
    qb = np.sum(d_off * u_off, axis=2)
    qc = np.sum(u_off * u_off, axis=2) - R * R
    return (np.sqrt(np.maximum(qb * qb - qa * qc, 0.0)) - qb) / np.maximum(qa, 1e-12)


def _drawn(tree: Tree, tangent: np.ndarray, att: np.ndarray, k: np.ndarray, q: np.ndarray):
    """The parents' drawn tubes level with points ``q`` (C, K, 3, from the attach nodes
    ``att``, the ``k``-th nodes of their parents): the centre line's point there (from ``att``),
    its unit tangent and the radius, on the Hermite curve of the segment after ``att`` (or
    before it, for points behind ``att`` not at a parent's base); ``tangent`` (N, 3): the
    nodes' drawn unit tangents."""
    P, r = tree.rest_positions, 0.5 * tree.node_diameter
    C, K = q.shape[:2]
    along = np.sum(q * tangent[att][:, None], axis=2)
    ahead = (along >= 0) | (k == 0)[:, None]
    n0 = np.where(ahead, att[:, None], att[:, None] - 1).ravel()
    n1 = np.minimum(n0 + 1, len(P) - 1)
    length = np.linalg.norm(P[n1] - P[n0], axis=1)
    t = np.clip((along.ravel() + np.where(ahead.ravel(), 0.0, length)) / np.maximum(length, 1e-12), 0.0, 1.0)
    centre, dq = hermite(t, P[n1] - P[n0], length[:, None] * tangent[n0], length[:, None] * tangent[n1])
    centre = centre + P[n0] - np.repeat(P[att], K, axis=0)
    radius = (1.0 - t) * r[n0] + t * r[n1]
    return centre.reshape(C, K, 3), _unit(dq, tangent[n0]).reshape(C, K, 3), radius.reshape(C, K)


def collars(tree: Tree, child: np.ndarray, d: np.ndarray, radial: np.ndarray, room: np.ndarray, parent_tangents,
            tangent: np.ndarray):
    """Rest geometry of the collars of child branches ``child`` (module notes).

    Parameters
    ----------
    tree : Tree
    child : (C,) int
        Branch objects that have a parent.
    d : (C, 3) float
        Unit directions in which they leave their parents.
    radial : (C, K, 3) float
        Unit directions of the K sides of their tubes, square to ``d``.
    room : (C,) float
        Length of each child's first band: the rim stays within the first half of it.
    parent_tangents : tuple
        The parents' tangents at the attach nodes and their neighbours, as the mesh's
        ``_node_tangents`` gives them (tangent, base, tip, next, previous).
    tangent : (N, 3) float
        The unit tangents of the parents' drawn rest curves at their nodes.

    Returns
    -------
    rim, normal : (C, K, 3) float
        The rim's vertices, from the child's base node, and their normals (the parent's).
    axis : (C, 3) float
        The parent's unit direction at the joint.
    apex : (C, 3) float
        The apex sunk in the parent, from the child's base node.
    """
    P = tree.rest_positions
    r = 0.5 * tree.node_diameter
    att = tree.attach_node[child]
    a, _, end, _, prv = parent_tangents
    R, rc = r[att], r[tree.object_start[child]]
    cos = np.sum(a * d, axis=1)
    am = a[:, None, :]
    # Along a parent: each side of the child's tube, widened to ρ, runs out along the child to
    # where it leaves the parent's drawn tube (radius R about the parent's tangent at the joint,
    # then, twice, the parent's Hermite centre line, tangent and radius where that put it), at
    # most half the first band out.
    rho = np.minimum(np.clip(0.5 * (R + rc), COLLAR_FLARE[0] * rc, COLLAR_FLARE[1] * rc), COLLAR_FIT * R)
    foot = rho[:, None, None] * radial
    s = np.clip(_leave(d, foot, am, np.broadcast_to(R[:, None], radial.shape[:2])), 0.0, 0.5 * room[:, None])
    k = att - tree.object_start[tree.parent[child]]
    for _ in range(2):
        centre, axis, radius = _drawn(tree, tangent, att, k, s[..., None] * d[:, None, :] + foot)
        s = np.clip(_leave(d, foot - centre, axis, radius), 0.0, 0.5 * room[:, None])
    side = s[..., None] * d[:, None, :] + foot
    # At a fork (on the parent's tip): the parent's end ring, widened at least to the flare
    # and then raised as far as a cone from the apex sunk below the end rises through the end
    # ring; turned towards a child more than COLLAR_FORK° off the parent's direction, by the excess.
    sink = np.minimum(COLLAR_SINK * R, 0.5 * np.linalg.norm(P[att] - P[prv], axis=1))
    top = np.maximum(R, COLLAR_FLARE[0] * rc)
    tilt = np.maximum(np.arccos(np.clip(cos, -1.0, 1.0)) - np.radians(COLLAR_FORK), 0.0)
    plane = np.cos(tilt)[:, None] * a + np.sin(tilt)[:, None] * _unit(d - cos[:, None] * a, _perpendicular(a))
    end_ring = (sink * (top / R - 1.0))[:, None, None] * am + top[:, None, None] * outward(radial, plane)
    rim = np.where(end[:, None, None], end_ring, side)
    apex = np.where(end[:, None], -sink[:, None] * a, 0.0)  # below a parent's end, else on its axis
    return rim, outward(rim, a), a, apex
