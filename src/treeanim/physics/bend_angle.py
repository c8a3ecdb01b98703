"""The bend angle of one joint (Eqs. 8–9) and the saturating twist (Eq. 11), vectorised.

:func:`solve_bend_angle` solves |F||s| sin(θ₀ − φ) = kφ for every segment at once
(docs/design.md §5); :mod:`treeanim.physics.bending` turns the angles into rotations.
"""

from __future__ import annotations

import numpy as np

#: Newton stops when |Δφ| is below this (radians).
NEWTON_TOL = 1e-7
#: Halley iterations run on every segment; from the previous step's angle (a warm start) two
#: usually converge. Segments not converged by then continue alone (Newton, then bisection), so
#: the tolerance always holds.
NEWTON_FIXED = 2
#: Further Newton iterations for the stragglers before bisection takes over.
NEWTON_EXTRA = 12


def _residual(phi, a, theta0, k):
    """h(φ) = a sin(θ₀ − φ) − kφ, hp = −h′ = a cos(θ₀ − φ) + k, m = −h″ = a sin(θ₀ − φ).

    sin and cos come from τ = tan((θ₀ − φ)/2) (one fast tan). Returns (h, hp, m).
    """
    tau = np.subtract(theta0, phi)
    tau *= 0.5
    np.tan(tau, out=tau)
    t2 = tau * tau
    r = t2 + 1.0
    np.divide(a, r, out=r)  # a/(1 + τ²)
    m = tau * r
    m += m  # a sin ψ = 2τ a/(1+τ²)
    hp = t2
    hp *= r
    np.subtract(r, hp, out=hp)  # a cos ψ = (1 − τ²) a/(1+τ²)
    hp += k
    h = k * phi
    np.subtract(m, h, out=h)
    return h, hp, m


def solve_bend_angle(nn: np.ndarray, dot: np.ndarray, k: np.ndarray, theta0: np.ndarray,
                     phi0: np.ndarray | None = None, tol: float = NEWTON_TOL,
                     fixed: int = NEWTON_FIXED, a: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Solve |F||s| sin(θ₀ − φ) = k φ for φ ∈ [0, θ₀] (Eqs. 8–9), vectorised.

    With a = |F||s| (``a·sin θ₀ = |s × F|`` = ``nn``, ``a·cos θ₀ = s·F`` = ``dot``) the
    residual h(φ) = a sin(θ₀ − φ) − k φ is concave on [0, θ₀] with h(0) >= 0 >= h(θ₀), so the
    root is unique. ``fixed`` safeguarded iterations of Halley's method (Newton with the
    curvature term, cubically convergent; iterates clipped to [0, θ₀]) run on every entry;
    entries whose last correction is still >= ``tol``, or that sit left of the apex of h (where
    the step points away from the root), continue alone with plain Newton started on the right
    of the root (monotone there) and finally bisection on [0, θ₀], so the tolerance always
    holds.

    Parameters
    ----------
    nn, dot : (K,) float
        |s × F| and s·F (N·m).
    k : (K,) float
        Segment stiffness (N·m/rad), >= 0.
    theta0 : (K,) float
        ∠(F, s) in [0, π].
    phi0 : (K,) float, optional
        Start (e.g. from the previous step); default: the Newton step from 0.
    tol : float
        Convergence: the last correction is below ``tol``.
    fixed : int
        Iterations run on every entry.
    a : (K,) float, optional
        |F||s| if the caller has it (else hypot(nn, dot)).

    Returns
    -------
    phi : (K,) float
        φ in [0, θ₀] (the last evaluated iterate, whose correction is < tol).
    t : (K,) float
        tan(φ/2).
    """
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        if a is None:
            a = np.hypot(nn, dot)
        if phi0 is None:
            den = k + dot
            phi = nn / den
            phi = np.where((den > 0) & (phi < theta0), phi, theta0)
        else:
            phi = np.maximum(phi0, 0.0)
            np.minimum(phi, theta0, out=phi)
        fixed = max(int(fixed), 1)
        for it in range(fixed):
            h, hp, m = _residual(phi, a, theta0, k)
            if it + 1 == fixed:
                # h′ >= 0: left of the apex of h, where the step points the wrong way (and a
                # clipped step can look converged at φ = 0); such entries start again on the
                # right of the root below.
                stuck = hp <= 0
            # Halley: φ + h·hp / (hp² + h·m/2)   (h′ = −hp, h″ = −m)
            m *= h
            m *= 0.5
            new = h * hp
            hp *= hp
            hp += m
            new /= hp
            new += phi
            np.maximum(new, 0.0, out=new)
            np.minimum(new, theta0, out=new)  # NaN stays NaN and is caught below
            if it + 1 < fixed:
                phi = new
        new -= phi
        np.abs(new, out=new)
        bad = ~(new < tol)
        bad |= stuck
        if bad.any():
            idx = np.flatnonzero(bad)
            phi = phi.copy()
            phi[idx] = _stragglers(phi[idx], a[idx], k[idx], theta0[idx], tol)
        t = np.multiply(phi, 0.5)
        np.tan(t, out=t)
    return phi, t


def _stragglers(phi, a, k, theta0, tol):
    """More safeguarded Halley iterations for the entries the fixed ones left unconverged,
    each dropped once converged; bisection for any that still are not."""
    out = phi.copy()
    idx = np.arange(len(phi))
    for _ in range(NEWTON_EXTRA):
        h, hp, m = _residual(phi, a, theta0, k)
        new = h * hp / (hp * hp + 0.5 * h * m)
        new += phi
        right = hp > 0
        new = np.where(right, new, theta0)  # left of the apex: restart right of the root
        np.maximum(new, 0.0, out=new)
        np.minimum(new, theta0, out=new)
        done = np.abs(new - phi) < tol
        done &= right
        if done.all():
            out[idx] = phi
            return out
        out[idx[done]] = phi[done]
        keep = ~done
        idx, phi, a, k, theta0 = idx[keep], new[keep], a[keep], k[keep], theta0[keep]
    # Bisection on [0, θ₀] (h(0) >= 0 >= h(θ₀)) for the rest: always converges.
    lo = np.zeros_like(phi)
    hi = theta0.copy()
    while np.any(hi - lo >= tol):
        mid = 0.5 * (lo + hi)
        h, _, _ = _residual(mid, a, theta0, k)
        pos = h > 0
        lo = np.where(pos, mid, lo)
        hi = np.where(pos, hi, mid)
    out[idx] = 0.5 * (lo + hi)
    return out


def saturating_twist(torque: np.ndarray, rate, scale) -> np.ndarray:
    """Eq. 11's twist: γ = −scale·sgn(T)(1 − exp(−rate·|T|)), a new array.

    Parameters
    ----------
    torque : (K,) float
        The twisting moment T (the paper's L′_v, or the torsion a joint carries).
    rate : float or (K,) float
        1/moment at which the twist saturates (the paper's c0/k₀).
    scale : float or (K,) float
        Minus the largest twist (−0.5π/n per segment in the paper, −0.5π per joint).
    """
    gamma = np.abs(torque)
    gamma *= rate
    gamma *= -1.0
    np.expm1(gamma, out=gamma)
    gamma *= np.sign(torque)
    gamma *= scale
    return gamma
