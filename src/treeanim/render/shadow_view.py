"""The sun's shadow map fitted to the view, for a scene larger than the view
(:meth:`~.shadow.ShadowMap.follow`; docs/design.md §17, Drawing).

The map covers, across the sun's rays, what the camera sees of the scene within
:data:`VIEW_REACH` of its eye: the corners of the polytope where the view's frustum, cut at that
depth, meets the box that holds every receiver (the scene's box and its shadow on the ground).
Its depth range still holds every caster of the scene. So its texels are as fine as the view
near the eye needs, and stay so as the camera moves among the trees: the map's size steps by
:data:`EXTENT_STEP` (not with every move), and its corner moves in whole texels, so a texel
covers the same ground from frame to frame and shadow edges do not shimmer.
"""

from __future__ import annotations

import itertools
import math

import numpy as np

from .culling import frustum_planes

#: The map reaches this many times the camera's distance to its target from the eye (and no
#: less than :data:`MIN_REACH` metres): the target's surroundings and what lies before them.
VIEW_REACH = 1.5
MIN_REACH = 8.0
#: The map's side grows and shrinks in steps of this factor.
EXTENT_STEP = 2.0 ** 0.25
#: Shadows fade out over this share of the map's half side at its border (the trees beyond lit,
#: without a seam).
EDGE_FADE = 0.1

_TRIPLES = np.array(list(itertools.combinations(range(12), 3)))


def box_planes(lo, hi) -> np.ndarray:
    """(6, 4) planes (n, d) of the box ``lo`` .. ``hi``: inside where n·p + d ≥ 0."""
    eye = np.eye(3)
    return np.vstack([np.column_stack([eye, -np.asarray(lo, float)]), np.column_stack([-eye, np.asarray(hi, float)])])


def polytope_vertices(planes: np.ndarray, tol: float = 1e-6) -> np.ndarray:
    """(V, 3) corners of the convex polytope ``planes`` (12, 4) keep (n·p + d ≥ 0): every point
    where three of the planes meet and that all keep (none if the polytope is empty)."""
    A = planes[_TRIPLES, :3]
    b = -planes[_TRIPLES, 3]
    ok = np.abs(np.linalg.det(A)) > 1e-12
    p = np.linalg.solve(A[ok], b[ok][..., None])[..., 0]
    inside = np.all(p @ planes[:, :3].T + planes[:, 3] >= -tol * (1.0 + np.abs(p).max(axis=1, keepdims=True)), axis=1)
    return p[inside]


def view_slice(view_proj: np.ndarray, eye, forward, reach: float) -> np.ndarray:
    """(6, 4) planes of the view's frustum, its far plane moved to ``reach`` metres from the
    ``eye`` along its unit ``forward``."""
    planes = frustum_planes(view_proj)
    f = np.asarray(forward, float)
    planes[5] = np.r_[-f, f @ np.asarray(eye, float) + reach]
    return planes


def seen_corners(receivers: tuple[np.ndarray, np.ndarray], slice_planes: np.ndarray) -> np.ndarray:
    """(V, 3) corners of the part of the box ``receivers`` (everything a shadow can fall on)
    that the view's ``slice_planes`` (:func:`view_slice`) hold; none where the view sees none
    of it."""
    return polytope_vertices(np.vstack([box_planes(*receivers), slice_planes]))


def view_window(basis, corners: np.ndarray, size: int, whole: float) -> tuple[float, float, float, float] | None:
    """The map's window across the sun's rays for a view, snapped to its texels.

    Parameters
    ----------
    basis : (right, up, forward)
        The sun's axes (:func:`~.shadow.sun_basis`).
    corners : (V, 3) float, V > 0
        What the view sees of the receivers (:func:`seen_corners`).
    size : int
        The map's texels a side.
    whole : float
        The side of the map that holds the whole scene (metres).

    Returns
    -------
    (x0, x1, y0, y1) or None
        A square along the sun's right and up axes (metres), its side a power of
        :data:`EXTENT_STEP` and its corner on the texel grid; None where it would be no smaller
        than ``whole``.
    """
    right, up = basis[0], basis[1]
    x, y = corners @ right, corners @ up
    side = max(np.ptp(x), np.ptp(y)) * (1.0 + 4.0 / size) + 1e-6
    side = EXTENT_STEP ** math.ceil(math.log(side, EXTENT_STEP))
    if side >= whole:
        return None
    texel = side / size
    x0 = math.floor((0.5 * (x.min() + x.max()) - 0.5 * side) / texel) * texel
    y0 = math.floor((0.5 * (y.min() + y.max()) - 0.5 * side) / texel) * texel
    return x0, x0 + side, y0, y0 + side


def window_on_ground(basis, window) -> np.ndarray:
    """(4, 2) corners (x, z), in order round it, of the ground y = 0 that the map's ``window``
    covers (where the sun's rays through it meet the ground)."""
    right, up, forward = basis
    x0, x1, y0, y1 = window
    q = np.array([x0 * right + y0 * up, x1 * right + y0 * up, x1 * right + y1 * up, x0 * right + y1 * up])
    ground = q - np.outer(q[:, 1] / forward[1], forward)
    return ground[:, [0, 2]]


def clip_convex(polygon: np.ndarray, clipper: np.ndarray) -> np.ndarray:
    """The part of convex ``polygon`` (K, 2) inside convex ``clipper`` (C, 2), both in order round
    them (either way round): Sutherland-Hodgman."""
    centre = clipper.mean(axis=0)
    out = np.asarray(polygon, float)
    for a, b in zip(clipper, np.roll(clipper, -1, axis=0)):
        n = np.array([a[1] - b[1], b[0] - a[0]])
        if n @ (centre - a) < 0:
            n = -n
        d = (out - a) @ n
        kept = []
        for i in range(len(out)):
            j = (i + 1) % len(out)
            if d[i] >= 0:
                kept.append(out[i])
            if (d[i] >= 0) != (d[j] >= 0):
                kept.append(out[i] + (out[j] - out[i]) * (d[i] / (d[i] - d[j])))
        out = np.array(kept).reshape(-1, 2)
        if not len(out):
            break
    return out
