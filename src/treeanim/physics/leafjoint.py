"""The leaves' petiole joints on top of the articulated tree (docs/design.md §12), and the
pose of every node: compiled passes (numba, ``cache=True``)."""

from __future__ import annotations

import numpy as np

from .articulated import _cross
from .compiled import njit
from .scalar import SERIES_MAX, inv_cbrt, sin_turn, sinc_cos, sinc_cos_series, sincos

__all__ = ["leaf_step", "pose_nodes", "MAX_TURN", "PETIOLE_STOP", "FLUTTER_STROUHAL"]

#: The most a petiole bends about either axis in one step (rad): a guard. The step takes the
#: air's moment on the lamina linearised about the step's start (its slope near the flow, its
#: chord to where the lamina lets go far from it, :func:`_release_turn`), exact at both ends
#: along the axis but not across the axes nor as the lamina's own speed changes the air on
#: it; a turn this large leaves that model. Where the chord is taken the guard is the turn to
#: the air's balance if that is farther (the chord is exact as far as it): in a 30 m/s wind
#: at 1/10 s, where the wind at a twig changes by up to 10 m/s and 25° from step to step, a
#: fixed guard bound 5.0 % of the large cherry's leaf steps and turned 0.14 % by it one way
#: and the next the other; following the balance, 0.07 % reach this and none flips. The
#: twist, linear (driven by the flutter, damped by the air against the lamina's roll), has
#: no such limit.
MAX_TURN = 0.4
#: A bend whose Newton step (τ − kθ)/(k + k_air) would pass this (rad) takes the air's chord
#: stiffness (:func:`_release_turn`); below it the local slope is within a few per cent of it.
SECANT_TURN = 0.3
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
def _axis_step(h, J, K, d, f0, f1, g, th, om):
    """One step of J·θ̈ + d·θ̇ + K·θ = f0 + f1·t/h + g/h from (θ, θ̇) = (th, om): (θ, θ̇) after it
    (g: a constant force's impulse over the step, given as such so that no step divides by h).

    The 2-stage Radau IIA method, in closed form. On this linear system it is the exact flow
    with exp(Z) taken as its (1, 2) Padé approximant R(Z) = (1 − ⅔Z + Z²/6)⁻¹(1 + Z/3)
    (Z = h·A, A the system's matrix): third order, exact for the forcing's ramp, A-stable (the
    energy ½(Kθ² + Jθ̇²) never grows unforced, any h) and L-stable (a swing far faster than
    the step settles in it, as backward Euler's, and never rings at the step rate, as the
    trapezoidal rule's overdamped modes do). With a = Kh/J, q = dh/J, φ = hf/J:
    x⁺ = D⁻¹[N·x + (1 − Z/6)φ₀e₂ + (½ − Z/6)φ₁e₂], N = 1 + Z/3, D = 1 − ⅔Z + Z²/6,
    Z = [[0, h], [−a, −q]] (no division by h: a step of 10⁻³²⁰ s is a step).
    """
    hJ = h / J
    a, q = K * hJ, d * hJ
    ph0, ph1 = hJ * f0 + g / J, hJ * f1
    y0 = th + h * (om / 3.0 - (ph0 + ph1) / 6.0)
    y1 = om - (a * th + q * om) / 3.0 + ph0 * (1.0 + q / 6.0) + ph1 * (0.5 + q / 6.0)
    p = a * h
    d00, d01 = 1.0 - p / 6.0, -h * (2.0 / 3.0 + q / 6.0)
    d10, d11 = a * (2.0 / 3.0 + q / 6.0), 1.0 + 2.0 * q / 3.0 + (q * q - p) / 6.0
    r = 1.0 / (1.0 + q * (2.0 / 3.0 + q / 6.0) + p * ((1.0 + q) / 9.0 + p / 36.0))  # det D, a sum of positives
    return (d11 * y0 - d01 * y1) * r, (d00 * y1 - d10 * y0) * r


@njit(cache=True, fastmath=True, error_model="numpy")
def _release_turn(tau, alpha, beta, gamma):
    """The turn δ* to where the air lets a lamina's bend far from the flow go (∞ where it
    never does): the air's chord stiffness against the bend is its moment τ(0)/δ*.

    Turning the lamina by δ about an axis e carries its normal and its lever alike, so the
    moment about e is τ(δ) = c|U|(e·p)·(α + β cos δ + γ sin δ), α = (e·U)(e·n), β = U·n − α,
    γ = e·(n × U): a sinusoid. δ* is its first zero in the direction τ(0) turns the lamina,
    where it comes to rest edge-on (stable: the moment turns back beyond). The local slope
    −τ′(0) (Newton's step) always lands beyond δ*, from 67° off the flow on farther beyond
    it than it started, and flipped laminas from side to side; the chord τ(0)/δ* is exact at
    both ends, so a step long against the lamina's settling lands on δ*, a shorter one short
    of it.
    """
    sg = 1.0 if tau > 0.0 else -1.0
    rho = np.sqrt(beta * beta + gamma * gamma)
    if rho <= abs(alpha):
        return np.inf
    # α + β cos t + σγ sin t = α + ρ cos(t − ψ) = 0 for the smallest t > 0
    psi = np.arctan2(sg * gamma, beta)
    a = np.arccos(-alpha / rho)
    t = 4.0 * np.pi
    for cand in (psi + a, psi - a):
        cand = cand % (2.0 * np.pi)
        if cand <= 1e-12:
            cand += 2.0 * np.pi
        t = min(t, cand)
    return abs(tau) / t


@njit(cache=True, fastmath=True, error_model="numpy", inline="always")
def _quat_rotation(qw, qx, qy, qz):
    """The rotation of the unit quaternion (qw, qx, qy, qz): its nine terms, row by row."""
    return (1.0 - 2.0 * (qy * qy + qz * qz), 2.0 * (qx * qy - qw * qz), 2.0 * (qx * qz + qw * qy),
            2.0 * (qx * qy + qw * qz), 1.0 - 2.0 * (qx * qx + qz * qz), 2.0 * (qy * qz - qw * qx),
            2.0 * (qx * qz - qw * qy), 2.0 * (qy * qz + qw * qx), 1.0 - 2.0 * (qx * qx + qy * qy))


@njit(cache=True, fastmath=True, error_model="numpy", inline="always")
def _leaf_rotation(ax, ay, az, vx, vy, vz, sb, cb, st, ct):
    """exp([v]×)·exp(θ₀[a]×), the leaf against its twig (v = θ₁b₁ + θ₂b₂, β = |v|; E's columns
    a, b₁, b₂), composed as quaternions from sb = sin(β/2)/β, cb = cos(β/2), st = sin(θ₀/2),
    ct = cos(θ₀/2): its nine terms, row by row."""
    qw = cb * ct - sb * st * (vx * ax + vy * ay + vz * az)
    cx, cy, cz = _cross(vx, vy, vz, ax, ay, az)
    qx = cb * st * ax + ct * sb * vx + sb * st * cx
    qy = cb * st * ay + ct * sb * vy + sb * st * cy
    qz = cb * st * az + ct * sb * vz + sb * st * cz
    return _quat_rotation(qw, qx, qy, qz)


@njit(cache=True, fastmath=True, error_model="numpy", inline="always")
def _lamina(geo, l, T0, T1, T2, series):
    """Leaf l's rotation against its twig (θ = (T0, T1, T2)) applied to its lever r_c and normal
    n (``geo``: :attr:`~treeanim.physics.structure.Structure.leaf_geometry`), and the larger
    squared half angle; by the branch-free series where ``series`` (valid up to
    :data:`~treeanim.physics.scalar.SERIES_MAX`)."""
    ax, ay, az = geo[0, l], geo[3, l], geo[6, l]
    vx = geo[1, l] * T1 + geo[2, l] * T2
    vy = geo[4, l] * T1 + geo[5, l] * T2
    vz = geo[7, l] * T1 + geo[8, l] * T2
    x2, t2 = 0.25 * (vx * vx + vy * vy + vz * vz), 0.25 * T0 * T0
    if series:
        (sb, cb), (st, ct) = sinc_cos_series(x2), sinc_cos_series(t2)
        st *= 0.5 * T0
    else:
        (sb, cb), (st, ct) = sinc_cos(x2), sincos(0.5 * T0)
    g00, g01, g02, g10, g11, g12, g20, g21, g22 = _leaf_rotation(ax, ay, az, vx, vy, vz, 0.5 * sb, cb, st, ct)
    r0, r1, r2, n0, n1, n2 = geo[9, l], geo[10, l], geo[11, l], geo[12, l], geo[13, l], geo[14, l]
    return (g00 * r0 + g01 * r1 + g02 * r2, g10 * r0 + g11 * r1 + g12 * r2, g20 * r0 + g21 * r1 + g22 * r2,
            g00 * n0 + g01 * n1 + g02 * n2, g10 * n0 + g11 * n1 + g12 * n2, g20 * n0 + g21 * n1 + g22 * n2,
            max(x2, t2))


@njit(cache=True, fastmath=True, error_model="numpy")
def _laminas(geo, th, A):
    """A (6, L): every leaf's lever r_c and normal n turned by its rotation against its twig
    (:func:`_lamina`), in its twig's axes, a row per component. The leaves run as vectors
    (eight a time with AVX-512: five times faster than one by one), their series checked
    after and the few beyond them taken one by one."""
    L = th.shape[0]
    T = np.empty((3, L))
    for l in range(L):  # θ's columns as rows, so the next loop reads every operand contiguous
        T[0, l], T[1, l], T[2, l] = th[l, 0], th[l, 1], th[l, 2]
    beyond = 0
    for l in range(L):
        A[0, l], A[1, l], A[2, l], A[3, l], A[4, l], A[5, l], x2 = _lamina(geo, l, T[0, l], T[1, l], T[2, l], True)
        beyond += x2 > SERIES_MAX
    if beyond:  # a twist past 3.2 rad (a bend stops at 2.8): those leaves by libm's sines
        for l in range(L):
            if _lamina(geo, l, th[l, 0], th[l, 1], th[l, 2], True)[6] > SERIES_MAX:
                A[0, l], A[1, l], A[2, l], A[3, l], A[4, l], A[5, l], _ = _lamina(geo, l, th[l, 0], th[l, 1],
                                                                                th[l, 2], False)


@njit(cache=True, fastmath=True, error_model="numpy", inline="always")
def _add_outer(C, w, a0, a1, a2, a3, a4, a5):
    """C + w·aaᵀ for a = (a0 … a5), C the upper triangle of a symmetric 6×6 (21 terms, row by row)."""
    w0, w1, w2, w3, w4, w5 = w * a0, w * a1, w * a2, w * a3, w * a4, w * a5
    return (C[0] + w0 * a0, C[1] + w0 * a1, C[2] + w0 * a2, C[3] + w0 * a3, C[4] + w0 * a4, C[5] + w0 * a5,
            C[6] + w1 * a1, C[7] + w1 * a2, C[8] + w1 * a3, C[9] + w1 * a4, C[10] + w1 * a5,
            C[11] + w2 * a2, C[12] + w2 * a3, C[13] + w2 * a4, C[14] + w2 * a5,
            C[15] + w3 * a3, C[16] + w3 * a4, C[17] + w3 * a5, C[18] + w4 * a4, C[19] + w4 * a5, C[20] + w5 * a5)


@njit(cache=True, fastmath=True, error_model="numpy", inline="always")
def _turn_stiffness(K, cs2, px, py, pz, nx, ny, nz, ex, ey, ez):
    """K + the symmetric part of Ka = −∂τ/∂φ made positive by Gershgorin's shift (as
    :func:`~treeanim.physics.treestep._add_turn` takes a segment's), K its upper triangle
    (k₀₀, k₁₁, k₂₂, k₀₁, k₀₂, k₁₂), for a lamina's normal force F = c|U|²(Û·n)n at x on its
    twig, the twig turning by δφ (δx = δφ × x, δn = δφ × n): the leaves' pull on a twig as it
    turns. ∂τ/∂φ = c|U|²[(Û·n)(x nᵀ − n xᵀ) + p qᵀ] with p = x × n, q = n × Û (Û = (ex, ey, ez));
    the first term is skew, so the symmetric part of Ka is −½c|U|²(p qᵀ + q pᵀ)."""
    qx, qy, qz = _cross(nx, ny, nz, ex, ey, ez)
    w = -0.5 * cs2
    k00, k11, k22 = 2.0 * w * px * qx, 2.0 * w * py * qy, 2.0 * w * pz * qz
    k01, k02, k12 = w * (px * qy + qx * py), w * (px * qz + qx * pz), w * (py * qz + qy * pz)
    shift = max(0.0, abs(k01) + abs(k02) - k00, abs(k01) + abs(k12) - k11, abs(k02) + abs(k12) - k22)
    return K[0] + (k00 + shift), K[1] + (k11 + shift), K[2] + (k22 + shift), K[3] + k01, K[4] + k02, K[5] + k12


@njit(cache=True, fastmath=True, error_model="numpy")
def _add_twig(b, F, C, K, LF, LC, LK):
    """Add a twig's sums (:func:`leaf_step`'s F, C and K) to its rows of LF, LC and LK."""
    if b < 0:
        return
    n = 0
    for i in range(6):
        LF[b, i] += F[i]
        for j in range(i, 6):
            LC[b, i, j] += C[n]
            n += 1
    LK[b, 0, 0] += K[0]
    LK[b, 1, 1] += K[1]
    LK[b, 2, 2] += K[2]
    LK[b, 0, 1] += K[3]
    LK[b, 0, 2] += K[4]
    LK[b, 1, 2] += K[5]


@njit(cache=True, fastmath=True, error_model="numpy")
def leaf_step(h, on, body, base0, rc0, geo, E, k, J, dstr, cna, cswing, roll2, cauchy, size, R, P, Om, V, U,
              amp, phase, twist, th, thd, LF, LC, LK):
    """Advance every leaf's petiole joint (bend about two axes and twist) over one step, and
    give the force it passes to its twig for the next.

    A leaf is a lamina on a petiole, its rotation against its twig exp(E·θ) (θ in the leaf's
    own axes E = [a, b₁, b₂], a along the lever from the petiole's base to the lamina's
    centroid: θ_a twists it, θ_b bends it). Its inertia is small next to its twig's and rides
    on it rigidly in the articulated step; here it turns on top, driven by the normal force
    ½ρC_nA|U_rel|(U_rel·n)n on the lamina (its twist by the flutter), held by its petiole's
    spring and damped by the petiole and the air, each axis stepped by :func:`_axis_step`
    (the air's moment linearised about the step's start, its restoring stiffness implicit).

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
    base0, rc0 : (L, 3) — rest offset of the petiole's base from its twig's joint, of the
        lamina's centroid from the petiole's base.
    geo : (15, L) — E, rc0 and the lamina's rest normal, a row per component
        (:attr:`~treeanim.physics.structure.Structure.leaf_geometry`).
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
    phase, twist : (L,) — the flutter's phase and its twist φ (rad), advanced in place: a
        frequency St·|U|/ℓ (:data:`FLUTTER_STROUHAL`; at most :data:`MAX_FLUTTER_HZ` and a
        quarter of the step rate), an amplitude ``amp``·U²/(U² + :data:`FLUTTER_SPEED`²),
        φ = amplitude·sin(phase). It drives the petiole's twist through its torque k_t·φ, a
        ramp over the step from φ's value at its start to its value at its end.
    th, thd : (L, 3) — the state, advanced in place.
    LF, LC, LK : (B, 6), (B, 6, 6), (B, 3, 3) — written: summed over each twig's leaves, the
        laminas' spatial force (world, N, about the twig's joint), their air damping there as
        point terms Pᵀ C P (C = ½ρC_n·A·(|U_rel| n nᵀ + |U_rel·n| ÛÛᵀ), N·s/m, the force's
        derivative against the velocity bounded by a symmetric one) and their normal forces'
        stiffness against the twig's turn (:func:`_turn_stiffness`, N·m); the last two
        symmetric, their upper triangles written, for the next step to take implicitly.
    """
    LF[:] = 0.0
    LC[:] = 0.0
    LK[:] = 0.0
    A = np.empty((6, body.shape[0]))
    C = np.empty((8, 3 * body.shape[0]))  # each petiole axis's step (_petioles)
    _laminas(geo, th, A)
    f_max = 0.25 / h  # a quarter of the step rate (the flutter is at most MAX_FLUTTER_HZ anyway)
    z6 = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    z21 = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    TF, TC, TK = z6, z21, z6  # the sums over the current twig's leaves, kept in registers
    last = -1
    for l in range(body.shape[0]):
        b = body[l]
        if b != last:  # the twig's kinematics, kept in registers while its leaves follow
            _add_twig(last, TF, TC, TK, LF, LC, LK)
            TF, TC, TK = z6, z21, z6
            last = b
            r00, r01, r02, r10, r11, r12, r20, r21, r22 = (R[b, 0, 0], R[b, 0, 1], R[b, 0, 2], R[b, 1, 0], R[b, 1, 1],
                                                           R[b, 1, 2], R[b, 2, 0], R[b, 2, 1], R[b, 2, 2])
            Ux, Uy, Uz = U[b, 0], U[b, 1], U[b, 2]
            Wx, Wy, Wz = Ux - V[b, 0], Uy - V[b, 1], Uz - V[b, 2]
            ox, oy, oz = Om[b, 0], Om[b, 1], Om[b, 2]
            u2 = Ux * Ux + Uy * Uy + Uz * Uz
            fU, flutter = FLUTTER_STROUHAL * np.sqrt(u2), amp * u2 / (u2 + FLUTTER_SPEED * FLUTTER_SPEED)
        # the flutter: its phase and amplitude in the wind at the twig, slowed to a quarter of
        # the step rate where it is faster (:data:`MAX_FLUTTER_HZ`)
        f_leaf = min(fU / max(size[l], 1e-3), MAX_FLUTTER_HZ)
        f = min(f_leaf, f_max)
        ph = phase[l] + 2.0 * np.pi * f * h  # less than 4π: f ≤ 1/(4h)
        ph = ph - 2.0 * np.pi if ph >= 2.0 * np.pi else ph  # exact (Sterbenz)
        phase[l] = ph
        twist0 = twist[l]
        if not on[l]:
            twist[l] = 0.0
            C[:5, 3 * l:3 * l + 3] = 0.0
            continue
        # slowed, it is scaled by f/f_leaf: a lamina's bends follow its twist within their
        # settling (some 0.03 s in a gale), and twist and bends each take a 12 Hz flutter about
        # half as far as a 2.5 Hz one; unscaled, a 1/10 s step's slowed flutter swung the
        # laminas' bends from side to side from one step to the next
        twist1 = flutter * sin_turn(ph) * (f / f_leaf if f < f_leaf else 1.0)
        twist[l] = twist1
        # the lever and the normal turned against the twig (A), in the world's axes
        a0, a1, a2 = A[0, l], A[1, l], A[2, l]
        cx, cy, cz = r00 * a0 + r01 * a1 + r02 * a2, r10 * a0 + r11 * a1 + r12 * a2, r20 * a0 + r21 * a1 + r22 * a2
        a0, a1, a2 = A[3, l], A[4, l], A[5, l]
        nx, ny, nz = r00 * a0 + r01 * a1 + r02 * a2, r10 * a0 + r11 * a1 + r12 * a2, r20 * a0 + r21 * a1 + r22 * a2
        q0, q1, q2 = base0[l, 0], base0[l, 1], base0[l, 2]
        bx, by, bz = r00 * q0 + r01 * q1 + r02 * q2, r10 * q0 + r11 * q1 + r12 * q2, r20 * q0 + r21 * q1 + r22 * q2
        xx, xy, xz = bx + cx, by + cy, bz + cz  # the centroid from the twig's joint
        # the air relative to the lamina, its twig's motion taken away
        o = _cross(ox, oy, oz, xx, xy, xz)
        ux, uy, uz = Wx - o[0], Wy - o[1], Wz - o[2]
        s = np.sqrt(ux * ux + uy * uy + uz * uz)
        un = ux * nx + uy * ny + uz * nz
        c = cna[l] * inv_cbrt(1.0 + cauchy[l] * s * s)  # the folded lamina's
        fn = c * s * un
        # on the twig: the force's Plücker line a = (x × n, n) through the centroid x, and,
        # the next step taking them implicitly, the point terms α·aaᵀ + β·bbᵀ (b = (x × Û, Û))
        # and the force's stiffness against the twig's turn (:func:`_turn_stiffness`)
        mx, my, mz = _cross(xx, xy, xz, nx, ny, nz)
        TF = (TF[0] + fn * mx, TF[1] + fn * my, TF[2] + fn * mz, TF[3] + fn * nx, TF[4] + fn * ny, TF[5] + fn * nz)
        if c * s > 0.0:
            q = 1.0 / s
            ex, ey, ez = ux * q, uy * q, uz * q
            rx, ry, rz = _cross(xx, xy, xz, ex, ey, ez)
            TC = _add_outer(_add_outer(TC, c * s, mx, my, mz, nx, ny, nz), c * abs(un), rx, ry, rz, ex, ey, ez)
            TK = _turn_stiffness(TK, c * s * s, mx, my, mz, nx, ny, nz, ex, ey, ez)
        # about the petiole's base the normal force's moment is fn·p (p = x_c × n, x_c the
        # centroid from the base) and its stiffness against a turn about an axis e (δx_c = e × x_c,
        # δn = e × n) is −c|U|(e·p)(e·w), w = n × U_rel; in the twig's axes, where E's are
        px, py, pz = _cross(cx, cy, cz, nx, ny, nz)
        pl0, pl1, pl2 = r00 * px + r10 * py + r20 * pz, r01 * px + r11 * py + r21 * pz, r02 * px + r12 * py + r22 * pz
        wx, wy, wz = _cross(nx, ny, nz, ux, uy, uz)
        wl0, wl1, wl2 = r00 * wx + r10 * wy + r20 * wz, r01 * wx + r11 * wy + r21 * wz, r02 * wx + r12 * wy + r22 * wz
        lever2 = rc0[l, 0] ** 2 + rc0[l, 1] ** 2 + rc0[l, 2] ** 2
        dair = max(cswing[l], c) * s * lever2  # the air against the lamina's own swing
        for i in range(3):
            kk, guard = k[l, i], MAX_TURN
            if i == 0:
                # the twist: nil for a force at the centroid, which lies on the lamina's axis;
                # the flutter drives it (its torque a ramp over the step), the lamina's halves
                # swinging through the air damp it, against the flutter, which is the air's own
                # motion of the lamina: the air damps the roll's departure from it
                droll = cswing[l] * s * roll2[l]
                K, f0, f1, g = kk, kk * twist0, kk * (twist1 - twist0), droll * (twist1 - twist0)
                d = dstr[l, i] + droll
            else:
                # a bend: the air's moment linearised about the step's start, its stiffness
                # taken implicitly where it restores (a lamina weathervaning into the flow)
                ep = E[l, 0, i] * pl0 + E[l, 1, i] * pl1 + E[l, 2, i] * pl2
                ew = E[l, 0, i] * wl0 + E[l, 1, i] * wl1 + E[l, 2, i] * wl2
                tau = fn * ep
                ka = max(0.0, -c * s * ep * ew)
                if abs(tau - kk * th[l, i]) > SECANT_TURN * (kk + ka):  # far from rest: the chord
                    e0, e1, e2 = E[l, 0, i], E[l, 1, i], E[l, 2, i]
                    ex, ey, ez = r00 * e0 + r01 * e1 + r02 * e2, r10 * e0 + r11 * e1 + r12 * e2, r20 * e0 + r21 * e1 + r22 * e2
                    eu = ex * ux + ey * uy + ez * uz
                    en = ex * nx + ey * ny + ez * nz
                    dstar = _release_turn(tau, eu * en, un - eu * en, ew)
                    ka = max(ka, abs(tau) / dstar)
                    if np.isfinite(dstar):  # the chord is exact as far as the air's balance
                        guard = max(guard, dstar)
                K, f0, f1, g = kk + ka, tau + ka * th[l, i], 0.0, 0.0
                d = dstr[l, i] + dair
            j = 3 * l + i
            C[0, j], C[1, j], C[2, j], C[3, j], C[4, j], C[7, j] = K, d, f0, f1, g, guard
    _add_twig(last, TF, TC, TK, LF, LC, LK)
    _petioles(h, on, J, th, thd, C)


@njit(cache=True, fastmath=True, error_model="numpy")
def _petioles(h, on, J, th, thd, C):
    """Step every petiole axis of the leaves ``on`` by :func:`_axis_step` from its K, d, f₀, f₁
    and g (C's rows 0–4, a column per axis, θ's order), all axes as vectors (rows 5 and 6 take
    θ and θ̇ after it), then the guard (row 7, at least :data:`MAX_TURN`) and the petiole's
    stop leaf by leaf."""
    n = C.shape[1]
    Jf, tf, vf = J.reshape(n), th.reshape(n), thd.reshape(n)
    for j in range(n):
        C[5, j], C[6, j] = _axis_step(h, Jf[j], C[0, j], C[1, j], C[2, j], C[3, j], C[4, j], tf[j], vf[j])
    for l in range(on.shape[0]):
        if not on[l]:
            continue
        for i in range(3):
            turn, v = C[5, 3 * l + i] - th[l, i], C[6, 3 * l + i]
            guard = C[7, 3 * l + i]
            if i > 0 and abs(turn) > guard:  # the guard (see MAX_TURN): speed cut with it
                v *= guard / abs(turn)
                turn = guard if turn > 0.0 else -guard
            th[l, i] += turn
            thd[l, i] = v
        # a petiole's stop
        bend2 = th[l, 1] ** 2 + th[l, 2] ** 2
        if bend2 > PETIOLE_STOP * PETIOLE_STOP:
            sc = PETIOLE_STOP / np.sqrt(bend2)
            th[l, 1] *= sc
            th[l, 2] *= sc
            thd[l, 1] *= sc
            thd[l, 2] *= sc


@njit(cache=True, fastmath=True, error_model="numpy", inline="always")
def _matrix_quat(M):
    """The unit quaternion (w, x, y, z) of the rotation matrix M (Shepperd: from its largest
    diagonal term)."""
    t = M[0, 0] + M[1, 1] + M[2, 2]
    if t > 0.0:
        s = 2.0 * np.sqrt(t + 1.0)
        return 0.25 * s, (M[2, 1] - M[1, 2]) / s, (M[0, 2] - M[2, 0]) / s, (M[1, 0] - M[0, 1]) / s
    if M[0, 0] > M[1, 1] and M[0, 0] > M[2, 2]:
        s = 2.0 * np.sqrt(1.0 + M[0, 0] - M[1, 1] - M[2, 2])
        return (M[2, 1] - M[1, 2]) / s, 0.25 * s, (M[0, 1] + M[1, 0]) / s, (M[0, 2] + M[2, 0]) / s
    if M[1, 1] > M[2, 2]:
        s = 2.0 * np.sqrt(1.0 + M[1, 1] - M[0, 0] - M[2, 2])
        return (M[0, 2] - M[2, 0]) / s, (M[0, 1] + M[1, 0]) / s, 0.25 * s, (M[1, 2] + M[2, 1]) / s
    s = 2.0 * np.sqrt(1.0 + M[2, 2] - M[0, 0] - M[1, 1])
    return (M[1, 0] - M[0, 1]) / s, (M[0, 2] + M[2, 0]) / s, (M[1, 2] + M[2, 1]) / s, 0.25 * s


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
    last = -1
    Qw = Qx = Qy = Qz = Px = Py = Pz = xb = yb = zb = 0.0
    r00 = r01 = r02 = r10 = r11 = r12 = r20 = r21 = r22 = 0.0
    g00 = g01 = g02 = g10 = g11 = g12 = g20 = g21 = g22 = 0.0
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
        k = leaf_first[l + 1] - a - 1
        if b != last:  # the twig's pose, its rotation as a quaternion (kept while its leaves follow)
            last = b
            Qw, Qx, Qy, Qz = _matrix_quat(R[b])
            jb = body_node[b]
            r00, r01, r02, r10, r11, r12, r20, r21, r22 = (R[b, 0, 0], R[b, 0, 1], R[b, 0, 2], R[b, 1, 0], R[b, 1, 1],
                                                           R[b, 1, 2], R[b, 2, 0], R[b, 2, 1], R[b, 2, 2])
            Px, Py, Pz = P[b, 0], P[b, 1], P[b, 2]
            xb, yb, zb = Xrest[jb, 0], Xrest[jb, 1], Xrest[jb, 2]
        # the petiole's base on its twig
        n0 = leaf_nodes[a]
        x0, y0, z0 = Xrest[n0, 0], Xrest[n0, 1], Xrest[n0, 2]
        dx, dy, dz = x0 - xb, y0 - yb, z0 - zb
        sx = Px + r00 * dx + r01 * dy + r02 * dz
        sy = Py + r10 * dx + r11 * dy + r12 * dz
        sz = Pz + r20 * dx + r21 * dy + r22 * dz
        pos[n0, 0], pos[n0, 1], pos[n0, 2] = sx, sy, sz
        if k == 0:
            continue
        # segment q turns by G_q = B^((q+1)/k)·T^((q+1)/k), the bend B (angle β about v/β) and
        # the twist T (about a) as quaternions whose half angles grow by one k-th a segment
        # (angle addition; the bend's sine kept as sin/β, so v needs no normalising), then the
        # twig's turn on top: Q·(c_b + s_b·v)(c_t + s_t·a) = c_b·c_t·Q + c_b·s_t·Qa + s_b·c_t·Qv
        # + s_b·s_t·Qva (Qa = Q·a, Qv = Q·v, Qva = Q·v·a; a and v as pure quaternions)
        on = 1.0 if leaf_on[l] else 0.0
        ax, ay, az = leaf_E[l, 0, 0], leaf_E[l, 1, 0], leaf_E[l, 2, 0]
        t1, t2 = on * leaf_th[l, 1], on * leaf_th[l, 2]
        vx = leaf_E[l, 0, 1] * t1 + leaf_E[l, 0, 2] * t2
        vy = leaf_E[l, 1, 1] * t1 + leaf_E[l, 1, 2] * t2
        vz = leaf_E[l, 2, 1] * t1 + leaf_E[l, 2, 2] * t2
        b2 = vx * vx + vy * vy + vz * vz
        sb1, cb1 = sinc_cos(b2 / (4 * k * k))  # of β/2k
        sb1 /= 2 * k  # sin(β/2k)/β
        st1, ct1 = sincos(0.5 * on * leaf_th[l, 0] / k)
        cb, sb, ct, st = cb1, sb1, ct1, st1
        aw, ax_, ay_, az_ = _qmul_pure(Qw, Qx, Qy, Qz, ax, ay, az)
        bw, bx_, by_, bz_ = _qmul_pure(Qw, Qx, Qy, Qz, vx, vy, vz)
        cw, cx_, cy_, cz_ = _qmul_pure(bw, bx_, by_, bz_, ax, ay, az)
        for q in range(k):
            if q > 0:
                cb, sb = cb * cb1 - b2 * sb * sb1, sb * cb1 + cb * sb1
                ct, st = ct * ct1 - st * st1, st * ct1 + ct * st1
            w0, w1, w2, w3 = cb * ct, cb * st, sb * ct, sb * st
            g00, g01, g02, g10, g11, g12, g20, g21, g22 = _quat_rotation(
                w0 * Qw + w1 * aw + w2 * bw + w3 * cw, w0 * Qx + w1 * ax_ + w2 * bx_ + w3 * cx_,
                w0 * Qy + w1 * ay_ + w2 * by_ + w3 * cy_, w0 * Qz + w1 * az_ + w2 * bz_ + w3 * cz_)
            _put3(rot, n0, g00, g01, g02, g10, g11, g12, g20, g21, g22)
            n1 = leaf_nodes[a + q + 1]
            x1, y1, z1 = Xrest[n1, 0], Xrest[n1, 1], Xrest[n1, 2]
            dx, dy, dz = x1 - x0, y1 - y0, z1 - z0
            sx += g00 * dx + g01 * dy + g02 * dz
            sy += g10 * dx + g11 * dy + g12 * dz
            sz += g20 * dx + g21 * dy + g22 * dz
            pos[n1, 0], pos[n1, 1], pos[n1, 2] = sx, sy, sz
            n0, x0, y0, z0 = n1, x1, y1, z1
        _put3(rot, n0, g00, g01, g02, g10, g11, g12, g20, g21, g22)  # the lamina turns with its last segment


@njit(cache=True, fastmath=True, error_model="numpy", inline="always")
def _qmul_pure(qw, qx, qy, qz, ux, uy, uz):
    """The quaternion product (qw, qx, qy, qz)·(0, ux, uy, uz)."""
    cx, cy, cz = _cross(qx, qy, qz, ux, uy, uz)
    return -(qx * ux + qy * uy + qz * uz), qw * ux + cx, qw * uy + cy, qw * uz + cz


@njit(cache=True, fastmath=True, error_model="numpy", inline="always")
def _put3(M, n, m00, m01, m02, m10, m11, m12, m20, m21, m22):
    """M[n] = the 3×3 matrix of the nine terms, row by row."""
    M[n, 0, 0], M[n, 0, 1], M[n, 0, 2] = m00, m01, m02
    M[n, 1, 0], M[n, 1, 1], M[n, 1, 2] = m10, m11, m12
    M[n, 2, 0], M[n, 2, 1], M[n, 2, 2] = m20, m21, m22
