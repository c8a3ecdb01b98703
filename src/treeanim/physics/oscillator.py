"""Driven damped oscillators of the three modes (Eqs. 2–5, docs/design.md §5).

Each mode obeys q̈ + 4πζf q̇ + 4π²f² q = g (m = 1) and outputs L′ = 4π²f² q (Eq. 5), so L′
settles at the applied load g: unit static gain. The state is kept in load units:
``p = L′ = ω²q`` and ``pd = ω²q̇`` with ω = 2πf, which satisfy the same equation with the
load scaled by ω².

Two integrators advance the state over a step with the load held constant (:data:`INTEGRATORS`,
by name, each with the same ``step`` and ``response``):

``exact``
    The closed-form solution of the damped oscillator (under-, critically and over-damped,
    ζ = 0 too). Unconditionally stable: the free decay has exactly frequency f and damping ratio
    ζ whatever the step, and a step of any length cannot blow up.
``euler``
    The paper's explicit Euler in its semi-implicit (symplectic) form — velocity first, then
    position — sub-stepped so that ω·h <= 0.05. The semi-implicit form is used because the
    forward form pumps energy (a growth rate of ω²h/2 per second, which at ω·h = 0.05 nearly
    cancels a damping ratio of 0.03). A heavily damped mode takes shorter sub-steps as well, with
    2ζω·h <= 1 (explicit damping overshoots beyond 1 and diverges beyond 2, ζ above about 20 at
    ω·h = 0.05); the paper's ζ of at most 0.5 never needs them. At most
    :data:`EULER_MAX_SUBSTEPS` sub-steps are taken per
    call; a longer step is clamped to ``EULER_MAX_SUBSTEPS · 0.05 / ω_max`` seconds of
    oscillator time (the simulation clock still advances by the full step).
"""

from __future__ import annotations

import numpy as np

#: ω·h limit of the Euler sub-steps.
EULER_OMEGA_H = 0.05
#: Most Euler sub-steps per call (beyond that the step is clamped, see the module notes).
EULER_MAX_SUBSTEPS = 4096

#: |x| below which the series of cos(√x) and sin(√x)/√x is used (x = ω²(1−ζ²)h²).
_SERIES_X = 1e-3


def exact_coefficients(f: np.ndarray, zeta: np.ndarray, dt: float) -> tuple[np.ndarray, ...]:
    """Transition coefficients of the exact step.

    For a displacement y = p − g from the static point and its rate ẏ = pd, the free damped
    oscillator gives ``y(dt) = A·y + B·ẏ`` and ``ẏ(dt) = C·y + D·ẏ``.

    Parameters
    ----------
    f : array of float
        Natural frequencies (Hz), > 0.
    zeta : array of float, same shape
        Damping ratios, >= 0.
    dt : float
        Step length (s), > 0.

    Returns
    -------
    A, B, C, D : arrays of the shape of ``f``
    """
    f = np.asarray(f, float)
    zeta = np.asarray(zeta, float)
    w = 2.0 * np.pi * f
    alpha = zeta * w  # decay rate ζω
    x = (w * dt) ** 2 * (1.0 - zeta * zeta)  # (ω_d dt)², negative when over-damped
    ec = np.empty_like(w)  # e^{-αh}·cos(ω_d h)      (cosh when over-damped)
    es = np.empty_like(w)  # e^{-αh}·sin(ω_d h)/ω_d  (sinh(βh)/β when over-damped)
    with np.errstate(over="ignore", under="ignore", invalid="ignore"):
        series = np.abs(x) < _SERIES_X
        under = ~series & (x > 0)
        over = ~series & (x < 0)
        if np.any(series):  # near critical damping: no division by ω_d ≈ 0
            xs = x[series]
            e = np.exp(-alpha[series] * dt)
            ec[series] = e * (1 - xs / 2 * (1 - xs / 12 * (1 - xs / 30 * (1 - xs / 56))))
            es[series] = e * dt * (1 - xs / 6 * (1 - xs / 20 * (1 - xs / 42 * (1 - xs / 72))))
        if np.any(under):
            wd = np.sqrt(x[under]) / dt
            e = np.exp(-alpha[under] * dt)
            ec[under] = e * np.cos(wd * dt)
            es[under] = e * np.sin(wd * dt) / wd
        if np.any(over):  # combine the exponentials so that nothing overflows for a long step
            b = np.sqrt(-x[over]) / dt
            ep = np.exp((b - alpha[over]) * dt)
            em = np.exp((-b - alpha[over]) * dt)
            ec[over] = 0.5 * (ep + em)
            es[over] = 0.5 * (ep - em) / b
    A = ec + alpha * es
    B = es
    C = -(w * w) * es
    D = ec - alpha * es
    return A, B, C, D


def exact_step(p: np.ndarray, pd: np.ndarray, g: np.ndarray, coeffs) -> None:
    """Advance the state in place by the exact step whose coefficients are ``coeffs``.

    Parameters
    ----------
    p, pd : arrays
        L′ and its rate (modified in place).
    g : array
        Load held constant over the step (N).
    coeffs : tuple
        From :func:`exact_coefficients`.
    """
    A, B, C, D = coeffs
    y = p - g
    ynew = A * y
    ynew += B * pd
    pd *= D
    pd += C * y
    np.add(g, ynew, out=p)


def euler_substeps(f_max: float, dt: float, damp_max: float = 0.0) -> tuple[int, float]:
    """Number of Euler sub-steps and their length for a step ``dt``.

    Returns ``(n, h)`` with ω_max·h <= 0.05, ``damp_max``·h <= 1 (``damp_max`` the largest
    2ζω) and n <= :data:`EULER_MAX_SUBSTEPS`; when the cap binds, ``n·h < dt`` (the step is
    clamped).
    """
    w = 2.0 * np.pi * float(f_max)
    n = int(np.ceil(w * dt / EULER_OMEGA_H - 1e-12)) if w > 0 else 1
    n = max(n, 1, int(np.ceil(float(damp_max) * dt - 1e-12)))
    if n > EULER_MAX_SUBSTEPS:
        return EULER_MAX_SUBSTEPS, min(EULER_OMEGA_H / w if w > 0 else np.inf, 1.0 / max(float(damp_max), 1e-300))
    return n, dt / n


def euler_step(p: np.ndarray, pd: np.ndarray, g: np.ndarray, f: np.ndarray, zeta: np.ndarray, dt: float) -> None:
    """Advance the state in place by semi-implicit Euler sub-steps (see the module notes).

    Parameters
    ----------
    p, pd : arrays
        L′ and its rate (modified in place).
    g : array
        Load held constant over the step (N).
    f, zeta : arrays
        Natural frequencies (Hz) and damping ratios.
    dt : float
        Step length (s).
    """
    w = 2.0 * np.pi * np.asarray(f, float)
    k_damp = 2.0 * zeta * w  # 4πζf
    k_spring = w * w  # 4π²f²
    n, h = euler_substeps(float(np.max(w)) / (2 * np.pi), dt, float(np.max(k_damp, initial=0.0)))
    for _ in range(n):
        # p̈ = ω²g − 4πζf ṗ − 4π²f² p  (Eq. 2–4 scaled by ω²)
        acc = g - p
        acc *= k_spring
        acc -= k_damp * pd
        pd += h * acc
        p += h * pd


class Exact:
    """The closed-form step; its coefficients are cached per step length until :meth:`clear`
    (the modes changed)."""

    def __init__(self):
        self._cache: dict[float, tuple] = {}

    def clear(self) -> None:
        """Forget the coefficients (call when f or ζ change)."""
        self._cache.clear()

    def coefficients(self, f: np.ndarray, zeta: np.ndarray, dt: float) -> tuple[np.ndarray, ...]:
        """:func:`exact_coefficients`, cached."""
        coef = self._cache.get(dt)
        if coef is None:
            if len(self._cache) > 8:
                self._cache.clear()
            coef = self._cache[dt] = exact_coefficients(f, zeta, dt)
        return coef

    def step(self, p, pd, g, f, zeta, dt) -> None:
        """Advance (p, pd) in place under the load g (:func:`exact_step`)."""
        exact_step(p, pd, g, self.coefficients(f, zeta, dt))


class Euler:
    """The paper's Euler steps (semi-implicit, sub-stepped; see the module notes)."""

    def clear(self) -> None:
        """Nothing is cached."""

    def step(self, p, pd, g, f, zeta, dt) -> None:
        """Advance (p, pd) in place under the load g (:func:`euler_step`)."""
        euler_step(p, pd, g, f, zeta, dt)


#: The integrators by name (``Simulation(integrator=...)``).
INTEGRATORS = {"exact": Exact, "euler": Euler}
