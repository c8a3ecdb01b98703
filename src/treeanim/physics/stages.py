"""The stages of the paper's step (docs/design.md §6): wind → loads → oscillators → bending →
hierarchy.

:class:`Stages` is mixed into :class:`~treeanim.physics.paper_sim.PaperSim`, whose state its
methods read and advance; :meth:`PaperSim.step <treeanim.physics.paper_sim.PaperSim.step>`
calls them in order.
"""

from __future__ import annotations

import math

import numpy as np

from .bend_angle import saturating_twist
from .rotation import qrot

#: Time constant (s) of the low-pass filter on base accelerations (base excitation). It keeps
#: the finite-difference acceleration finite and smooth at any dt and delays it by ~10 ms.
ACCEL_TAU = 0.01
#: Velocities and accelerations are differences over a step of at least this (s): over a
#: shorter one (a step of 1e-320 s) the change in position is rounding noise.
MIN_RATE_STEP = 1e-6


class Stages:
    """The step's stages, each a few whole-array operations over all objects."""

    def _wind_at_samples(self, t: float) -> np.ndarray | None:
        """Stage 1: the wind (M, 3) at every object's sample point (previous pose), or None."""
        if self._wind is None:
            return None
        pts = self._ws.get("pts", (self._M, 3))
        pts[...] = self._sample_pos.T
        U = np.asarray(self._wind.sample(pts, t), dtype=float)
        if U.shape != (self._M, 3):
            raise ValueError(f"wind.sample returned shape {U.shape}, expected {(self._M, 3)}")
        if not np.isfinite(U).all():
            raise ValueError("wind.sample returned non-finite velocities (NaN or inf)")
        return U

    def _step_paper(self, U, f3: np.ndarray, z3: np.ndarray, dt: float) -> None:
        """The paper's step (docs/design.md §6): linear loads on each object's own area, Eqs. 2–12."""
        M = self._M
        ws = self._ws
        mul = np.multiply
        # 2. World force on each object: wind (Eq. 19 × area × gain), pulls, base excitation.
        Fw = ws.get("Fw", (3, M))
        if U is not None:
            mul(U.T, self._gain_area, out=Fw)
        else:
            Fw.fill(0.0)
        for i, f in self._pulls.items():
            Fw[:, i] += f
        if self._coupling and len(self._nonroot):
            inertia = np.take(self._att_a, self._att_col, axis=1, out=ws.get("inertia", (3, M)))
            inertia *= self._mass
            Fw -= inertia
        # Local loads L = (U·u, U·v, U·w) in the previous-step frame, carried by the parent
        # (Eqs. 12, 19): the inverse of the object's frame applied to the world force.
        L = qrot(self._frame, Fw, conj=True, out=self._L, ws=ws)

        # 3. Oscillators (Eqs. 2–5), signed loads, unit static gain.
        g = ws.get("g", (3, M))
        g[0] = L[2]  # g_u = L_w
        mul(self._lever, L[2], out=g[1])  # g_v = r·L_w
        g[2] = L[0]  # g_w = L_u
        self._osc.step(self._p, self._pd, g, f3, z3, dt)
        if self._pulls:  # held objects sit at the static deflection of their load (§8)
            held = np.fromiter(self._pulls, dtype=np.int64)
            self._p[:, held] = g[:, held]
            self._pd[:, held] = 0.0

        # 4. Force in the local rest frame (Eq. 6): (L′_w, 0, L′_u); twist (Eq. 11).
        po = np.take(self._p, self._bplan.order, axis=1, out=ws.get("po", (3, M)))
        gamma = saturating_twist(po[1], self._c0k_ord, self._neg_half_pi_over_n_ord)  # Eq. 11
        # 5. Bend every object in its local rest frame (Eqs. 7–10).
        bp = self._bplan
        bp.bend(po[2], po[0], gamma, self._k, predict=self._predict(dt))
        self._compose()
        self._paper_base_motion(dt)

    def _predict(self, dt: float) -> float:
        """The bending solver's extrapolation ratio dt/dt_prev (0 on the first step)."""
        return 0.0 if self._dt_prev is None else min(dt / self._dt_prev, 2.0)

    def _compose(self) -> None:
        """Stage 6: compose the hierarchy (Eq. 12), then the objects' frames and sample points."""
        bp, ws, M = self._bplan, self._ws, self._M
        P = self._P
        self._cplan.compose_structural(bp.q, bp.o, self._Fw, P)  # Eq. 12
        self._cplan.object_frames(self._Fw, P, out=(self._frame, self._base))
        so = np.take(bp.o, self._sample_ofs, axis=1, out=ws.get("so", (3, M)))  # the middle node
        qrot(self._frame, so, out=self._sample_pos, ws=ws)
        self._sample_pos += self._base

    def _paper_base_motion(self, dt: float) -> None:
        """Base accelerations for the next step's excitation, low-passed (finite at any dt)."""
        if len(self._att_nodes):
            x = self._P[:, self._att_nodes]
            vel = (x - self._att_x) / max(dt, MIN_RATE_STEP)
            h = max(dt if self._dt_prev is None else 0.5 * (dt + self._dt_prev), MIN_RATE_STEP)
            a_raw = (vel - self._att_v) / h
            alpha = -math.expm1(-dt / ACCEL_TAU)
            acc = self._att_a[:, :-1]
            acc += alpha * (a_raw - acc)
            self._att_x = x
            self._att_v = vel
