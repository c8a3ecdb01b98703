"""Welded junctions (docs/design.md §10): where a child branch's tube meets its parent's, its
base ring is a collar on the parent's surface (or, at a fork, on the parent's end ring) and
its base cap a cone sunk inside the parent. Used by :mod:`treeanim.render.mesh`."""

from __future__ import annotations

import numpy as np

from ..model.geometry import perpendicular as _perpendicular
from ..model.geometry import unit as _unit
from ..model.tree import Tree

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


def outward(q: np.ndarray, axis: np.ndarray) -> np.ndarray:
    """Unit directions of points ``q`` (C, K, 3) away from the lines through 0 along ``axis`` (C, 3)."""
    m = axis[:, None, :]
    return _unit(q - np.sum(q * m, axis=2, keepdims=True) * m, np.broadcast_to(m, q.shape))


def _leave(d: np.ndarray, radial: np.ndarray, rho: np.ndarray, axis: np.ndarray, R: np.ndarray) -> np.ndarray:
    """(C, K): the largest s at which s·d + ρ·radial meets the cylinder of radius R about
    ``axis`` (C, 1 or K, 3) through 0 (d (C, 3), radial (C, K, 3), ρ and R (C,))."""
    dm = d[:, None, :]
    d_off = dm - np.sum(dm * axis, axis=2, keepdims=True) * axis
    u_off = radial - np.sum(radial * axis, axis=2, keepdims=True) * axis
    qa = np.sum(d_off * d_off, axis=2)
    qb = rho[:, None] * np.sum(d_off * u_off, axis=2)
    qc = (rho * rho)[:, None] * np.sum(u_off * u_off, axis=2) - (R * R)[:, None]
    return (np.sqrt(np.maximum(qb * qb - qa * qc, 0.0)) - qb) / np.maximum(qa, 1e-12)


def collars(tree: Tree, child: np.ndarray, d: np.ndarray, radial: np.ndarray, room: np.ndarray, parent_tangents):
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
    # where it leaves the parent's tube (radius R about the parent's tangent at the joint,
    # which its curve follows there), at most half the first band out.
    rho = np.minimum(np.clip(0.5 * (R + rc), COLLAR_FLARE[0] * rc, COLLAR_FLARE[1] * rc), COLLAR_FIT * R)
    s = np.clip(_leave(d, radial, rho, am, R), 0.0, 0.5 * room[:, None])
    side = s[..., None] * d[:, None, :] + rho[:, None, None] * radial
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
