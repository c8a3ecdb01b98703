"""Small geometric helpers shared by the model, the physics and the renderer.

One home for what several modules need: unit vectors and perpendiculars, polygon area and
centroid (the lamina outline), per-node segment lengths and arc lengths that never count the
jump from one object's tip to the next object's base, and the rest frame of a leaf's lamina.

Nothing here imports the rest of the package at run time, so ``model``, ``physics`` and
``render`` may all import it.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:  # pragma: no cover - annotations only
    from .tree import Tree

__all__ = [
    "unit",
    "perpendicular",
    "polygon_area",
    "polygon_centroid",
    "segment_lengths",
    "arc_length",
    "object_lengths",
    "lamina_frames",
]


def unit(v, fallback=None) -> np.ndarray:
    """Rows of ``v`` scaled to unit length.

    Parameters
    ----------
    v : array_like, (..., 3)
        Vectors.
    fallback : array_like, (..., 3), optional
        Used instead where |v| <= 1e-9. Without it, a vector shorter than 1e-12 is returned
        unscaled (a zero vector stays zero: no NaN).

    Returns
    -------
    numpy.ndarray, (..., 3) float
    """
    v = np.asarray(v, float)
    n = np.linalg.norm(v, axis=-1, keepdims=True)
    out = v / np.where(n > 1e-12, n, 1.0)
    if fallback is not None:
        out = np.where(n > 1e-9, out, fallback)
    return out


def perpendicular(v) -> np.ndarray:
    """A unit vector perpendicular to each row of ``v``, stable for any direction.

    Parameters
    ----------
    v : array_like, (..., 3)
        Directions (need not be unit length).

    Returns
    -------
    numpy.ndarray, (..., 3) float
        v × ŷ normalised, or v × x̂ where v is within ~25° of the y axis. A zero ``v`` gives a
        zero vector.
    """
    v = np.asarray(v, float)
    helper = np.where(np.abs(v[..., 1:2]) < 0.9, [0.0, 1.0, 0.0], [1.0, 0.0, 0.0])
    return unit(np.cross(v, helper))


def polygon_area(xy, signed: bool = False) -> float:
    """Area of a simple polygon (shoelace formula).

    Parameters
    ----------
    xy : array_like, (K, 2)
        Vertices in order (the closing edge back to the first is implied).
    signed : bool
        Return the signed area (> 0 counter-clockwise) instead of its magnitude.

    Returns
    -------
    float
    """
    xy = np.asarray(xy, float)
    x, y = xy[:, 0], xy[:, 1]
    a = 0.5 * (float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))))
    return a if signed else abs(a)


def polygon_centroid(xy) -> tuple[float, float]:
    """Centroid of a simple polygon's area.

    Parameters
    ----------
    xy : array_like, (K, 2)
        Vertices in order, either orientation.

    Returns
    -------
    (float, float)
        The centroid; the mean of the vertices if the area is ~0.
    """
    xy = np.asarray(xy, float)
    x, y = xy[:, 0], xy[:, 1]
    xn, yn = np.roll(x, -1), np.roll(y, -1)
    cr = x * yn - xn * y
    a = 0.5 * cr.sum()
    if abs(a) < 1e-15:
        return float(x.mean()), float(y.mean())
    return float(((x + xn) * cr).sum() / (6 * a)), float(((y + yn) * cr).sum() / (6 * a))


def segment_lengths(tree: "Tree") -> np.ndarray:
    """Length of the segment leaving each node, within its object.

    Parameters
    ----------
    tree : Tree

    Returns
    -------
    numpy.ndarray, (N,) float
        |P[j+1] − P[j]| for every node j that is not its object's tip; 0 at tip nodes (the
        difference to the next object's base is not a segment).
    """
    X = np.asarray(tree.rest_positions, float)
    seg = np.zeros(len(X))
    if len(X) > 1:
        seg[:-1] = np.linalg.norm(np.diff(X, axis=0), axis=1)
    tips = np.asarray(tree.object_start) + np.asarray(tree.object_count) - 1
    seg[tips] = 0.0
    return seg


def arc_length(tree: "Tree") -> np.ndarray:
    """Distance of each node from its object's base along the object.

    Parameters
    ----------
    tree : Tree

    Returns
    -------
    numpy.ndarray, (N,) float
        Metres; 0 at every object's base node.
    """
    seg = segment_lengths(tree)
    csum = np.concatenate([[0.0], np.cumsum(seg[:-1])]) if len(seg) else seg
    start = np.asarray(tree.object_start)
    return csum - np.repeat(csum[start], np.asarray(tree.object_count))


def object_lengths(tree: "Tree") -> np.ndarray:
    """Rest length of each object (the sum of its segment lengths).

    Parameters
    ----------
    tree : Tree

    Returns
    -------
    numpy.ndarray, (M,) float
        Metres.
    """
    return np.add.reduceat(segment_lengths(tree), np.asarray(tree.object_start))


def lamina_frames(tree: "Tree", leaves) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Rest frame of each leaf's lamina (Fig. 6), as the mesh, picking and physics use it.

    v is the direction of the petiole's *last* segment (the lamina sits on the petiole's tip
    node), w the leaf's ``rest_w`` orthogonalised against v (any perpendicular if it runs
    along v), u = v × w. A lamina point (x, y) lies at ``L·(x·u + y·v)`` from the tip node,
    L the leaf's ``lamina_length``.

    Parameters
    ----------
    tree : Tree
    leaves : array_like of int, (L,)
        Object indices of leaves.

    Returns
    -------
    tip : (L,) int
        The petiole's tip node of each leaf.
    u, v, w : (L, 3) float
        Unit axes of each lamina's frame.
    """
    leaves = np.asarray(leaves, dtype=np.int64)
    P = np.asarray(tree.rest_positions, float)
    tipn = np.asarray(tree.object_start)[leaves] + np.asarray(tree.object_count)[leaves] - 1
    v = unit(P[tipn] - P[tipn - 1])
    w = np.asarray(tree.rest_w, float)[leaves]
    w = unit(w - np.sum(w * v, axis=1, keepdims=True) * v, perpendicular(v))
    return tipn, np.cross(v, w), v, w
