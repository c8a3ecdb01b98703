"""The mouse's grab: on the tree model a :class:`TreeDrag` (the target handed to
:meth:`Simulation.drag`, whose stiff spring is solved inside the step); on the paper's model a
:class:`SpringPull` (a spring from a grabbed point of an object to a target (the cursor's
point), its force low-passed and capped, applied through :meth:`Simulation.pull`).

Both have the same interface for the viewer: ``object``, ``target``, ``aim``, ``step``,
``anchor``, ``grabbed_point``, ``spring``, ``release``; :func:`grab` makes the one ``sim.model``
takes, its spring scaled by a strength (1: :data:`~treeanim.physics.tree_sim.GRAB_STIFFNESS`
times the tree's own stiffness at the point on the tree model, a loop gain of :data:`GAIN` on
the paper's).

The SpringPull's stiffness comes from the simulation's own compliance at the grabbed point
(:meth:`Simulation.compliance`, the stiffness the bending uses), so the grabbed point covers a
set share of the way to the target (:data:`GAIN`) on any object, trunk or leaf. No GL, no
window: the viewer turns the cursor into a target (:meth:`SpringPull.aim`) and steps it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .simulation import MAX_PULL
from .tree_sim import GRAB_STIFFNESS

__all__ = ["grab", "TreeDrag", "SpringPull", "TAU", "GAIN", "MAX_LENGTHS"]

#: Time constant (s, simulated) of the low-pass on the pull force: it damps the loop between
#: the spring and the beam's static deflection, so the grabbed point settles without ringing.
TAU = 0.04
#: The spring's loop gain: at equilibrium the grabbed point covers GAIN / (1 + GAIN) of the
#: distance to the target (60 % for a small drag; a stiff beam bends less than that).
GAIN = 1.5
#: The pull force saturates at the spring force of a drag this many object lengths long.
MAX_LENGTHS = 2.0


class _Aimed:
    """The target of a grab moves in the plane through the grabbed point facing the camera
    (``plane_point``, ``plane_normal``, ``target``)."""

    def aim(self, origin, direction) -> None:
        """Move the target to where the ray from ``origin`` along ``direction`` meets the
        plane (kept where the ray runs along the plane; never behind the origin)."""
        o, d = np.asarray(origin, float), np.asarray(direction, float)
        denom = float(d @ self.plane_normal)
        if abs(denom) >= 1e-9:
            t = float((self.plane_point - o) @ self.plane_normal) / denom
            self.target = o + max(t, 0.0) * d


def _nearest(P: np.ndarray, nodes: np.ndarray, point: np.ndarray) -> tuple[int, float, np.ndarray]:
    """(segment k, fraction along it, nearest point) of the polyline ``P[nodes]`` to ``point``."""
    a, b = P[nodes[:-1]], P[nodes[1:]]
    e = b - a
    s = np.clip(np.einsum("ij,ij->i", point - a, e) / np.maximum(np.einsum("ij,ij->i", e, e), 1e-30), 0, 1)
    near = a + s[:, None] * e
    k = int(np.argmin(np.linalg.norm(near - point, axis=1)))
    return k, float(s[k]), near[k]


def grab(sim, obj: int, point, plane_normal, strength: float = 1.0):
    """The mouse's grab of object ``obj`` at world ``point`` for ``sim``'s model: a
    :class:`TreeDrag` on the tree model, a :class:`SpringPull` on the paper's; ``strength``
    scales its spring (1: the default of each)."""
    cls = TreeDrag if sim.model == "tree" else SpringPull
    return cls.grab(sim, obj, point, plane_normal, strength)


@dataclass
class TreeDrag(_Aimed):
    """A drag in progress on the tree model (make one with :meth:`grab`): the point at fraction
    :attr:`s` of the object's length is held by :meth:`Simulation.drag`, its target moved with
    the cursor.

    Attributes
    ----------
    object : int
        The grabbed object.
    s : float
        Fraction of the object's length (from its base) of the held point, 0 … 1 (a leaf is
        held where it hangs from its twig, whatever ``s``).
    offset : (3,) float
        Picked point minus the held point at grab time (the picked point lies on the bark or
        on a leaf's lamina): the held point is dragged to the target less this, so the picked
        point follows the cursor without a jump at the press.
    plane_point, plane_normal : (3,) float
        The plane the target moves in (facing the camera through the picked point).
    target : (3,) float
        The cursor's point in that plane.
    stiffness : float
        The spring, in units of the tree's own stiffness at the held point.
    sent : (3,) float or None
        The target last handed to :meth:`Simulation.drag` (the held point's).
    """

    object: int
    s: float
    offset: np.ndarray
    plane_point: np.ndarray
    plane_normal: np.ndarray
    target: np.ndarray
    stiffness: float = GRAB_STIFFNESS
    sent: np.ndarray | None = None

    @classmethod
    def grab(cls, sim, obj: int, point, plane_normal, strength: float = 1.0) -> "TreeDrag":
        """Grab object ``obj`` of ``sim`` (model 'tree') at world ``point``: ``s`` is the
        fraction of its length at the point of its current pose nearest ``point`` (measured on
        the rest lengths, as :meth:`Simulation.drag` takes it). The drag starts at once, its
        target where the held point is (nothing moves until the cursor does), its spring
        ``strength`` × :data:`~treeanim.physics.tree_sim.GRAB_STIFFNESS`."""
        tree = sim.tree
        nodes = tree.object_nodes(obj)
        point = np.asarray(point, float)
        L = np.linalg.norm(np.diff(tree.rest_positions[nodes], axis=0), axis=1)
        if len(nodes) < 2 or L.sum() <= 0:
            s = 1.0
        else:
            k, t, _ = _nearest(sim.positions, nodes, point)
            s = float(min(max((L[:k].sum() + t * L[k]) / L.sum(), 0.0), 1.0))
        held = np.asarray(sim.point_position(obj, s), float)
        d = cls(object=int(obj), s=s, offset=point - held, plane_point=point.copy(),
                plane_normal=np.asarray(plane_normal, float).copy(), target=point.copy(),
                stiffness=GRAB_STIFFNESS * float(strength))
        d.step(sim, 0.0)
        return d

    def anchor(self, sim) -> np.ndarray:
        """Where the grabbed (picked) point is now (world): the held point plus the offset."""
        return np.asarray(sim.point_position(self.object, self.s), float) + self.offset

    def grabbed_point(self, sim, exact: bool = True) -> np.ndarray:
        """Where the grabbed point is (the held point needs no whole pose: ``exact`` is moot)."""
        return self.anchor(sim)

    def step(self, sim, h: float, exact: bool = True) -> None:
        """Before a step: hand a moved target to :meth:`Simulation.drag` (the spring itself is
        solved inside the step)."""
        want = self.target - self.offset
        if self.sent is None or not np.array_equal(want, self.sent):
            sim.drag(self.object, want, self.s, self.stiffness)
            self.sent = want

    def spring(self, sim) -> float:
        """The spring (N/m) holding the point."""
        return sim.drags[self.object][1]

    def release(self, sim) -> None:
        """Let go: the object swings freely from where it is."""
        sim.release(self.object)


@dataclass
class SpringPull(_Aimed):
    """A pull in progress (make one with :meth:`grab`).

    Attributes
    ----------
    object : int
        The grabbed object.
    node : int
        Global index of the first node of the segment holding the anchor.
    s : float
        Where the anchor lies along that segment, 0 … 1.
    offset : (3,) float
        Picked point minus anchor at grab time (the picked point may lie on a leaf's lamina).
    plane_point, plane_normal : (3,) float
        The plane the target moves in (facing the camera through the picked point).
    target : (3,) float
        Where the spring pulls the grabbed point to.
    k : float
        Spring constant, N/m.
    f_max : float
        Largest force, N.
    force : (3,) float
        The current (low-passed) pull force, N.
    ratio : float
        Metres the grabbed point moves per metre the object's tip moves while bent by a tip
        force (the ratio of their compliances): between a frame's steps the grabbed point is
        followed through :meth:`Simulation.tip_position` instead of the whole pose.
    frame_anchor, frame_tip : (3,) float or None
        The grabbed point and the tip at the last exact step (from the pose).
    """

    object: int
    node: int
    s: float
    offset: np.ndarray
    plane_point: np.ndarray
    plane_normal: np.ndarray
    target: np.ndarray
    k: float
    f_max: float
    force: np.ndarray
    ratio: float = 1.0
    frame_anchor: np.ndarray | None = None
    frame_tip: np.ndarray | None = None

    @classmethod
    def grab(cls, sim, obj: int, point, plane_normal, strength: float = 1.0) -> "SpringPull":
        """Grab object ``obj`` of ``sim`` at world ``point`` (on it, or on its lamina), the
        target to move in the plane through ``point`` normal to ``plane_normal``.

        The anchor is the nearest point of the object's current pose; the spring constant is
        ``strength`` × :data:`GAIN` over :meth:`Simulation.compliance` there, and the force is
        capped at the spring force of a drag :data:`MAX_LENGTHS` object lengths long.
        """
        tree = sim.tree
        nodes = tree.object_nodes(obj)
        point = np.asarray(point, float)
        k, s, near = _nearest(sim.positions, nodes, point)
        offset = point - near
        G = max(sim.compliance(obj, k, s, offset), 1e-12)
        G_tip = max(sim.compliance(obj, len(nodes) - 2, 1.0), 1e-12)
        spring = float(strength) * GAIN / G
        length = float(np.sum(np.linalg.norm(np.diff(tree.rest_positions[nodes], axis=0), axis=1)))
        length += float(tree.lamina_length[obj])
        return cls(object=int(obj), node=int(nodes[k]), s=s, offset=offset, plane_point=point.copy(),
                   plane_normal=np.asarray(plane_normal, float).copy(), target=point.copy(), k=spring,
                   f_max=spring * MAX_LENGTHS * length, force=np.zeros(3), ratio=G / G_tip)

    def anchor(self, sim) -> np.ndarray:
        """Where the grabbed point is now (world), from ``sim``'s pose."""
        P = sim.positions
        return P[self.node] + self.s * (P[self.node + 1] - P[self.node]) + self.offset

    def grabbed_point(self, sim, exact: bool) -> np.ndarray:
        """Where the grabbed point is: exact from the pose when ``exact`` (then remembered with
        the tip), else followed from the last exact point by the tip's motion since (one tip,
        not N nodes, a step)."""
        tip = sim.tip_position(self.object)
        if exact or self.frame_anchor is None:
            self.frame_anchor, self.frame_tip = self.anchor(sim), tip
            return self.frame_anchor
        return self.frame_anchor + self.ratio * (tip - self.frame_tip)

    def step(self, sim, h: float, exact: bool = True) -> None:
        """Before a step of ``h`` seconds: the spring's force towards the target, capped at
        :attr:`f_max` (and :data:`~treeanim.physics.simulation.MAX_PULL`), low-passed with
        :data:`TAU`, held on the object through :meth:`Simulation.pull`."""
        raw = self.k * (self.target - self.grabbed_point(sim, exact))
        mag = float(np.linalg.norm(raw))
        f_max = min(self.f_max, MAX_PULL)
        if mag > f_max:
            raw *= f_max / mag
        self.force += (h / (TAU + h)) * (raw - self.force)
        sim.pull(self.object, self.force)

    def spring(self, sim) -> float:
        """The spring (N/m) pulling the point."""
        return self.k

    def release(self, sim) -> None:
        """Let go: the object swings freely from where it is."""
        sim.release(self.object)
