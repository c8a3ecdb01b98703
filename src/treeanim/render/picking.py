"""Vectorised ray picking against the tree as the renderer draws it.

The axis of every tube is the polyline through the centres of its mesh rings
(:mod:`treeanim.render.mesh`), placed each pick by the vertex shader's own formula
(:func:`~treeanim.render.skinning.skin_points`): a branch's segment runs along its cubic Hermite
curve in :func:`~treeanim.model.tree.curve_bands` bands (four along a one-segment twig), a
petiole's and a blade's straight from node to node, a blade on to its apex half a segment
beyond its tip. Each piece of the polyline is a capsule of the tube's radius (a blade: half its
width), tapering along it as the tube does. A leaf's lamina is one more capsule, along the
midrib of its outline's middle, 0.8 of its half width.

A ray meets a capsule within its radius, or within ``min_pixels`` pixels of its axis at its
distance from the eye. Twigs and blades thinner than ``thin_pixels`` are drawn a pixel wider
each side (``shaders/tree.vert``), and such twigs behind every solid surface (``DEPTH_THIN``).
The hit is the nearest capsule whose drawn surface the ray meets, save thin twigs; failing
that, the nearest capsule within reach.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..model.tree import Tree, curve_bands
from .collars import leaders, tube_radius
from .mesh import _node_tangents, _object_nodes, lamina_frames, segment_tangents
from .skinning import hermite, skin_points


class PickHit(NamedTuple):
    """A pick: the object, the point on its axis closest to the ray, and the distance along
    the ray from its origin."""

    object: int
    point: np.ndarray
    distance: float


class Picker:
    """Axis and capsule tables of ``tree`` built once; :meth:`pick` per click.

    Parameters
    ----------
    tree : Tree
    """

    def __init__(self, tree: Tree) -> None:
        self.tree = tree
        kind = np.asarray(tree.kind)
        P = tree.rest_positions
        N = tree.n_nodes
        r = tube_radius(tree)

        # The tubes' rings, as render/mesh.py's _tubes places them: from each node but an
        # object's tip, one ring per band of the segment leaving it; then the object's end
        # ring (a branch's at t = 1 on its last segment, else its tip node's own).
        objs = np.flatnonzero(tree.object_count >= 2)
        nodes, k, obj = _object_nodes(tree, objs)
        count = tree.object_count[obj]
        base, tip = k == 0, k == count - 1
        inner = ~(base | tip)
        curved = kind[obj] == "branch"
        bands = np.where(curved, curve_bands(count, tree.joint_turn()[obj]), 1)
        reps = np.where(tip, 1, bands)
        src = np.repeat(np.arange(len(nodes)), reps)
        t = (np.arange(len(src)) - np.repeat(np.cumsum(reps) - reps, reps)) / bands[src]
        end = tip[src]
        shift = end & curved[src]
        src = np.where(shift, src - 1, src)
        t = np.where(shift, 1.0, t)
        # T₀ of the segment leaving each node: a branch's base turns with its parent's attach
        # node (the ground's identity under a root), an inner joint with the node before.
        child = tree.parent[obj] >= 0
        prev = np.where(curved & base, np.where(child, tree.attach_node[obj], -1), np.where(inner, nodes - 1, nodes))
        weight = np.where(curved & base, 1.0, np.where(inner, 0.5, 0.0))
        # A branch carrying branches on its tip ends in their base frame, not a free tip's.
        carries = np.zeros(tree.n_objects, bool)
        sub = np.flatnonzero((tree.parent >= 0) & (kind == "branch"))
        par = tree.parent[sub]
        carries[par[tree.attach_node[sub] == tree.object_start[par] + tree.object_count[par] - 1]] = True
        ring_obj = obj[src]
        free_end = curved[src] & tip[np.minimum(src + 1, len(nodes) - 1)] & ~carries[ring_obj]
        j = nodes[src]
        j1 = np.minimum(j + 1, N - 1)
        # A branch's rest axis: each segment's Hermite curve (render/skinning.py).
        tangent = _node_tangents(tree, nodes, k, obj, True)[0]
        leaders(tree, nodes, tangent)
        length = np.where(curved[src], np.linalg.norm(P[j1] - P[j], axis=1), 0.0)
        d0, d1 = segment_tangents(tangent, src, length)
        offset = hermite(t, P[j1] - P[j], d0, d1)[0]
        radius = (1.0 - t) * r[j] + t * r[j1]
        first_cap = np.flatnonzero(~end)  # a piece from each ring to the next, within an object

        # A blade ends in a triangle to an apex half its last segment beyond its tip.
        blade_end = np.flatnonzero(end & (kind[ring_obj] == "blade"))
        bt = j[blade_end]
        apex = len(src) + np.arange(len(bt))

        # A lamina: its midrib through the middle of its outline, in the leaf's rest frame.
        leaves = np.flatnonzero(kind == "leaf")
        lam = tree.lamina
        if lam is not None and len(leaves) and len(lam.outline):
            tipn, u, v, w = lamina_frames(tree, leaves)
            x, y = lam.outline[:, 0], lam.outline[:, 1]
            xm = 0.5 * (x.max() + x.min())
            L = np.asarray(tree.lamina_length, float)[leaves][:, None]
            lam_start = L * (xm * u + y.min() * v + lam.curl * xm * xm * w)
            lam_end = lam_start + L * ((y.max() - y.min()) * v)
            lam_radius = 0.8 * L[:, 0] * 0.5 * (x.max() - x.min())
        else:
            tipn = leaves = np.zeros(0, np.int64)
            lam_start = lam_end = np.zeros((0, 3))
            lam_radius = np.zeros(0)
        lam_a = len(src) + len(bt) + np.arange(len(leaves))
        lam_b = lam_a + len(leaves)

        # Points skinned per pick: rings, blades' apexes, laminas' midrib ends (t = 0 on their
        # node: placed rigidly with T₀ = its rotation).
        z = np.zeros(len(bt) + 2 * len(leaves))
        self.node = np.concatenate([j, bt, tipn, tipn])
        self.prev = np.concatenate([prev[src], bt, tipn, tipn])
        self.weight = np.concatenate([weight[src], z])
        self.t = np.concatenate([t, z])
        self.free_end = np.concatenate([free_end, z > 0])
        self.offset = np.concatenate([offset, 0.5 * (P[bt] - P[bt - 1]), lam_start, lam_end])
        self.d0 = np.concatenate([d0, np.zeros((len(z), 3))])
        self.d1 = np.concatenate([d1, np.zeros((len(z), 3))])

        # Capsules: from point ia to ib, radius r0 there and r1 at ib.
        self.cap_a = np.concatenate([first_cap, blade_end, lam_a])
        self.cap_b = np.concatenate([first_cap + 1, apex, lam_b])
        self.cap_object = np.concatenate([ring_obj[first_cap], ring_obj[blade_end], leaves]).astype(np.int64)
        self.cap_r0 = np.concatenate([radius[first_cap], radius[blade_end], lam_radius])
        self.cap_r1 = np.concatenate([radius[first_cap + 1], np.zeros(len(bt)), lam_radius])
        cap_kind = kind[self.cap_object]
        self.cap_bark = cap_kind == "branch"
        self.cap_thin_drawn = self.cap_bark | (cap_kind == "blade")  # drawn wider when thin

    def axis_points(self, positions: np.ndarray, rotations: np.ndarray) -> np.ndarray:
        """The skinned points the capsules join, for a pose.

        Parameters
        ----------
        positions : (N, 3), rotations : (N, 3, 3)
            The pose (as ``Simulation.positions`` / ``rotations``).

        Returns
        -------
        (Q, 3) float
            The capsules run from row :attr:`cap_a` to row :attr:`cap_b` of it.
        """
        return skin_points(positions, rotations, self.node, self.prev, self.weight, self.t, self.free_end,
                           self.offset, self.d0, self.d1)[0]

    def pick(self, positions: np.ndarray, rotations: np.ndarray, origin, direction, *,
             present: np.ndarray | None = None, pixel_angle: float = 0.0,
             min_pixels: float = 4.0, thin_pixels: float = 0.0) -> PickHit | None:
        """The object the ray picks (module notes), or None.

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
        min_pixels : float
            Smallest pick radius, pixels.
        thin_pixels : float
            The renderer's ``Scene.thin_pixels`` in the same pixels: twigs and blades of a
            smaller half width on screen are drawn a pixel wider each side, and such twigs
            behind every solid surface (0: none is).

        Returns
        -------
        PickHit or None
        """
        o = np.asarray(origin, float)
        d = np.asarray(direction, float)
        d = d / np.linalg.norm(d)
        pts = self.axis_points(positions, rotations)
        a = pts[self.cap_a]
        e = pts[self.cap_b] - a

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

        radius = self.cap_r0 + s * (self.cap_r1 - self.cap_r0)
        px = pixel_angle * t  # a pixel's size there, metres
        thin = self.cap_thin_drawn & (radius < thin_pixels * px)
        drawn = np.where(thin, radius + px, radius)
        hit = (dist <= np.maximum(drawn, min_pixels * px)) & (t > 0)
        if present is not None:
            hit &= np.asarray(present, bool)[self.cap_object]
        if not hit.any():
            return None
        solid = hit & (dist <= drawn) & ~(thin & self.cap_bark)
        pool = solid if solid.any() else hit
        k = np.flatnonzero(pool)[np.argmin(t[pool])]
        return PickHit(int(self.cap_object[k]), on_seg[k], float(t[k]))


def pick(tree: Tree, positions, rotations, origin, direction, **kw) -> PickHit | None:
    """One-off :meth:`Picker.pick` (builds the tables each call).

    Parameters
    ----------
    tree : Tree
    positions, rotations, origin, direction
        As :meth:`Picker.pick`.
    **kw
        Keywords of :meth:`Picker.pick`.

    Returns
    -------
    PickHit or None
    """
    return Picker(tree).pick(positions, rotations, origin, direction, **kw)
