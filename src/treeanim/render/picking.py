"""Vectorised ray picking against the tree's deformed segments.

Every segment of every object is a capsule around its axis, of radius half its mean diameter
(a blade: half its width), widened to at least ``min_pixels`` pixels at its distance from the
eye. A leaf's lamina is one more capsule, from the petiole's tip along the lamina's midrib,
as wide as the lamina. The hit is the capsule the ray meets nearest the eye.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..model.tree import Tree
from .mesh import lamina_frames


class PickHit(NamedTuple):
    """A pick: the object, the point on its axis closest to the ray, and the distance along
    the ray from its origin."""

    object: int
    point: np.ndarray
    distance: float


class Picker:
    """Segment tables of ``tree`` built once; :meth:`pick` per click.

    Parameters
    ----------
    tree : Tree
    """

    def __init__(self, tree: Tree) -> None:
        self.tree = tree
        N = tree.n_nodes
        node_obj = tree.node_object
        a = np.arange(N - 1)
        a = a[node_obj[a] == node_obj[a + 1]]  # segments inside one object
        self.seg_a = a
        self.seg_b = a + 1
        self.seg_object = node_obj[a]
        self.seg_radius = 0.25 * (tree.node_diameter[a] + tree.node_diameter[a + 1])

        leaves = np.flatnonzero(tree.kind == "leaf")
        lam = tree.lamina
        if lam is not None and len(leaves) and len(lam.outline):
            tipn, u, v, w = lamina_frames(tree, leaves)
            x, y = lam.outline[:, 0], lam.outline[:, 1]
            L = tree.lamina_length[leaves][:, None]
            self.lam_node = tipn
            self.lam_object = leaves
            self.lam_start = L * (y.min() * v)  # rest offsets from the tip node
            self.lam_vec = L * ((y.max() - y.min()) * v)
            self.lam_radius = (L[:, 0] * 0.5 * (x.max() - x.min())) * 0.8
        else:
            self.lam_node = np.zeros(0, int)
            self.lam_object = np.zeros(0, int)
            self.lam_start = self.lam_vec = np.zeros((0, 3))
            self.lam_radius = np.zeros(0)

    def pick(self, positions: np.ndarray, rotations: np.ndarray, origin, direction, *,
             present: np.ndarray | None = None, pixel_angle: float = 0.0,
             min_pixels: float = 4.0) -> PickHit | None:
        """The object nearest the eye whose capsule the ray meets, or None.

        Parameters
        ----------
        positions : (N, 3), rotations : (N, 3, 3)
            The current pose (as ``Simulation.positions`` / ``rotations``).
        origin, direction : (3,)
            The ray (direction need not be unit).
        present : (M,) bool or None
            Objects that can be hit (None: all).
        pixel_angle : float
            Size of a pixel at 1 m from the eye (``OrbitCamera.pixel_angle(height)``); with
            ``min_pixels`` it sets the smallest pick radius at each distance.
        """
        o = np.asarray(origin, float)
        d = np.asarray(direction, float)
        d = d / np.linalg.norm(d)
        P = np.asarray(positions, float)
        a = np.concatenate([P[self.seg_a], P[self.lam_node] + np.einsum(
            "kij,kj->ki", rotations[self.lam_node], self.lam_start)])
        e = np.concatenate([P[self.seg_b] - P[self.seg_a], np.einsum(
            "kij,kj->ki", rotations[self.lam_node], self.lam_vec)])
        obj = np.concatenate([self.seg_object, self.lam_object])
        radius = np.concatenate([self.seg_radius, self.lam_radius])

        # Closest points between the segments a + s e (s in [0, 1]) and the ray o + t d (t >= 0).
        r = a - o
        ee = np.maximum(np.einsum("ij,ij->i", e, e), 1e-30)
        b = e @ d
        c = np.einsum("ij,ij->i", e, r)
        f = r @ d
        denom = ee - b * b
        s = np.where(denom > 1e-12 * ee, np.clip((b * f - c) / np.where(denom > 0, denom, 1.0), 0, 1), 0.0)
        t = b * s + f
        neg = t < 0
        t = np.where(neg, 0.0, t)
        s = np.where(neg, np.clip(-c / ee, 0, 1), s)
        on_seg = a + s[:, None] * e
        dist = np.linalg.norm(on_seg - (o + t[:, None] * d), axis=1)

        reach = np.maximum(radius, min_pixels * pixel_angle * t)
        hit = (dist <= reach) & (t > 0)
        if present is not None:
            hit &= np.asarray(present, bool)[obj]
        if not hit.any():
            return None
        k = np.flatnonzero(hit)[np.argmin(t[hit])]
        return PickHit(int(obj[k]), on_seg[k], float(t[k]))


def pick(tree: Tree, positions, rotations, origin, direction, **kw) -> PickHit | None:
    """One-off :meth:`Picker.pick` (builds the segment tables each call)."""
    return Picker(tree).pick(positions, rotations, origin, direction, **kw)
