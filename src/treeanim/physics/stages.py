"""The stages of one step (docs/design.md §6, §12, §13): wind → aerodynamic loads → load path
and oscillators → bending → hierarchy, for the load path and for the paper's model.

:class:`Stages` is mixed into :class:`~treeanim.physics.simulation.Simulation`, whose state its
methods read and advance; :meth:`Simulation.step <treeanim.physics.simulation.Simulation.step>`
calls them in order.
"""

from __future__ import annotations

import math

import numpy as np

from .bend_angle import saturating_twist
from .oscillator import exact_coefficients, exact_response
from .rotation import dot, qrot

#: Time constant (s) of the low-pass filter on base accelerations (base excitation). It keeps
#: the finite-difference acceleration finite and smooth at any dt and delays it by ~10 ms.
ACCEL_TAU = 0.01
#: Velocities and accelerations are differences over a step of at least this (s): over a
#: shorter one (a step of 1e-320 s) the change in position is rounding noise.
MIN_RATE_STEP = 1e-6
#: The load path's longest step (s). Its base excitation is explicit — each object feels its
#: ancestors' accelerations at the start of the step — and a crown's mass far outweighs the
#: limbs that carry it, so over steps much longer than this the loop from a child's inertia
#: to its parent's motion and back to the child gains energy (a winter small cherry, left in
#: a 5 m/s breeze at 1/30 s steps, thrashed within a minute; 1/40 s is about the limit).
#: :meth:`Simulation.step <treeanim.physics.simulation.Simulation.step>` divides longer
#: steps into sub-steps of at most this length, up to MAX_SUBSTEPS of them; over longer
#: sub-steps still (a step over a second: the tree all but settles within it) the base
#: excitation is off.
MAX_SUBSTEP = 1.0 / 60.0
MAX_SUBSTEPS = 64


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

    def _wind_at_points(self, t: float):
        """``points (n, 3) -> (n, 3)`` the wind at time ``t`` (non-finite values zeroed), or None."""
        if self._wind is None:
            return None
        return lambda pts: np.nan_to_num(np.asarray(self._wind.sample(pts, t), float), posinf=0.0, neginf=0.0)

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
        if self._load_path:  # the true middle: half the arc length along the bent object
            so = np.take(bp.o, self._mid_b, axis=1, out=ws.get("so", (3, M)))
            so *= self._mid_t
            if len(self._mid_far):
                so[:, self._mid_far] += bp.o[:, self._mid_a] * self._mid_ta
        else:
            so = np.take(bp.o, self._sample_ofs, axis=1, out=ws.get("so", (3, M)))
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

    def _step_load_path(self, U, f3: np.ndarray, z3: np.ndarray, dt: float) -> None:
        """The whole-tree step (docs/design.md §12): aerodynamic loads → load path with the
        oscillators (Eqs. 2–5) → bending (Eqs. 7–11 generalised) → hierarchy (Eq. 12)."""
        held = np.fromiter(self._pulls, dtype=np.int64)  # the objects being pulled
        F_own, c_air = self._aero_loads(U)
        F_pull = self._pull_loads(held)
        g_extra = self._base_excitation(dt)
        p_free, pd_free, gain, gain_d = self._oscillator_response(f3, z3, dt, held)
        g = self._g_prev
        slots = self._lp.inward(F_own, F_pull, held, g_extra, (p_free, gain), g)
        self._advance(g, p_free, pd_free, gain, gain_d, c_air, dt, held)
        self._L = g  # the loads read are the last step's (g is refilled in place)
        F_own, F_tip, dT, slots = self._distributed_loads(F_own, F_pull, slots, g - g_extra, dt)
        blocks, gamma = self._lp.segment_forces(F_own, F_tip, dT, self._p[1], slots)
        leaf = self._lp.leaf_seg  # leaves turn at a bounded speed, and flutter
        gamma[leaf] = self._leaf_twist.step(gamma[leaf], self._drag.leaf_speed, self._drag.leaf_incidence,
                                            self._physics.leaf_flutter, dt)
        self._bplan.bend(None, None, gamma, self._lp.k_blocks, predict=self._predict(dt), blocks=blocks)
        self._sample_prev[...] = self._sample_pos
        self._compose()
        self._sample_vel = (self._sample_pos - self._sample_prev) / max(dt, MIN_RATE_STEP)

    def _distributed_loads(self, F_own, F_pull, slots, E, dt) -> tuple[np.ndarray, ...]:
        """Stage 4 (load path): the loads along each object, low-passed at its own frequency.

        An object's oscillators filter the equivalent load at its load point (E′); how the load
        spreads along it would otherwise follow the wind and its children from step to step
        with no inertia at all, and a lamina's force, which turns with the lamina, would flip
        the twig it bends from side to side within one step. So the own loads, pulls and
        children's loads (``slots``) reach the segments through a first-order low-pass at the
        object's bending frequency, and the load point takes the rest, E′ − Ē, with Ē the
        same low-pass of the static equivalent load E (E′ the oscillators' output, advanced):
        the segments still carry E′ in all.

        Returns (own loads, load-point loads, torsion excess, slots) for
        :meth:`LoadPath.segment_forces`.
        """
        if self._spread_alpha[0] != dt:  # the filter's weight on the new loads, per step length
            a = -np.expm1(-dt * self._spread_rate)
            self._spread_alpha = (dt, np.concatenate([np.tile(a, 9), np.tile(a[self._lp.slot_owner], 6)]))
        new = np.concatenate([F_own.ravel(), F_pull.ravel(), E.ravel(), slots.ravel()])
        if self._spread is None:
            self._spread = new
        else:
            self._spread += self._spread_alpha[1] * (new - self._spread)
        M = self._M
        F_bar, P_bar, E_bar = self._spread[:9 * M].reshape(3, 3, M)
        S_bar = self._spread[9 * M:].reshape(6, -1)
        dE = self._p - E_bar  # E′ − Ē, rows of the modes u, v, w
        F_tip = P_bar.copy()
        F_tip[0] += dE[2]  # mode w bends along u, mode u along w
        F_tip[2] += dE[0]
        return F_bar, F_tip, dE[1], S_bar

    def _aero_loads(self, U) -> tuple[np.ndarray, np.ndarray]:
        """Stage 2 (load path): the drag, local, and the air's damping on each object's mode.

        The drag of the air-relative wind, F(U − v), is split as F(U) − c·v: the drag of the
        wind itself, here, and the damping c = ∂F/∂v = ρ C A |U − v| (2 × ½ρCA|U_rel|, on the
        object's mode and, through Q, on what it carries), which the oscillators take
        implicitly (:meth:`_advance`) — stable however light a twig and strong the wind.
        """
        if U is None:
            F, rel = np.zeros((3, self._M)), -self._sample_vel
        else:
            U = np.ascontiguousarray(U.T)  # (3, M): whole rows are many times faster to work on
            F = self._drag.loads(U, self._frame, np.take(self._bplan.q, self._tip_flat, axis=1))
            rel = U - self._sample_vel
        speed = np.sqrt(dot(rel, rel))
        lp = self._lp
        c_air = lp.Q_foliage * self._drag.reconfigured(speed)
        c_air += lp.Q_wood
        c_air *= 2.0 * speed
        return F, c_air

    def _pull_loads(self, held: np.ndarray) -> np.ndarray:
        """(3, M) the pulls at the objects' load points ``held``, local (carried frames)."""
        F = np.zeros((3, self._M))
        if len(held):
            world = np.array([self._pulls[i] for i in held]).T
            F[:, held] = qrot(self._frame[:, held], world, conj=True)
        return F

    def _base_excitation(self, dt: float) -> np.ndarray:
        """(3, M) oscillator inputs −m_eff·a of the moving bases (always on in the load path:
        loads go down the tree and motion comes back up, or a gust sets it ringing), with the
        effective mass m_eff = min(K/(2πf)², modal mass) of each bending mode, off over steps
        longer than :data:`MAX_SUBSTEP` (the simulation sub-steps up to a second)."""
        g = np.zeros((3, self._M))
        if dt > MAX_SUBSTEP:  # a step over a second long: off (nearly static, and unstable)
            return g
        # p̈ = ω²(g − p) − (2ζω + ω²c/K) ṗ of the bending modes (rows u, w): Eq. 2 in load
        # units, with the air's damping c of the last step (in a gale it holds a light twig
        # back far more than its own ζ does)
        acc = self._g_prev[::2] - self._p[::2]
        acc *= self._w2[::2]
        damp = self._two_zeta_w[::2] + self._air_prev
        damp *= self._pd[::2]
        acc -= damp
        a_u, a_w = self._lp.base_acceleration(acc)
        np.multiply(self._neg_m_eff[0], a_w, out=g[0])  # mode u moves along w
        np.multiply(self._neg_m_eff[1], a_u, out=g[2])
        return g

    def _oscillator_response(self, f3: np.ndarray, z3: np.ndarray, dt: float,
                             held: np.ndarray) -> tuple[np.ndarray, ...]:
        """Stage 3 (load path): the oscillators over the step (Eqs. 2–5) are linear in their
        input g: L′ = p_free + c·g, L̇′ = pd_free + c_d·g. The ``held`` objects are critically
        damped (§8). Returns (p_free, pd_free, c, c_d), each (3, M)."""

        p, pd = self._p, self._pd
        out = self._osc.response(p, pd, f3, z3, dt)
        if len(held):
            zc = np.maximum(z3[:, held], 1.0)
            zc[1] = z3[1, held]
            for arr, val in zip(out, exact_response(exact_coefficients(f3[:, held], zc, dt), p[:, held], pd[:, held])):
                arr[:, held] = val
        return out

    def _air_damping(self, c_air: np.ndarray) -> np.ndarray:
        """(3, M) the air's damping rate ω²c/K on every mode (the bending modes only: row v 0)."""
        damp = self._w2 * (c_air / self._lp.K)
        damp[1] = 0.0
        return damp

    def _advance(self, g, p_free, pd_free, gain, gain_d, c_air, dt, held) -> None:
        """Set the oscillators' state after the step under the input g, with the air's damping
        split off and implicit: ṗ /= 1 + ω²c·dt/K (stable however light a twig)."""
        np.multiply(gain, g, out=self._p)
        self._p += p_free
        np.multiply(gain_d, g, out=self._pd)
        self._pd += pd_free
        damp = self._air_damping(c_air)
        self._air_prev = damp[::2].copy()  # for the next step's base excitation
        damp[:, held] = 0.0  # a held object approaches its pull critically damped, as it is
        damp *= dt
        damp += 1.0
        self._pd /= damp
