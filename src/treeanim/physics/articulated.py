"""The whole tree as one articulated body, stepped implicitly in O(n) (docs/design.md §12).

Compiled passes along the hierarchy (numba, ``cache=True``); everything else about the tree
stepper lives in :mod:`treeanim.physics.structure` (the model) and
:mod:`treeanim.physics.treestep` (the step). Conventions:

* Every *body* is one rigid segment of a branch or a grass blade, jointed to its parent body at
  its first node by a ball joint (three rotational degrees of freedom: two bends, one twist).
  Bodies are ordered so that a parent comes before its children; a root's parent is the ground.
* All spatial quantities are in world axes about each body's own joint point: a spatial velocity
  is (ω, v) with v the velocity of the body-fixed point at the joint, a spatial force (n, f) with
  n the moment about the joint. A joint's motion subspace is then S = [1₃; 0].
* A body's rest-relative world rotation is R_b = R_parent·Q_b, with Q_b the joint's rotation in
  its parent's rest axes; its joint angular velocity w_b is kept in the same axes.
* Joint springs and dampers (K, D) and a grab's spring are integrated by the θ-method, with
  Δ the change of the joint velocities over the step:

      (M + hΘD + h²Θ²K + Jᵀ(h·C + h²θ²·K_grab)J) Δ = h·(τ − K q − (D + hΘK) q̇),
      q⁺ = q + h(q̇ + ΘΔ),

  solved by Featherstone's articulated-body algorithm: the joint terms join each joint's 3×3
  D block, the body terms its spatial inertia (as point "masses" κ at the points they act on).
  Each joint has its own Θ = θ_b(1 − aaᵀ) + θ_t·aaᵀ (:func:`theta_of`, one θ for its bends and
  one for its twist about its axis a): ½, the trapezoidal rule, for a swing the step resolves,
  toward 1 for one it cannot, so stiff stub twigs and thin twisting segments never ring. The air's damping C is
  taken by backward Euler (θ = 1): drag only ever slows a part.
* Each body's velocity-product force ν ×* Iν (gyroscopic and centrifugal) is taken linearly
  implicitly, its derivative joining the body's inertia (:func:`_add_bias`), for a whirl the
  step resolves (|ω|h ≲ 1; beyond, it fades out). That derivative is not symmetric, so the
  sweeps keep both IA·S and Sᵀ·IA. The joints' own velocity-product accelerations (a child's
  joint carried round by its parent) are left out: quadratic in the swings' angular velocities,
  small in a tree's swings.
"""

from __future__ import annotations

import numpy as np

from .compiled import njit

__all__ = ["theta_of", "articulated_step", "rot_log", "rot_exp", "add_point", "JOINT_STOP"]

#: The most a joint turns against its parent (rad): beyond it a segment stops, its outward
#: speed taken away (a soft grass blade can fold; no joint wraps past π).
JOINT_STOP = 0.6 * np.pi
#: tr Q below which a joint has turned past the stop (tr Q = 1 + 2 cos angle).
STOP_TRACE = 1.0 + 2.0 * np.cos(JOINT_STOP)


@njit(cache=True, fastmath=True, error_model="numpy")
def theta_of(x):
    """The θ-method's weight for a joint whose swing of frequency ω makes x = ωh a step.

    θ = ½ + ½·x⁴/(x⁴ + (2π)⁴): the trapezoidal rule (no numerical damping; θ − ½ < 0.03 for
    x < π) for every swing up to the step's Nyquist limit (two steps a period), ¾ at one step
    a period (x = 2π) and toward 1 (backward Euler) for swings far faster than the step, which
    then shrink by (1 − θ)/θ a step instead of ringing at the step rate. A limb's release at
    1/10 s steps (x ≈ 2–3 for its joints) thus keeps swinging as at 1/120 s, slower (the
    trapezoidal rule's frequency 2·atan(x/2)/h) but no more damped. ω is the joint's lowest
    swing with everything beyond it flexible
    (:func:`~treeanim.physics.structure._flexible_frequency`) for its bends, its own segment's
    twist for its twist.
    """
    x4 = (x * x) ** 2
    return 0.5 + 0.5 * x4 / (x4 + 1558.5454565440389)


@njit(cache=True, inline="always", fastmath=True, error_model="numpy")
def _cross(a0, a1, a2, b0, b1, b2):
    return a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0


@njit(cache=True, fastmath=True, error_model="numpy")
def rot_exp(x, y, z, out):
    """Rodrigues: ``out`` (3, 3) = exp([r]×) for the rotation vector r = (x, y, z)."""
    t2 = x * x + y * y + z * z
    if t2 < 1e-12:
        a = 1.0 - t2 / 6.0
        b = 0.5 - t2 / 24.0
    else:
        t = np.sqrt(t2)
        a = np.sin(t) / t
        b = (1.0 - np.cos(t)) / t2
    out[0, 0] = 1.0 - b * (y * y + z * z)
    out[1, 1] = 1.0 - b * (x * x + z * z)
    out[2, 2] = 1.0 - b * (x * x + y * y)
    out[0, 1] = b * x * y - a * z
    out[1, 0] = b * x * y + a * z
    out[0, 2] = b * x * z + a * y
    out[2, 0] = b * x * z - a * y
    out[1, 2] = b * y * z - a * x
    out[2, 1] = b * y * z + a * x


@njit(cache=True, fastmath=True, error_model="numpy")
def rot_log(Q, out):
    """The rotation vector ``out`` (3,) of the rotation matrix ``Q`` (3, 3) (angle < π)."""
    c = 0.5 * (Q[0, 0] + Q[1, 1] + Q[2, 2] - 1.0)
    c = min(1.0, max(-1.0, c))
    t = np.arccos(c)
    x = 0.5 * (Q[2, 1] - Q[1, 2])
    y = 0.5 * (Q[0, 2] - Q[2, 0])
    z = 0.5 * (Q[1, 0] - Q[0, 1])
    s = np.sin(t)
    f = 1.0 + t * t / 6.0 if t < 1e-4 else t / max(s, 1e-12)
    out[0] = f * x
    out[1] = f * y
    out[2] = f * z


@njit(cache=True, fastmath=True, error_model="numpy")
def _orthonormalize(Q):
    """Re-orthonormalise a rotation matrix (rows by Gram–Schmidt) against round-off drift."""
    n = np.sqrt(Q[0, 0] ** 2 + Q[0, 1] ** 2 + Q[0, 2] ** 2)
    Q[0, 0] /= n
    Q[0, 1] /= n
    Q[0, 2] /= n
    d = Q[1, 0] * Q[0, 0] + Q[1, 1] * Q[0, 1] + Q[1, 2] * Q[0, 2]
    Q[1, 0] -= d * Q[0, 0]
    Q[1, 1] -= d * Q[0, 1]
    Q[1, 2] -= d * Q[0, 2]
    n = np.sqrt(Q[1, 0] ** 2 + Q[1, 1] ** 2 + Q[1, 2] ** 2)
    Q[1, 0] /= n
    Q[1, 1] /= n
    Q[1, 2] /= n
    Q[2, 0], Q[2, 1], Q[2, 2] = _cross(Q[0, 0], Q[0, 1], Q[0, 2], Q[1, 0], Q[1, 1], Q[1, 2])


@njit(cache=True, fastmath=True, error_model="numpy")
def _inv3(A, out):
    a, b, c = A[0, 0], A[0, 1], A[0, 2]
    d, e, f = A[1, 0], A[1, 1], A[1, 2]
    g, h, i = A[2, 0], A[2, 1], A[2, 2]
    c00 = e * i - f * h
    c01 = f * g - d * i
    c02 = d * h - e * g
    det = a * c00 + b * c01 + c * c02
    r = 1.0 / det
    out[0, 0] = c00 * r
    out[1, 0] = c01 * r
    out[2, 0] = c02 * r
    out[0, 1] = (c * h - b * i) * r
    out[1, 1] = (a * i - c * g) * r
    out[2, 1] = (b * g - a * h) * r
    out[0, 2] = (b * f - c * e) * r
    out[1, 2] = (c * d - a * f) * r
    out[2, 2] = (a * e - b * d) * r


@njit(cache=True, fastmath=True, error_model="numpy", inline="always")
def _resolved(x2):
    """(1 + x⁴)⁻¹ for x² = (h·|ω|)², x the radians a whirl turns in a step: the share of it
    the step's linearisation holds for (a turn of a radian or more a step it overshoots)."""
    return 1.0 / (1.0 + x2 * x2)


@njit(cache=True, fastmath=True, error_model="numpy", inline="always")
def _whirl_theta(h, w, kick, t1, t2):
    """A joint's θ for its bends and twist this step: its swing's (:func:`theta_of`), raised
    to 1 − ½·:func:`_resolved` (½ + ½·y⁴/(y⁴ + 1)) if more, y the radians it turns in the
    step, h·|w|, or ``kick`` = h·|Δw| (its change of velocity over the last step) if more.
    A whirl of a radian or more a step (a grass blade's tip whipping in a gust's wake at
    1/30 s) leaves the step's linearisation, which then gains energy on the trapezoidal rule;
    a swing the step resolves turns far less. A swing of amplitude A changes w by about A·x²
    a step (x = ωh) against its speed A·x/h: a large kick marks a swing faster than the step
    (a grass blade's chain modes at 1/10 s, which rang at the step rate and, passing energy
    between the springs and the segments, gained up to a fifth of it every other step)."""
    y2 = max(h * h * (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]), kick * kick)
    tw = 1.0 - 0.5 * _resolved(y2)
    return max(t1, tw), max(t2, tw)


@njit(cache=True, fastmath=True, error_model="numpy")
def articulated_step(h, theta, theta_t, axis, parent, r0, m0, h0, J0, kb, kt, dkk, R, P, Q, w, kick, Om, V,
                     F, kap, IA, pA, Dinv, Ucol, Urow, u, acc):
    """One implicit step of every body (the articulated-body algorithm, three passes).

    Parameters
    ----------
    h : float
        Step length (s).
    theta, theta_t : (B,) float
        Each joint's θ (:func:`theta_of`) for its bends and its twist (the twist of a thin
        segment is far stiffer for its inertia than its bend).
    axis : (B, 3)
        Each segment's rest axis (its twist axis, in the parent's rest axes).
    parent, r0 : see :func:`~treeanim.physics.kinematics.forward_kinematics`.
    m0, h0, J0 : (B,), (B, 3), (B, 3, 3)
        Each body's mass, first and second moments about its joint in rest axes (what it carries
        rigidly — its leaves — included).
    kb, kt, dkk : (B,)
        Each joint's bending and twisting stiffness (N·m/rad) and its damping per unit of
        stiffness (s): K = k_b(1 − aaᵀ) + k_t·aaᵀ about the segment's axis a, D = dkk·K.
    R, P, Q, w : the state (see :func:`~treeanim.physics.kinematics.forward_kinematics`); Q
        and w are advanced in place, R and P are left for forward kinematics to redo.
    kick : (B,) float
        h·|Δw|, each joint's change of velocity over the last step as the radians it would turn
        in a step (:func:`_whirl_theta`); written.
    F : (B, 6)
        External spatial force on each body (moment about its joint, force), world.
    kap : (B, 6, 6)
        The implicit terms of forces linear in a point's velocity (the air, h·C) or
        displacement (a grab, h²θ²·k): Σ Pᵀ κ P over their points, P = [−[r]×, 1] the map from
        the body's spatial velocity to the point's (:func:`add_point`).
    Om, V : (B, 3)
        Each body's world angular velocity and its joint point's velocity now (the
        velocity-product forces, :func:`_add_bias`).
    IA, pA, Dinv, Ucol, Urow, u : work arrays (B, 6, 6), (B, 6), (B, 3, 3), (B, 6, 3), (B, 3, 6),
        (B, 3).
    acc : (B, 6)
        Written: each body's change of spatial velocity over the step (world, at its joint).
    """
    B = parent.shape[0]
    Rm = np.empty((3, 3))
    Jw = np.empty((3, 3))
    tmp = np.empty((3, 3))
    th = np.empty(3)
    Dj = np.empty((3, 3))
    Ia = np.empty((6, 6))
    UD = np.empty((6, 3))
    pa = np.empty(6)
    wk = np.empty((3, 3, 3))
    Ib, mom = np.empty((6, 6)), np.empty(6)
    # --- 1. each body's own inertia (plus the implicit point terms) and bias force
    for b in range(B):
        m = m0[b]
        hx = R[b, 0, 0] * h0[b, 0] + R[b, 0, 1] * h0[b, 1] + R[b, 0, 2] * h0[b, 2]
        hy = R[b, 1, 0] * h0[b, 0] + R[b, 1, 1] * h0[b, 1] + R[b, 1, 2] * h0[b, 2]
        hz = R[b, 2, 0] * h0[b, 0] + R[b, 2, 1] * h0[b, 1] + R[b, 2, 2] * h0[b, 2]
        for i in range(3):
            for j in range(3):
                s = 0.0
                for k in range(3):
                    s += R[b, i, k] * J0[b, k, j]
                tmp[i, j] = s
        for i in range(3):
            for j in range(3):
                s = 0.0
                for k in range(3):
                    s += tmp[i, k] * R[b, j, k]
                Jw[i, j] = s
        for i in range(6):
            pA[b, i] = -h * F[b, i]
        for i in range(3):
            for j in range(3):
                IA[b, i, j] = Jw[i, j] + kap[b, i, j]
                IA[b, 3 + i, 3 + j] = kap[b, 3 + i, 3 + j]
            IA[b, 3 + i, 3 + i] += m
        # upper right [h]× (+ κ's), lower left its transpose
        IA[b, 0, 3], IA[b, 0, 4], IA[b, 0, 5] = 0.0, -hz, hy
        IA[b, 1, 3], IA[b, 1, 4], IA[b, 1, 5] = hz, 0.0, -hx
        IA[b, 2, 3], IA[b, 2, 4], IA[b, 2, 5] = -hy, hx, 0.0
        for i in range(3):
            for j in range(3):
                IA[b, i, 3 + j] += kap[b, i, 3 + j]
        for i in range(3):
            for j in range(3):
                IA[b, 3 + i, j] = IA[b, j, 3 + i]
        _add_bias(h, b, kap, Om, V, IA, pA, Ib, mom)
    # --- 2. inward: articulated inertias and bias forces, the joints' terms folded in
    for b in range(B - 1, -1, -1):
        p = parent[b]
        # the joint's relative angular velocity (world) and its rotation vector (world)
        if p >= 0:
            for i in range(3):
                for j in range(3):
                    Rm[i, j] = R[p, i, j]
        else:
            for i in range(3):
                for j in range(3):
                    Rm[i, j] = 1.0 if i == j else 0.0
        rot_log(Q[b], th)
        wr0 = Rm[0, 0] * w[b, 0] + Rm[0, 1] * w[b, 1] + Rm[0, 2] * w[b, 2]
        wr1 = Rm[1, 0] * w[b, 0] + Rm[1, 1] * w[b, 1] + Rm[1, 2] * w[b, 2]
        wr2 = Rm[2, 0] * w[b, 0] + Rm[2, 1] * w[b, 1] + Rm[2, 2] * w[b, 2]
        # K = k_b(1 − aaᵀ) + k_t·aaᵀ, D = d·K and Θ = θ_b(1 − aaᵀ) + θ_t·aaᵀ share the axis
        # a (world: Rm·axis), so every product of them is α·1 + β·aaᵀ
        ax = Rm[0, 0] * axis[b, 0] + Rm[0, 1] * axis[b, 1] + Rm[0, 2] * axis[b, 2]
        ay = Rm[1, 0] * axis[b, 0] + Rm[1, 1] * axis[b, 1] + Rm[1, 2] * axis[b, 2]
        az = Rm[2, 0] * axis[b, 0] + Rm[2, 1] * axis[b, 1] + Rm[2, 2] * axis[b, 2]
        aw = (ax, ay, az)
        k1, k2, dk = kb[b], kt[b], dkk[b]
        t1, t2 = _whirl_theta(h, w[b], kick[b], theta[b], theta_t[b])
        tw0 = Rm[0, 0] * th[0] + Rm[0, 1] * th[1] + Rm[0, 2] * th[2]
        tw1 = Rm[1, 0] * th[0] + Rm[1, 1] * th[1] + Rm[1, 2] * th[2]
        tw2 = Rm[2, 0] * th[0] + Rm[2, 1] * th[1] + Rm[2, 2] * th[2]
        tw = (tw0, tw1, tw2)
        wr = (wr0, wr1, wr2)
        at = ax * tw0 + ay * tw1 + az * tw2
        aq = ax * wr0 + ay * wr1 + az * wr2
        # joint torque −K θ − (D + hΘK) ω_rel, in world (θ = Rm·log Q)
        c1 = (dk + h * t1) * k1  # (D + hΘK) = c1·1 + (c2 − c1)·aaᵀ
        c2 = (dk + h * t2) * k2
        for i in range(3):
            tau = -(k1 * tw[i] + (k2 - k1) * at * aw[i]) - (c1 * wr[i] + (c2 - c1) * aq * aw[i])
            u[b, i] = h * tau - pA[b, i]
        # D = Sᵀ IA S + hΘD + h²Θ²K
        al = h * t1 * k1 * (dk + h * t1)
        be = h * t2 * k2 * (dk + h * t2) - al
        for i in range(3):
            for j in range(3):
                Dj[i, j] = IA[b, i, j] + be * aw[i] * aw[j]
            Dj[i, i] += al
        _inv3(Dj, Dinv[b])
        for i in range(6):
            for j in range(3):
                Ucol[b, i, j] = IA[b, i, j]  # IA S
                Urow[b, j, i] = IA[b, j, i]  # Sᵀ IA (IA is not symmetric: the velocity products)
        if p < 0:
            continue
        # Ia = IA − (IA S) D⁻¹ (Sᵀ IA) ; pa = pA + (IA S) D⁻¹ u
        for i in range(6):
            for j in range(3):
                UD[i, j] = Ucol[b, i, 0] * Dinv[b, 0, j] + Ucol[b, i, 1] * Dinv[b, 1, j] + Ucol[b, i, 2] * Dinv[b, 2, j]
        for i in range(6):
            for j in range(6):
                Ia[i, j] = IA[b, i, j] - (UD[i, 0] * Urow[b, 0, j] + UD[i, 1] * Urow[b, 1, j] + UD[i, 2] * Urow[b, 2, j])
        for i in range(6):
            pa[i] = pA[b, i] + UD[i, 0] * u[b, 0] + UD[i, 1] * u[b, 1] + UD[i, 2] * u[b, 2]
        # to the parent's joint: r = P_b − P_p
        rx, ry, rz = P[b, 0] - P[p, 0], P[b, 1] - P[p, 1], P[b, 2] - P[p, 2]
        # the joint's velocity-product acceleration over the step, h·c = h·ν_b ×ₘ S·ω_rel
        # (kept in acc until the outward pass): (ω_p × ω_rel, v_b × ω_rel); pa += Ia·h·c.
        # Explicit, so weighted as _add_bias's by :func:`_resolved`, x = h·|ω|
        o0, o1, o2 = Om[p, 0], Om[p, 1], Om[p, 2]
        c0, c1, c2 = _cross(o0, o1, o2, wr0, wr1, wr2)
        c3, c4, c5 = _cross(V[b, 0], V[b, 1], V[b, 2], wr0, wr1, wr2)
        hc = h * _resolved(h * h * (o0 * o0 + o1 * o1 + o2 * o2 + wr0 * wr0 + wr1 * wr1 + wr2 * wr2))
        acc[b, 0], acc[b, 1], acc[b, 2] = hc * c0, hc * c1, hc * c2
        acc[b, 3], acc[b, 4], acc[b, 5] = hc * c3, hc * c4, hc * c5
        for i in range(6):
            pa[i] += (Ia[i, 0] * acc[b, 0] + Ia[i, 1] * acc[b, 1] + Ia[i, 2] * acc[b, 2]
                      + Ia[i, 3] * acc[b, 3] + Ia[i, 4] * acc[b, 4] + Ia[i, 5] * acc[b, 5])
        _add_translated(Ia, pa, rx, ry, rz, IA[p], pA[p], wk)
    # --- 3. outward: the joints' velocity changes and the bodies' spatial ones
    for b in range(B):
        p = parent[b]
        a0 = a1 = a2 = a3 = a4 = a5 = 0.0
        if p >= 0:
            rx, ry, rz = P[b, 0] - P[p, 0], P[b, 1] - P[p, 1], P[b, 2] - P[p, 2]
            a0, a1, a2 = acc[p, 0], acc[p, 1], acc[p, 2]
            cx, cy, cz = _cross(a0, a1, a2, rx, ry, rz)
            a3, a4, a5 = acc[p, 3] + cx + acc[b, 3], acc[p, 4] + cy + acc[b, 4], acc[p, 5] + cz + acc[b, 5]
            a0, a1, a2 = a0 + acc[b, 0], a1 + acc[b, 1], a2 + acc[b, 2]
        # Δ = D⁻¹ (u − Uᵀ a')
        r_0 = u[b, 0] - (Urow[b, 0, 0] * a0 + Urow[b, 0, 1] * a1 + Urow[b, 0, 2] * a2
                         + Urow[b, 0, 3] * a3 + Urow[b, 0, 4] * a4 + Urow[b, 0, 5] * a5)
        r_1 = u[b, 1] - (Urow[b, 1, 0] * a0 + Urow[b, 1, 1] * a1 + Urow[b, 1, 2] * a2
                         + Urow[b, 1, 3] * a3 + Urow[b, 1, 4] * a4 + Urow[b, 1, 5] * a5)
        r_2 = u[b, 2] - (Urow[b, 2, 0] * a0 + Urow[b, 2, 1] * a1 + Urow[b, 2, 2] * a2
                         + Urow[b, 2, 3] * a3 + Urow[b, 2, 4] * a4 + Urow[b, 2, 5] * a5)
        d0 = Dinv[b, 0, 0] * r_0 + Dinv[b, 0, 1] * r_1 + Dinv[b, 0, 2] * r_2
        d1 = Dinv[b, 1, 0] * r_0 + Dinv[b, 1, 1] * r_1 + Dinv[b, 1, 2] * r_2
        d2 = Dinv[b, 2, 0] * r_0 + Dinv[b, 2, 1] * r_1 + Dinv[b, 2, 2] * r_2
        acc[b, 0] = a0 + d0
        acc[b, 1] = a1 + d1
        acc[b, 2] = a2 + d2
        acc[b, 3] = a3
        acc[b, 4] = a4
        acc[b, 5] = a5
        # w⁺ = w + Rpᵀ Δ; Q⁺ = exp(h (w + θ Rpᵀ Δ)) Q
        if p >= 0:
            l0 = R[p, 0, 0] * d0 + R[p, 1, 0] * d1 + R[p, 2, 0] * d2
            l1 = R[p, 0, 1] * d0 + R[p, 1, 1] * d1 + R[p, 2, 1] * d2
            l2 = R[p, 0, 2] * d0 + R[p, 1, 2] * d1 + R[p, 2, 2] * d2
        else:
            l0, l1, l2 = d0, d1, d2
        # Θ in the parent's rest axes: θ_b + (θ_t − θ_b)·a aᵀ
        t1, t2 = _whirl_theta(h, w[b], kick[b], theta[b], theta_t[b])
        al = (axis[b, 0] * l0 + axis[b, 1] * l1 + axis[b, 2] * l2) * (t2 - t1)
        e0 = h * (w[b, 0] + t1 * l0 + al * axis[b, 0])
        e1 = h * (w[b, 1] + t1 * l1 + al * axis[b, 1])
        e2 = h * (w[b, 2] + t1 * l2 + al * axis[b, 2])
        w[b, 0] += l0
        w[b, 1] += l1
        w[b, 2] += l2
        kick[b] = h * np.sqrt(l0 * l0 + l1 * l1 + l2 * l2)
        rot_exp(e0, e1, e2, Rm)
        for i in range(3):
            for j in range(3):
                tmp[i, j] = Rm[i, 0] * Q[b, 0, j] + Rm[i, 1] * Q[b, 1, j] + Rm[i, 2] * Q[b, 2, j]
        for i in range(3):
            for j in range(3):
                Q[b, i, j] = tmp[i, j]
        _orthonormalize(Q[b])
        # a joint's stop: no segment turns against its parent by more than JOINT_STOP (wood
        # breaks first; past π the rotation vector would wrap and the spring flip)
        if Q[b, 0, 0] + Q[b, 1, 1] + Q[b, 2, 2] < STOP_TRACE:  # turned past the stop
            rot_log(Q[b], th)
            n = np.sqrt(th[0] * th[0] + th[1] * th[1] + th[2] * th[2])
            sc = JOINT_STOP / n
            rot_exp(th[0] * sc, th[1] * sc, th[2] * sc, Q[b])
            wn = (w[b, 0] * th[0] + w[b, 1] * th[1] + w[b, 2] * th[2]) / n
            if wn > 0.0:
                w[b, 0] -= wn * th[0] / n
                w[b, 1] -= wn * th[1] / n
                w[b, 2] -= wn * th[2] / n


@njit(cache=True, fastmath=True, error_model="numpy", inline="always")
def _add_skew(M, r, c, s, x, y, z):
    """M[r:r+3, c:c+3] += s·[(x, y, z)]×."""
    M[r, c + 1] -= s * z
    M[r, c + 2] += s * y
    M[r + 1, c] += s * z
    M[r + 1, c + 2] -= s * x
    M[r + 2, c] -= s * y
    M[r + 2, c + 1] += s * x


@njit(cache=True, fastmath=True, error_model="numpy", inline="always")
def _add_cross(M, r, c, s, x, y, z, A, ra, ca):
    """M[r:r+3, c:c+3] += s·[(x, y, z)]×·A[ra:ra+3, ca:ca+3], column by column."""
    for j in range(3):
        a0, a1, a2 = A[ra, ca + j], A[ra + 1, ca + j], A[ra + 2, ca + j]
        M[r, c + j] += s * (y * a2 - z * a1)
        M[r + 1, c + j] += s * (z * a0 - x * a2)
        M[r + 2, c + j] += s * (x * a1 - y * a0)


@njit(cache=True, fastmath=True, error_model="numpy")
def _add_bias(h, b, kap, Om, V, IA, pA, Ib, mom):
    """The body's velocity-product force f = ν ×* Iν (gyroscopic and centrifugal: ν = (ω, v)
    its spatial velocity, I its spatial inertia about its joint, IA[b] − κ[b] here) taken
    linearly implicitly: pA += h·f and IA += h·∂f/∂ν, ∂f/∂ν = crf(ν)·I + [[−[n]×, −[p]×],
    [−[p]×, 0]] with (n, p) = Iν: a twig whirling on its joint keeps its angular momentum, not
    its angular velocity (docs/design.md §12)."""
    wx, wy, wz = Om[b, 0], Om[b, 1], Om[b, 2]
    vx, vy, vz = V[b, 0], V[b, 1], V[b, 2]
    nu = (wx, wy, wz, vx, vy, vz)
    mom[:] = 0.0  # Iν = (n, p)
    for i in range(6):
        for j in range(6):
            Ib[i, j] = IA[b, i, j] - kap[b, i, j]
            mom[i] += Ib[i, j] * nu[j]
    # weighted by (1 + x⁴)⁻¹, x = h·|ν| in radians (|v| over the body's gyration length
    # ℓ² = tr J/m): a turn or a sweep of a radian or more a step the linearisation overshoots
    x2 = wx * wx + wy * wy + wz * wz
    tr = Ib[0, 0] + Ib[1, 1] + Ib[2, 2]
    if tr > 0.0:  # (a body whose inertia underflows has no sweep to speak of)
        x2 += (vx * vx + vy * vy + vz * vz) * Ib[3, 3] / tr
    h *= _resolved(x2 * h * h)
    n0, n1, n2, p0, p1, p2 = mom[0], mom[1], mom[2], mom[3], mom[4], mom[5]
    a = _cross(wx, wy, wz, n0, n1, n2)
    c = _cross(vx, vy, vz, p0, p1, p2)
    d = _cross(wx, wy, wz, p0, p1, p2)
    for i in range(3):
        pA[b, i] += h * (a[i] + c[i])
        pA[b, 3 + i] += h * d[i]
    # crf(ν)·I, crf(ν) = [[ω×, v×], [0, ω×]], block by block
    for col in (0, 3):
        _add_cross(IA[b], 0, col, h, wx, wy, wz, Ib, 0, col)
        _add_cross(IA[b], 0, col, h, vx, vy, vz, Ib, 3, col)
        _add_cross(IA[b], 3, col, h, wx, wy, wz, Ib, 3, col)
    _add_skew(IA[b], 0, 0, -h, n0, n1, n2)
    _add_skew(IA[b], 0, 3, -h, p0, p1, p2)
    _add_skew(IA[b], 3, 0, -h, p0, p1, p2)


@njit(cache=True, fastmath=True, error_model="numpy")
def add_point(kap, b, alpha, b1, e1x, e1y, e1z, b2, e2x, e2y, e2z, rx, ry, rz):
    """kap[b] += Pᵀ C P for C = α·1 + β₁·e₁e₁ᵀ + β₂·e₂e₂ᵀ acting at the point r (world, from
    b's joint). Scalars only: it runs for every segment and leaf each step."""
    c00 = alpha + b1 * e1x * e1x + b2 * e2x * e2x
    c11 = alpha + b1 * e1y * e1y + b2 * e2y * e2y
    c22 = alpha + b1 * e1z * e1z + b2 * e2z * e2z
    c01 = b1 * e1x * e1y + b2 * e2x * e2y
    c02 = b1 * e1x * e1z + b2 * e2x * e2z
    c12 = b1 * e1y * e1z + b2 * e2y * e2z
    # M = C [r]×
    m00, m01, m02 = c01 * rz - c02 * ry, c02 * rx - c00 * rz, c00 * ry - c01 * rx
    m10, m11, m12 = c11 * rz - c12 * ry, c12 * rx - c01 * rz, c01 * ry - c11 * rx
    m20, m21, m22 = c12 * rz - c22 * ry, c22 * rx - c02 * rz, c02 * ry - c12 * rx
    # upper left −[r]× M (symmetric: [r]×ᵀ C [r]×), upper right −Mᵀ, lower left −M, lower right C
    kap[b, 0, 0] -= ry * m20 - rz * m10
    kap[b, 0, 1] -= ry * m21 - rz * m11
    kap[b, 0, 2] -= ry * m22 - rz * m12
    kap[b, 1, 0] -= rz * m00 - rx * m20
    kap[b, 1, 1] -= rz * m01 - rx * m21
    kap[b, 1, 2] -= rz * m02 - rx * m22
    kap[b, 2, 0] -= rx * m10 - ry * m00
    kap[b, 2, 1] -= rx * m11 - ry * m01
    kap[b, 2, 2] -= rx * m12 - ry * m02
    kap[b, 0, 3] -= m00
    kap[b, 0, 4] -= m10
    kap[b, 0, 5] -= m20
    kap[b, 1, 3] -= m01
    kap[b, 1, 4] -= m11
    kap[b, 1, 5] -= m21
    kap[b, 2, 3] -= m02
    kap[b, 2, 4] -= m12
    kap[b, 2, 5] -= m22
    kap[b, 3, 0] -= m00
    kap[b, 3, 1] -= m01
    kap[b, 3, 2] -= m02
    kap[b, 4, 0] -= m10
    kap[b, 4, 1] -= m11
    kap[b, 4, 2] -= m12
    kap[b, 5, 0] -= m20
    kap[b, 5, 1] -= m21
    kap[b, 5, 2] -= m22
    kap[b, 3, 3] += c00
    kap[b, 3, 4] += c01
    kap[b, 3, 5] += c02
    kap[b, 4, 3] += c01
    kap[b, 4, 4] += c11
    kap[b, 4, 5] += c12
    kap[b, 5, 3] += c02
    kap[b, 5, 4] += c12
    kap[b, 5, 5] += c22


@njit(cache=True, fastmath=True, error_model="numpy")
def _add_translated(Ia, pa, rx, ry, rz, IAp, pAp, wk):
    """IAp += Xᵀ Ia X and pAp += Xᵀ pa for the translation r from the parent's joint to the
    child's (X: motion at the parent's joint → at the child's)."""
    # blocks of Ia: A (0:3, 0:3), Bm (0:3, 3:6), C (3:6, 0:3), Dm (3:6, 3:6)
    # A' = A − Bm[r] + [r]C − [r]Dm[r] ; Bm' = Bm + [r]Dm ; Dm' = Dm
    rc, rD, Bn = wk[0], wk[1], wk[2]
    rc[0, 0], rc[0, 1], rc[0, 2] = 0.0, -rz, ry
    rc[1, 0], rc[1, 1], rc[1, 2] = rz, 0.0, -rx
    rc[2, 0], rc[2, 1], rc[2, 2] = -ry, rx, 0.0
    # rD = [r] Dm
    for i in range(3):
        for j in range(3):
            rD[i, j] = rc[i, 0] * Ia[3, 3 + j] + rc[i, 1] * Ia[4, 3 + j] + rc[i, 2] * Ia[5, 3 + j]
    for i in range(3):
        for j in range(3):
            Bn[i, j] = Ia[i, 3 + j] + rD[i, j]
    # A' = A − Bm[r] + [r](C − Dm[r]) = A − Bm[r] + [r]C − rD[r]
    for i in range(3):
        for j in range(3):
            s = Ia[i, j]
            for k in range(3):
                s += -Ia[i, 3 + k] * rc[k, j] + rc[i, k] * Ia[3 + k, j] - rD[i, k] * rc[k, j]
            IAp[i, j] += s
    # C' = C − Dm[r] (Bm'ᵀ where Ia is symmetric)
    for i in range(3):
        for j in range(3):
            IAp[i, 3 + j] += Bn[i, j]
            IAp[3 + i, j] += Ia[3 + i, j] - (Ia[3 + i, 3] * rc[0, j] + Ia[3 + i, 4] * rc[1, j] + Ia[3 + i, 5] * rc[2, j])
            IAp[3 + i, 3 + j] += Ia[3 + i, 3 + j]
    c = _cross(rx, ry, rz, pa[3], pa[4], pa[5])
    pAp[0] += pa[0] + c[0]
    pAp[1] += pa[1] + c[1]
    pAp[2] += pa[2] + c[2]
    pAp[3] += pa[3]
    pAp[4] += pa[4]
    pAp[5] += pa[5]
