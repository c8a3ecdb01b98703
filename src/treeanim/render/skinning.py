"""The skinning of ``shaders/skin.glsl`` on the CPU, for exporters, picking and tests.

A vertex lies on the segment that leaves its node j, at a fraction t of its length (t = 0 at
the node). The segment's end frames are T₀ = orthonormalise(mix(R[j], R[prev], weight)) and
T₁ (:mod:`treeanim.render.mesh`'s notes say which nodes they blend). At rest the segment's
axis is the cubic Hermite curve q(t) from its node with end tangents d₀ and d₁
(:func:`hermite`): the rest chord's length along the object's unit tangents at the two nodes,
the bisectors of the neighbouring chords at inner nodes, so the curve through a chain of
segments has one tangent at each inner node. Bent, the curve runs between the segment's end
positions with tangents T₀d₀ and T₁d₁: the frames of an inner node are the same on both of
its segments, so it keeps one tangent there however the nodes turn. A vertex rides it turned
by the frame F(t) = orthonormalise((3t²−4t+1)·T₀ + (6t−6t²)·R[j] + (3t²−2t)·T₁), which carries
the rest curve's tangent onto the bent one (exactly where the three agree)::

    world = H(t) + F(t) @ (offset − q(t))

(t = 0: ``positions[j] + T₀ @ offset``).
"""

from __future__ import annotations

import numpy as np

from ..model.geometry import unit as _unit


def hermite(t: np.ndarray, chord: np.ndarray, d0: np.ndarray, d1: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A segment's cubic Hermite curve from its node: the point and the tangent at ``t``.

    Parameters
    ----------
    t : (V,) float
        Fraction along the segment.
    chord, d0, d1 : (V, 3) float
        The segment's chord and its end tangents (metres).

    Returns
    -------
    point, tangent : (V, 3) float
        q(t) from the segment's first node, and dq/dt.
    """
    t = np.asarray(t, float)[:, None]
    t2, t3 = t * t, t * t * t
    point = (3 * t2 - 2 * t3) * chord + (t3 - 2 * t2 + t) * d0 + (t3 - t2) * d1
    tangent = (6 * t - 6 * t2) * chord + (3 * t2 - 4 * t + 1) * d0 + (3 * t2 - 2 * t) * d1
    return point, tangent


def skin_points(positions, rotations, node, prev, weight, t, tip, offset, d0, d1) -> tuple[np.ndarray, np.ndarray]:
    """Where the vertex shader (``shaders/skin.glsl``) puts points, and the frames they turn with.

    The formula of the module notes, vectorised. :meth:`~treeanim.render.mesh.TreeMesh.skin`
    places the mesh's vertices with it, the picker (:mod:`treeanim.render.picking`) the
    centres of the tube's rings.

    Parameters
    ----------
    positions : (N, 3) float
        Node positions, world.
    rotations : (N, 3, 3) float
        Node rotations relative to rest.
    node, prev : (V,) int
        The node each point follows, and the node whose rotation T₀ blends in (< 0: the
        ground's identity).
    weight : (V,) float
        Weight of ``prev``'s rotation in T₀ (0: T₀ = ``rotations[node]``).
    t : (V,) float
        Fraction along the segment leaving ``node``, in [0, 1].
    tip : (V,) bool
        The segment ends at its object's free tip (T₁ = orthonormalise(1.5 R − ½ T₀)).
    offset : (V, 3) float
        Rest offset from ``node``'s rest position, metres.
    d0, d1 : (V, 3) float
        The rest curve's tangents at the segment's ends, metres (read where ``t`` > 0).

    Returns
    -------
    points : (V, 3) float64
    frames : (V, 3, 3) float64
        The rotation each point turns with (T₀ where ``t`` = 0).
    """
    j, prev = np.asarray(node), np.asarray(prev)
    w = np.asarray(weight, float)[:, None, None]
    t = np.asarray(t, float)
    offset = np.asarray(offset, float)
    P = np.asarray(positions, float)
    R = np.asarray(rotations, float)
    Rs = R[j]
    Rp = np.where(prev[:, None, None] >= 0, R[np.maximum(prev, 0)], np.eye(3))
    F = np.where(w > 0, blend_rotations(Rs * (1.0 - w) + Rp * w), Rs)  # T₀
    points = P[j] + np.einsum("vij,vj->vi", F, offset)
    m = np.flatnonzero(t > 0)
    if len(m):
        jm, tm, T0, Rm = j[m], t[m, None], F[m], Rs[m]
        d0m, d1m = np.asarray(d0, float)[m], np.asarray(d1, float)[m]
        c = np.einsum("vji,vj->vi", Rm, P[jm + 1] - P[jm])  # rest chord
        end = np.asarray(tip, bool)[m, None, None]
        T1 = blend_rotations(np.where(end, 1.5 * Rm - 0.5 * T0, 0.5 * (Rm + R[jm + 1])))
        rest, _ = hermite(t[m], c, d0m, d1m)
        bent, _ = hermite(t[m], P[jm + 1] - P[jm], np.einsum("vij,vj->vi", T0, d0m), np.einsum("vij,vj->vi", T1, d1m))
        t2, tm = tm[:, :, None] ** 2, tm[:, :, None]
        F[m] = blend_rotations((3 * t2 - 4 * tm + 1) * T0 + (6 * tm - 6 * t2) * Rm + (3 * t2 - 2 * tm) * T1)
        points[m] = P[jm] + bent + np.einsum("vij,vj->vi", F[m], offset[m] - rest)
    return points, F


def blend_rotations(m: np.ndarray) -> np.ndarray:
    """Gram–Schmidt on the columns of linearly blended rotations (..., 3, 3), as the shader does."""
    c0 = _unit(m[..., :, 0])
    c1 = m[..., :, 1] - np.sum(m[..., :, 1] * c0, axis=-1, keepdims=True) * c0
    c1 = _unit(c1)
    return np.stack([c0, c1, np.cross(c0, c1)], axis=-1)
