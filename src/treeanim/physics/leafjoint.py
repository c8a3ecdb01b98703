"""The leaves' petiole joints on top of the articulated tree (docs/design.md §12), and the
pose of every node: compiled passes (numba, ``cache=True``)."""

from __future__ import annotations

import numpy as np

from .articulated import _cross
from .compiled import njit

__all__ = ["leaf_step", "pose_nodes", "MAX_TURN", "PETIOLE_STOP", "FLUTTER_STROUHAL"]

#: The most a leaf turns about one of its axes in one step (rad). The step takes the air's
#: pull on a turning lamina linearised; in a gale a leaf settles in the flow within 10–20 ms
#: (its lever over |U|), so a longer step's linear turn would overshoot the flow and flip the
#: leaf from side to side. Capping the turn (and the speed with it: energy is only taken
#: away) keeps each step where the linearisation holds.
MAX_TURN = 0.4
#: The most a petiole bends (rad): past a right angle, so a leaf whose petiole points upwind
#: trails downwind of it in a gale instead of being held face-on to the flow.
PETIOLE_STOP = 0.9 * np.pi

#: f·ℓ/U of a lamina's flutter about its midrib (leaves of 5–15 cm flutter at several hertz in
#: a 10 m/s wind).
FLUTTER_STROUHAL = 0.05
#: The flutter's highest frequency (Hz).
MAX_FLUTTER_HZ = 12.0
#: The wind speed (m/s) at which the flutter reaches half its amplitude (U²/(U² + U_f²)).
FLUTTER_SPEED = 4.0


@njit(cache=True, fastmath=True, error_model="numpy", inline="always")
def _leaf_theta(x2):
    """A petiole joint's θ for x² = (ωh)²: ½ + ½·x⁴/(x⁴ + 10⁴), the trapezoidal rule up to a
    few steps a period (a leaf's turns stay visible at 30 frames a second, at a turn per frame
    proportional to the frame's length), toward backward Euler for swings ten times faster.
    Defined here, not shared with the joints' (``articulated.theta_of``): numba's cache does
    not see a change in another module's inlined function."""
    x4 = x2 * x2
    return 0.5 + 0.5 * x4 / (x4 + 1.0e4)


@njit(cache=True, fastmath=True, error_model="numpy", inline="always")
def _quat_matrix(qw, qx, qy, qz, G):
    """G (3, 3): the rotation of the unit quaternion (qw, qx, qy, qz)."""
    G[0, 0] = 1.0 - 2.0 * (qy * qy + qz * qz)
    G[1, 1] = 1.0 - 2.0 * (qx * qx + qz * qz)
    G[2, 2] = 1.0 - 2.0 * (qx * qx + qy * qy)
    G[0, 1] = 2.0 * (qx * qy - qw * qz)
    G[1, 0] = 2.0 * (qx * qy + qw * qz)
    G[0, 2] = 2.0 * (qx * qz + qw * qy)
    G[2, 0] = 2.0 * (qx * qz - qw * qy)
    G[1, 2] = 2.0 * (qy * qz - qw * qx)
    G[2, 1] = 2.0 * (qy * qz + qw * qx)


@njit(cache=True, fastmath=True, error_model="numpy")
def _leaf_rotation(E, th, G):
    """G (3, 3) = exp([θ₁b₁ + θ₂b₂]×)·exp(θ₀[a]×), the leaf against its twig (E: columns a, b₁, b₂),
    composed as quaternions."""
    ax, ay, az = E[0, 0], E[1, 0], E[2, 0]
    vx = E[0, 1] * th[1] + E[0, 2] * th[2]
    vy = E[1, 1] * th[1] + E[1, 2] * th[2]
    vz = E[2, 1] * th[1] + E[2, 2] * th[2]
    beta = np.sqrt(vx * vx + vy * vy + vz * vz)
    cb, ct, st = np.cos(0.5 * beta), np.cos(0.5 * th[0]), np.sin(0.5 * th[0])
    sb = np.sin(0.5 * beta) / beta if beta > 1e-12 else 0.5  # times the unnormalised axis v
    qw = cb * ct - sb * st * (vx * ax + vy * ay + vz * az)
    cx, cy, cz = _cross(vx, vy, vz, ax, ay, az)
    qx = cb * st * ax + ct * sb * vx + sb * st * cx
    qy = cb * st * ay + ct * sb * vy + sb * st * cy
    qz = cb * st * az + ct * sb * vz + sb * st * cz
    _quat_matrix(qw, qx, qy, qz, G)


@njit(cache=True, fastmath=True, error_model="numpy")
def leaf_step(h, on, body, base0, rc0, n0, E, k, J, dstr, cna, cswing, roll2, cauchy, size, R, P, Om, V, U,
              amp, phase, flutter, th, thd, F, X, Nrm, kap, Uh, kap2, speed):
    """Advance every leaf's petiole joint (bend about two axes and twist) over one step, and
    give the force it passes to its twig for the next.

    A leaf is a lamina on a petiole, its rotation against its twig exp(E·θ) (θ in the leaf's
    own axes E = [a, b₁, b₂], a along the lever from the petiole's base to the lamina's
    centroid: θ_a twists it, θ_b bends it). Its inertia is small next to its twig's and rides
    on it rigidly in the articulated step; here it turns on top, driven by the normal force
    ½ρC_nA|U_rel|(U_rel·n)n on the lamina and the twig's acceleration, held by its petiole's
    spring and damped by the petiole and the air, by the same θ-method per axis.

    The lamina's inertia rides its twig rigidly, so the twig's acceleration is not passed to
    it (that would feed the leaf energy its twig never gives up): a leaf moves by the air
    relative to it, its twig's motion included — for a leaf, whose drag outweighs its
    inertia many times, the larger part. The air against the lamina's own swing damps it at
    c·|U_rel|·r² (c = ½ρC_nA of a flat plate unfolded, r its lever), at least the rate of the
    normal force's own swing term, so in calm air the leaf and its twig together only ever
    lose energy.

    Parameters
    ----------
    on : (L,) bool — leaves on the tree; body : (L,) int — the twig body each sits on.
    base0, rc0, n0 : (L, 3) — rest offset of the petiole's base from its twig's joint, of the
        lamina's centroid from the petiole's base, the lamina's rest normal.
    E : (L, 3, 3) — the leaf's axes (columns a, b₁, b₂) in rest axes.
    k, J, dstr : (L, 3) — stiffness, inertia and structural damping per axis.
    cna : (L,) — ½ρC_nA of the lamina in the wind (``physics.drag_leaf``).
    cswing : (L,) — ½ρC_nA of the lamina against its own swing (a plate's coefficient).
    roll2 : (L,) — the lamina's mean squared distance from its axis (its width²/12).
    cauchy : (L,) — the lamina's scaled Cauchy number C* per (m/s)²: in the flow it folds and
        rolls, its normal force falls by R = (1 + C*|U_rel|²)^(−1/3) (Gosselin et al. 2010:
        a flexible plate's drag grows as U^(4/3) once C* ≫ 1, Vogel's exponent −2/3).
    size : (L,) — the lamina's length (m).
    R, P, Om, V : the twigs' new kinematics.
    U : (B, 3) — the wind at each twig body (m/s); a leaf takes its twig's.
    amp : float — the largest flutter angle (rad), reached edge-on in a strong wind.
    phase, flutter : (L,) — the flutter's phase (rad) and amplitude (rad), advanced in place:
        a frequency St·|U|/ℓ (:data:`FLUTTER_STROUHAL`; at most :data:`MAX_FLUTTER_HZ` and a
        quarter of the step rate), an amplitude ``amp``·U²/(U² + :data:`FLUTTER_SPEED`²). The
        flutter's twist, flutter·sin(phase), drives the twist through its torque k_t·flutter.
    th, thd : (L, 3) — the state, advanced in place.
    F : (L, 3) — written: the lamina's force (world, N) at X.
    X : (L, 3) — written: the lamina's centroid (world) relative to its twig's joint.
    Nrm : (L, 3) — written: the lamina's normal (world).
    kap, Uh, kap2 : (L,), (L, 3), (L,) — written: the air's damping there, the force's
        derivative against the velocity bounded by a symmetric one,
        ½ρC_n·A·(|U_rel| n nᵀ + |U_rel·n| ÛÛᵀ) (N·s/m; the next step takes it implicitly).
    speed : (L,) — written: |U_rel| at the lamina.
    """
    G = np.empty((3, 3))
    RG = np.empty((3, 3))
    f_max = min(MAX_FLUTTER_HZ, 0.25 / h)
    for l in range(body.shape[0]):
        b = body[l]
        # the flutter: its phase and amplitude in the wind at the twig
        u2 = U[b, 0] * U[b, 0] + U[b, 1] * U[b, 1] + U[b, 2] * U[b, 2]
        f = min(FLUTTER_STROUHAL * np.sqrt(u2) / max(size[l], 1e-3), f_max)
        phase[l] = (phase[l] + 2.0 * np.pi * f * h) % (2.0 * np.pi)
        if not on[l]:
            flutter[l] = 0.0
            F[l, 0] = F[l, 1] = F[l, 2] = 0.0
            kap[l] = 0.0
            continue
        flutter[l] = amp * u2 / (u2 + FLUTTER_SPEED * FLUTTER_SPEED)
        twist = flutter[l] * np.sin(phase[l])
        _leaf_rotation(E[l], th[l], G)
        for i in range(3):
            for j in range(3):
                RG[i, j] = R[b, i, 0] * G[0, j] + R[b, i, 1] * G[1, j] + R[b, i, 2] * G[2, j]
        bx = R[b, 0, 0] * base0[l, 0] + R[b, 0, 1] * base0[l, 1] + R[b, 0, 2] * base0[l, 2]
        by = R[b, 1, 0] * base0[l, 0] + R[b, 1, 1] * base0[l, 1] + R[b, 1, 2] * base0[l, 2]
        bz = R[b, 2, 0] * base0[l, 0] + R[b, 2, 1] * base0[l, 1] + R[b, 2, 2] * base0[l, 2]
        cx = RG[0, 0] * rc0[l, 0] + RG[0, 1] * rc0[l, 1] + RG[0, 2] * rc0[l, 2]
        cy = RG[1, 0] * rc0[l, 0] + RG[1, 1] * rc0[l, 1] + RG[1, 2] * rc0[l, 2]
        cz = RG[2, 0] * rc0[l, 0] + RG[2, 1] * rc0[l, 1] + RG[2, 2] * rc0[l, 2]
        nx = RG[0, 0] * n0[l, 0] + RG[0, 1] * n0[l, 1] + RG[0, 2] * n0[l, 2]
        ny = RG[1, 0] * n0[l, 0] + RG[1, 1] * n0[l, 1] + RG[1, 2] * n0[l, 2]
        nz = RG[2, 0] * n0[l, 0] + RG[2, 1] * n0[l, 1] + RG[2, 2] * n0[l, 2]
        xx, xy, xz = bx + cx, by + cy, bz + cz  # the centroid from the twig's joint
        X[l, 0], X[l, 1], X[l, 2] = xx, xy, xz
        # the twig's velocity and acceleration there
        o = _cross(Om[b, 0], Om[b, 1], Om[b, 2], xx, xy, xz)
        ux, uy, uz = U[b, 0] - V[b, 0] - o[0], U[b, 1] - V[b, 1] - o[1], U[b, 2] - V[b, 2] - o[2]
        s = np.sqrt(ux * ux + uy * uy + uz * uz)
        un = ux * nx + uy * ny + uz * nz
        c = cna[l] / np.cbrt(1.0 + cauchy[l] * s * s)  # the folded lamina's
        fn = c * s * un
        fx, fy, fz = fn * nx, fn * ny, fn * nz
        F[l, 0], F[l, 1], F[l, 2] = fx, fy, fz
        Nrm[l, 0], Nrm[l, 1], Nrm[l, 2] = nx, ny, nz
        kap[l] = c * s
        if s > 0.0:
            Uh[l, 0], Uh[l, 1], Uh[l, 2] = ux / s, uy / s, uz / s
        else:
            Uh[l, 0] = Uh[l, 1] = Uh[l, 2] = 0.0
        kap2[l] = c * abs(un)
        speed[l] = s
        # torque about the petiole's base: the bends take its part about the rest axes b₁, b₂
        # (in the twig's axes, Rᵀτ), the twist its part about the lamina's axis now (Ga): nil
        # for a force at the centroid, which lies on that axis; the flutter drives it instead
        t = _cross(cx, cy, cz, fx, fy, fz)
        tl0 = R[b, 0, 0] * t[0] + R[b, 1, 0] * t[1] + R[b, 2, 0] * t[2]
        tl1 = R[b, 0, 1] * t[0] + R[b, 1, 1] * t[1] + R[b, 2, 1] * t[2]
        tl2 = R[b, 0, 2] * t[0] + R[b, 1, 2] * t[1] + R[b, 2, 2] * t[2]
        lever2 = rc0[l, 0] ** 2 + rc0[l, 1] ** 2 + rc0[l, 2] ** 2
        dair = max(cswing[l], c) * s * lever2  # the air against the lamina's own swing
        for i in range(3):
            kk = k[l, i]
            ka = 0.0
            if i == 0:  # the lamina rolling about its axis: its halves swing through the air
                tau = kk * twist
                d = dstr[l, i] + cswing[l] * s * roll2[l]
            else:
                tau = E[l, 0, i] * tl0 + E[l, 1, i] * tl1 + E[l, 2, i] * tl2
                d = dstr[l, i] + dair
                # the air's stiffness against a turn about this axis e (world), taken implicitly
                # where it restores (a lamina weathervaning into the flow): −e·∂τ/∂θ with
                # ∂r = e × r, ∂n = e × n
                ex = R[b, 0, 0] * E[l, 0, i] + R[b, 0, 1] * E[l, 1, i] + R[b, 0, 2] * E[l, 2, i]
                ey = R[b, 1, 0] * E[l, 0, i] + R[b, 1, 1] * E[l, 1, i] + R[b, 1, 2] * E[l, 2, i]
                ez = R[b, 2, 0] * E[l, 0, i] + R[b, 2, 1] * E[l, 1, i] + R[b, 2, 2] * E[l, 2, i]
                dr = _cross(ex, ey, ez, cx, cy, cz)
                dn = _cross(ex, ey, ez, nx, ny, nz)
                udn = ux * dn[0] + uy * dn[1] + uz * dn[2]
                g0 = c * s * (udn * nx + un * dn[0])
                g1 = c * s * (udn * ny + un * dn[1])
                g2 = c * s * (udn * nz + un * dn[2])
                t1 = _cross(dr[0], dr[1], dr[2], fx, fy, fz)
                t2 = _cross(cx, cy, cz, g0, g1, g2)
                ka = max(0.0, -(ex * (t1[0] + t2[0]) + ey * (t1[1] + t2[1]) + ez * (t1[2] + t2[2])))
            kt = kk + ka
            tl = _leaf_theta(h * h * kt / J[l, i])
            hth = h * tl
            num = h * (tau - kk * th[l, i] - (d + hth * kt) * thd[l, i])
            dd = num / (J[l, i] + hth * d + hth * hth * kt)
            turn = h * (thd[l, i] + tl * dd)
            v = thd[l, i] + dd
            if abs(turn) > MAX_TURN:
                v *= MAX_TURN / abs(turn)
                turn = MAX_TURN if turn > 0.0 else -MAX_TURN
            th[l, i] += turn
            thd[l, i] = v
        # a petiole's stop
        bend = np.sqrt(th[l, 1] ** 2 + th[l, 2] ** 2)
        if bend > PETIOLE_STOP:
            sc = PETIOLE_STOP / bend
            th[l, 1] *= sc
            th[l, 2] *= sc
            thd[l, 1] *= sc
            thd[l, 2] *= sc


@njit(cache=True, fastmath=True, error_model="numpy")
def pose_nodes(bodies, leaves, body_node, body_tip, body_tip_node, Xrest, R, P, leaf_nodes, leaf_first, leaf_body,
               leaf_E, leaf_th, leaf_on, pos, rot):
    """Posed node positions ``pos`` (N, 3) and rest-relative rotations ``rot`` (N, 3, 3) of
    the ``bodies`` and ``leaves`` (indices; the others' nodes are left as they are).

    Bodies: the node at each joint takes the body's rotation and position; an object's tip
    node the last body's rotation and its end. Leaves: the petiole's k segments curl evenly,
    segment i turning by (i + 1)/k of the leaf's bend and twist against its twig; its tip
    node (the lamina) the whole turn.
    """
    G = np.empty((3, 3))
    for b in bodies:
        j = body_node[b]
        for i in range(3):
            pos[j, i] = P[b, i]
            for c in range(3):
                rot[j, i, c] = R[b, i, c]
        if body_tip[b]:
            t = body_tip_node[b]
            for i in range(3):
                s = P[b, i]
                for c in range(3):
                    s += R[b, i, c] * (Xrest[t, c] - Xrest[j, c])
                    rot[t, i, c] = R[b, i, c]
                pos[t, i] = s
    for l in leaves:
        b = leaf_body[l]
        a = leaf_first[l]
        e = leaf_first[l + 1]
        k = e - a - 1
        jb = body_node[b]
        # the petiole's base on its twig
        for i in range(3):
            s = P[b, i]
            for c in range(3):
                s += R[b, i, c] * (Xrest[leaf_nodes[a], c] - Xrest[jb, c])
            pos[leaf_nodes[a], i] = s
        # segment q turns by G_q = B^((q+1)/k)·T^((q+1)/k), the bend B and twist T each about
        # one axis: as quaternions whose half angles grow by one k-th a segment (angle addition)
        on = 1.0 if leaf_on[l] else 0.0
        ax, ay, az = leaf_E[l, 0, 0], leaf_E[l, 1, 0], leaf_E[l, 2, 0]
        vx = on * (leaf_E[l, 0, 1] * leaf_th[l, 1] + leaf_E[l, 0, 2] * leaf_th[l, 2])
        vy = on * (leaf_E[l, 1, 1] * leaf_th[l, 1] + leaf_E[l, 1, 2] * leaf_th[l, 2])
        vz = on * (leaf_E[l, 2, 1] * leaf_th[l, 1] + leaf_E[l, 2, 2] * leaf_th[l, 2])
        beta = np.sqrt(vx * vx + vy * vy + vz * vz)
        if beta > 1e-12:
            bx, by, bz = vx / beta, vy / beta, vz / beta
        else:
            bx, by, bz = 1.0, 0.0, 0.0
        cb1, sb1 = np.cos(0.5 * beta / k), np.sin(0.5 * beta / k)
        psi = on * leaf_th[l, 0]
        ct1, st1 = np.cos(0.5 * psi / k), np.sin(0.5 * psi / k)
        cb, sb, ct, st = cb1, sb1, ct1, st1
        ba = bx * ax + by * ay + bz * az
        cx_, cy_, cz_ = _cross(bx, by, bz, ax, ay, az)
        for q in range(k):
            if q > 0:
                cb, sb = cb * cb1 - sb * sb1, sb * cb1 + cb * sb1
                ct, st = ct * ct1 - st * st1, st * ct1 + ct * st1
            qw = cb * ct - sb * st * ba
            qx = cb * st * ax + ct * sb * bx + sb * st * cx_
            qy = cb * st * ay + ct * sb * by + sb * st * cy_
            qz = cb * st * az + ct * sb * bz + sb * st * cz_
            _quat_matrix(qw, qx, qy, qz, G)
            n0 = leaf_nodes[a + q]
            n1 = leaf_nodes[a + q + 1]
            for i in range(3):
                for c in range(3):
                    rot[n0, i, c] = R[b, i, 0] * G[0, c] + R[b, i, 1] * G[1, c] + R[b, i, 2] * G[2, c]
            for i in range(3):
                s = pos[n0, i]
                for c in range(3):
                    s += rot[n0, i, c] * (Xrest[n1, c] - Xrest[n0, c])
                pos[n1, i] = s
            if q == k - 1:
                for i in range(3):
                    for c in range(3):
                        rot[n1, i, c] = rot[n0, i, c]
