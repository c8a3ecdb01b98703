"""Leaves that fall (issue 12): when the season drops a leaf, it leaves the tree as a rigid
body, tumbles down through the wind and comes to rest flat on the ground.

A simple falling-leaf model, vectorised over every leaf in the air:

* **Drift.** The leaf's centre moves with a velocity v under gravity and a quadratic drag
  toward the wind, dv/dt = g + k|U − v|(U − v) with k = g/v_t², so in still air it sinks at its
  terminal speed v_t (0.8–1.6 m/s, that of broad leaves) and a wind carries it off downwind.
  The drag is taken implicitly (stable at any step and any wind).
* **Flutter and spin.** On top of the drift the leaf swings from side to side like a falling
  sheet of paper: a horizontal swing of amplitude A at f Hz, rocking about the axis across the
  swing by up to θ in step with it, while it spins about the vertical. Each leaf draws its own
  v_t, A, f, θ, spin and phase; the swing and rocking grow in over the first half-second, so a
  leaf leaves its twig without a jump.
* **Rest.** When its lowest node reaches the ground (y = 0), the leaf stops and turns flat,
  face up or down as it landed, over :data:`SETTLE_TIME`, pivoting on the ground; then it lies
  still.

Positions and rotations are those of the leaf's nodes when it fell, carried by the body's
motion: node k sits at c + Q·r_k and turns by Q·R_k, with Q the body's rotation since it fell.
"""

from __future__ import annotations

import copy

import numpy as np

from ..model.geometry import unit
from .rotation import qmat

__all__ = ["FallingLeaves"]

GRAVITY = 9.81
#: Terminal sinking speed in still air (m/s), drawn per leaf.
TERMINAL_SPEED = (0.8, 1.6)
#: Side-to-side swing: frequency (Hz), amplitude (m), rocking angle (rad), drawn per leaf.
SWING_HZ = (0.4, 1.0)
SWING_AMPLITUDE = (0.08, 0.25)
ROCKING = (0.3, 0.8)
#: Spin about the vertical (rad/s, either sense), drawn per leaf.
SPIN = (0.5, 3.0)
#: Time constant (s) over which the swing and rocking grow in after the leaf lets go.
RAMP_TIME = 0.4
#: Time (s) a landed leaf takes to turn flat, and its height above the ground at rest (m).
SETTLE_TIME = 0.3
REST_LIFT = 0.003
#: Fastest a leaf may be carried (m/s): a bound that keeps any wind's output finite.
MAX_SPEED = 200.0


def _axis_angle(axis: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """(F, 3, 3) rotations by ``angle`` (F,) about the unit ``axis`` (F, 3)."""
    half = 0.5 * np.asarray(angle, float)
    return qmat(np.vstack([np.cos(half), np.sin(half) * np.asarray(axis, float).T]))


class FallingLeaves:
    """Every leaf that has left the tree, in the air or on the ground.

    Parameters
    ----------
    object_start, object_count : (M,) int
        The tree's node ranges per object.
    normal : (M, 3) float
        Each object's rest w axis (for a leaf, its lamina's normal).
    seed : int
        Seed of the leaves' own draws (terminal speed, swing, spin).
    """

    _BODY = ("_n", "_c", "_v", "_off", "_Q", "_age", "_landed", "_Q_land", "_par", "_stale_p", "_stale_r")
    _NODE = ("_nodes", "_body", "_r", "_R", "_Pn", "_Rn")  # per node of a fallen leaf, body by body

    def __init__(self, object_start: np.ndarray, object_count: np.ndarray, normal: np.ndarray, seed: int):
        self._start = np.asarray(object_start)
        self._count = np.asarray(object_count)
        self._normal = np.asarray(normal, float)
        self._seed = int(seed)
        self.clear()

    def clear(self) -> None:
        """No leaf has fallen (and the draws start again from the seed)."""
        self._rng = np.random.default_rng([self._seed, 0xFA11])  # not the flutter's stream (0x1EAF)
        self.objects = np.zeros(0, np.int64)  # (F,) the fallen leaves
        # per leaf: rest normal now, drift centre, velocity, swing offset, rotation since it
        # fell, age, time since landing (−1: in the air), rotation at landing, own draws
        self._n, self._c, self._v, self._off = (np.zeros((0, 3)) for _ in range(4))
        self._Q, self._Q_land = np.zeros((0, 3, 3)), np.zeros((0, 3, 3))
        self._age, self._landed = np.zeros(0), np.zeros(0)
        self._par = np.zeros((0, 7))  # k, ω, A, θ, spin, phase, swing axis (angle)
        self._stale_p, self._stale_r = np.zeros(0, bool), np.zeros(0, bool)  # moved since posed
        # per node: index, body, offset from the centre and rotation when it fell, pose now
        self._nodes, self._body = np.zeros(0, np.int64), np.zeros(0, np.int64)
        self._r, self._Pn = np.zeros((0, 3)), np.zeros((0, 3))
        self._R, self._Rn = np.zeros((0, 3, 3)), np.zeros((0, 3, 3))
        self._first = np.zeros(0, np.int64)  # each body's first node in those

    def __len__(self) -> int:
        return len(self.objects)

    def copy(self) -> FallingLeaves:
        """An independent copy: its own arrays and random stream, the tree's constants shared
        (a timeline keeps one a step: 0.04 ms on the small cherry where a deep copy took 0.09)."""
        new = copy.copy(self)
        for name in ("objects", "_first", *self._BODY, *self._NODE):
            setattr(new, name, getattr(self, name).copy())
        new._rng = copy.deepcopy(self._rng)
        return new

    @property
    def airborne(self) -> np.ndarray:
        """(F,) bool: the fallen leaves still in the air."""
        return self._landed < 0.0

    def detach(self, objects: np.ndarray, positions: np.ndarray, rotations: np.ndarray) -> None:
        """Let ``objects`` (leaves) fall from the pose ``positions`` (N, 3), ``rotations``
        (N, 3, 3), at rest in the air."""
        objects = np.setdiff1d(np.asarray(objects, np.int64), self.objects)
        F = len(objects)
        if not F:
            return
        cnt = self._count[objects]
        ends = np.cumsum(cnt)
        body = np.repeat(np.arange(F), cnt)
        nodes = self._start[objects][body] + np.arange(ends[-1]) - (ends - cnt)[body]
        P = np.asarray(positions, float)[nodes]
        R = np.asarray(rotations, float)[nodes]
        c = np.zeros((F, 3))
        np.add.at(c, body, P)
        c /= cnt[:, None]
        n = np.einsum("fij,fj->fi", R[ends - 1], self._normal[objects])  # the lamina's normal now
        u = self._rng.random((8, F))
        lerp = lambda lohi, x: lohi[0] + (lohi[1] - lohi[0]) * x  # noqa: E731
        par = np.stack([
            GRAVITY / lerp(TERMINAL_SPEED, u[0]) ** 2,
            2 * np.pi * lerp(SWING_HZ, u[1]),
            lerp(SWING_AMPLITUDE, u[2]),
            lerp(ROCKING, u[3]),
            lerp(SPIN, u[4]) * np.where(u[5] < 0.5, -1.0, 1.0),
            2 * np.pi * u[6],
            2 * np.pi * u[7],
        ], axis=1)
        eye = np.broadcast_to(np.eye(3), (F, 3, 3))
        zero3 = np.zeros((F, 3))
        new = dict(_n=n, _c=c, _v=zero3, _off=zero3, _Q=eye, _age=np.zeros(F), _landed=np.full(F, -1.0),
                   _Q_land=eye, _par=par, _nodes=nodes, _body=body + len(self.objects), _r=P - c[body], _R=R,
                   _Pn=P, _Rn=R, _stale_p=np.zeros(F, bool), _stale_r=np.zeros(F, bool))
        self.objects = np.concatenate([self.objects, objects])
        for name in self._BODY + self._NODE:
            setattr(self, name, np.concatenate([getattr(self, name), new[name]]))
        self._first = np.searchsorted(self._body, np.arange(len(self.objects)))

    def remove(self, objects: np.ndarray) -> None:
        """Forget the fallen ``objects`` (leaves back on the tree)."""
        keep = ~np.isin(self.objects, objects)
        if keep.all():
            return
        node_keep = keep[self._body]
        renumber = np.cumsum(keep) - 1
        self.objects = self.objects[keep]
        for name in self._BODY:
            setattr(self, name, getattr(self, name)[keep])
        for name in self._NODE:
            setattr(self, name, getattr(self, name)[node_keep])
        self._body = renumber[self._body]
        self._first = np.searchsorted(self._body, np.arange(len(self.objects)))

    def _swing(self, idx: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The swing offset (F′, 3) and rotation since falling (F′, 3, 3) of leaves ``idx``."""
        k, w, A, theta, spin, phase, axis_angle = self._par[idx].T
        age = self._age[idx]
        s = np.sin(w * age + phase) * -np.expm1(-age / RAMP_TIME)  # grows in as it lets go
        ca, sa = np.cos(axis_angle), np.sin(axis_angle)
        zero = np.zeros_like(age)
        axis = np.stack([ca, zero, sa], axis=1)
        across = np.stack([-sa, zero, ca], axis=1)  # y × axis: the swing
        turn = _axis_angle(np.broadcast_to([0.0, 1.0, 0.0], axis.shape), spin * age)  # about the vertical
        return (A * s)[:, None] * across, turn @ _axis_angle(axis, theta * s)

    def step(self, wind_at, dt: float) -> None:
        """Advance every fallen leaf by ``dt`` seconds.

        Parameters
        ----------
        wind_at : callable or None
            ``wind_at(points (F′, 3)) -> (F′, 3)``: the wind there (m/s); None: calm.
        dt : float
            Step length (s), > 0.
        """
        air = self._landed < 0.0
        settle = (self._landed >= 0.0) & (self._landed < SETTLE_TIME)
        if not (air.any() or settle.any()):
            return
        ia = np.flatnonzero(air)
        if len(ia):
            c, v, k = self._c[ia], self._v[ia], self._par[ia, 0]
            U = np.zeros_like(c) if wind_at is None else np.asarray(wind_at(c + self._off[ia]), float)
            kdt = (k * np.linalg.norm(U - v, axis=1) * dt)[:, None]
            v = v + kdt * U  # dv/dt = g + k|U − v|(U − v), the drag implicit in v
            v[:, 1] -= GRAVITY * dt
            v /= 1.0 + kdt
            v = np.clip(np.nan_to_num(v), -MAX_SPEED, MAX_SPEED)
            self._v[ia] = v
            self._c[ia] = c + v * dt
            self._age[ia] += dt
            self._off[ia], self._Q[ia] = self._swing(ia)
        if settle.any():
            self._turn_flat(np.flatnonzero(settle), dt)
        self._stale_p |= air | settle
        self._stale_r |= air | settle
        y = np.einsum("nj,nj->n", self._Q[self._body, 1], self._r)  # the nodes' heights above c
        low = np.minimum.reduceat(y, self._first) + self._c[:, 1] + self._off[:, 1]
        hit = air & (low <= 0.0)  # landing: the swing folds into the drift, the body stops
        self._c[hit] += self._off[hit]
        self._off[hit] = 0.0
        self._landed[hit] = 0.0
        self._Q_land[hit] = self._Q[hit]
        lift = np.where(hit | settle, REST_LIFT - low, 0.0)  # landed leaves lie on the ground
        self._c[:, 1] += lift

    def _turn_flat(self, idx: np.ndarray, dt: float) -> None:
        """Turn the landed leaves ``idx`` toward flat (the lamina's normal to ±y) over
        :data:`SETTLE_TIME`; :meth:`step` then sets their lowest node on the ground."""
        t = np.minimum(self._landed[idx] + dt, SETTLE_TIME)
        self._landed[idx] = t
        s = t / SETTLE_TIME
        s = s * s * (3.0 - 2.0 * s)  # smoothstep
        Ql = self._Q_land[idx]
        n = np.einsum("fij,fj->fi", Ql, self._n[idx])
        up = np.where(n[:, 1:2] >= 0.0, 1.0, -1.0) * np.array([0.0, 1.0, 0.0])
        axis = np.cross(n, up)
        angle = np.arctan2(np.linalg.norm(axis, axis=1), np.einsum("fi,fi->f", n, up))
        self._Q[idx] = _axis_angle(unit(axis, np.broadcast_to([1.0, 0.0, 0.0], axis.shape)), s * angle) @ Ql

    def shown(self, M: int) -> np.ndarray:
        """(M,) bool: the fallen leaves."""
        out = np.zeros(M, bool)
        out[self.objects] = True
        return out

    def pose(self, positions: np.ndarray | None, rotations: np.ndarray | None = None) -> None:
        """Write the fallen leaves' nodes into ``positions`` (N, 3) and ``rotations``
        (N, 3, 3) (either may be None), in place."""
        if positions is not None:
            sel = np.flatnonzero(self._stale_p[self._body])  # nodes of leaves moved since posed
            b = self._body[sel]
            self._Pn[sel] = self._c[b] + self._off[b] + np.einsum("nij,nj->ni", self._Q[b], self._r[sel])
            self._stale_p[:] = False
            positions[self._nodes] = self._Pn
        if rotations is not None:
            sel = np.flatnonzero(self._stale_r[self._body])
            self._Rn[sel] = self._Q[self._body[sel]] @ self._R[sel]
            self._stale_r[:] = False
            rotations[self._nodes] = self._Rn
