"""The modal oscillators (Eqs. 2–5): exact and Euler integration, measured from their traces."""

import numpy as np
import pytest
from scipy.optimize import curve_fit

from treeanim.physics.oscillator import (
    EULER_MAX_SUBSTEPS,
    EULER_OMEGA_H,
    euler_step,
    euler_substeps,
    exact_coefficients,
    exact_step,
)


def run(f, zeta, dt, seconds, integrator="exact", p0=1.0, g=0.0):
    """Trace L′ of one oscillator released from L′ = p0 at rest under a constant load g."""
    f = np.array([float(f)])
    z = np.array([float(zeta)])
    p = np.array([p0])
    pd = np.array([0.0])
    gg = np.array([g])
    n = int(round(seconds / dt))
    out = np.empty(n + 1)
    out[0] = p[0]
    coef = exact_coefficients(f, z, dt)
    for k in range(n):
        if integrator == "exact":
            exact_step(p, pd, gg, coef)
        else:
            euler_step(p, pd, gg, f, z, dt)
        out[k + 1] = p[0]
    return np.arange(n + 1) * dt, out


def fit_decay(t, x):
    """(f, ζ) of a damped cosine fitted to the samples (the natural frequency, not ω_d)."""
    def model(t, A, zeta, f, ph):
        w = 2 * np.pi * f
        return A * np.exp(-zeta * w * t) * np.cos(w * np.sqrt(1 - zeta**2) * t + ph)

    spec = np.abs(np.fft.rfft(x - x.mean()))
    f0 = np.fft.rfftfreq(len(x), t[1] - t[0])[np.argmax(spec[1:]) + 1]
    p, _ = curve_fit(model, t, x, p0=[x[0], 0.05, f0, 0.0], maxfev=20000)
    return p[2], p[1]


def log_decrement(t, x):
    """(f, ζ) from successive positive peaks (logarithmic decrement), a second estimate."""
    i = np.flatnonzero((x[1:-1] > x[:-2]) & (x[1:-1] >= x[2:]) & (x[1:-1] > 0)) + 1
    # parabolic refinement of each peak
    y0, y1, y2 = x[i - 1], x[i], x[i + 1]
    d = 0.5 * (y0 - y2) / (y0 - 2 * y1 + y2)
    tp = t[i] + d * (t[1] - t[0])
    yp = y1 - 0.25 * (y0 - y2) * d
    delta = np.mean(np.diff(np.log(yp)))
    zeta = -delta / np.sqrt(4 * np.pi**2 + delta**2)
    fd = 1.0 / np.mean(np.diff(tp))
    return fd / np.sqrt(1 - zeta**2), zeta


@pytest.mark.parametrize("dt", [1 / 10, 1 / 60, 1 / 1000])
@pytest.mark.parametrize("f, zeta", [(0.75, 0.045), (1.3, 0.12), (0.5, 0.3), (2.8, 0.0)])
def test_exact_free_decay_has_f_and_zeta_at_any_dt(f, zeta, dt):
    t, x = run(f, zeta, dt, seconds=min(30.0, 8.0 / max(zeta * f, 0.2)))
    fm, zm = fit_decay(t, x)
    assert fm == pytest.approx(f, rel=1e-6)
    assert zm == pytest.approx(zeta, rel=1e-5, abs=1e-7)


@pytest.mark.parametrize("dt", [1 / 60, 1 / 1000])
def test_log_decrement_agrees(dt):
    t, x = run(0.8, 0.04, dt, 20.0)
    fm, zm = log_decrement(t, x)
    assert fm == pytest.approx(0.8, rel=2e-3)
    assert zm == pytest.approx(0.04, rel=2e-2)


@pytest.mark.parametrize("zeta", [1.0, 1.0 - 1e-9, 1.0 + 1e-9, 1.0 + 1e-3, 2.5])
@pytest.mark.parametrize("dt", [1 / 60, 0.5, 7.0])
def test_critical_and_over_damped_match_the_closed_form(zeta, dt):
    f = 1.1
    w = 2 * np.pi * f
    t, x = run(f, zeta, dt, seconds=3 * dt if dt > 1 else 4.0)
    if abs(zeta - 1) < 1e-6:
        ref = (1 + w * t) * np.exp(-w * t)
    else:
        b = w * np.sqrt(zeta**2 - 1)
        r1, r2 = -zeta * w + b, -zeta * w - b
        ref = (r1 * np.exp(r2 * t) - r2 * np.exp(r1 * t)) / (r1 - r2)
    assert np.all(np.isfinite(x))
    np.testing.assert_allclose(x, ref, rtol=1e-7, atol=1e-12)


def test_unit_static_gain():
    for integ in ("exact", "euler"):
        _, x = run(0.9, 0.2, 1 / 60, 30.0, integrator=integ, p0=0.0, g=3.5)
        assert x[-1] == pytest.approx(3.5, rel=1e-6)


@pytest.mark.parametrize("zeta", [0.0, 0.03, 0.3, 1.0, 3.0])
@pytest.mark.parametrize("dt", [5.0, 1e4, 1e9])
def test_one_long_step_cannot_blow_up(zeta, dt):
    f = np.array([0.3, 1.0, 2.8])
    z = np.full(3, zeta)
    p = np.array([1.0, -2.0, 0.5])
    pd = np.array([10.0, 0.0, -3.0])
    g = np.array([0.2, 0.0, -1.0])
    e0 = (p - g) ** 2 + (pd / (2 * np.pi * f)) ** 2  # energy about the static point, in L′²
    exact_step(p, pd, g, exact_coefficients(f, z, dt))
    e1 = (p - g) ** 2 + (pd / (2 * np.pi * f)) ** 2
    assert np.all(np.isfinite(p)) and np.all(np.isfinite(pd))
    assert np.all(e1 <= e0 * (1 + 1e-6))  # a damped oscillator never gains energy


def test_euler_agrees_with_exact_at_small_dt():
    for f, zeta in [(0.75, 0.045), (1.6, 0.12)]:
        t, xe = run(f, zeta, 1 / 1000, 10.0, integrator="exact")
        _, xu = run(f, zeta, 1 / 1000, 10.0, integrator="euler")
        assert np.max(np.abs(xe - xu)) < 5e-3  # O(ωh) phase error of a first-order scheme
        fm, zm = fit_decay(t, xu)
        assert fm == pytest.approx(f, rel=1e-3)
        assert zm == pytest.approx(zeta, rel=2e-2)


def test_euler_substeps_bound_omega_h_and_clamp_huge_steps():
    for f, dt in [(1.0, 1 / 60), (2.8, 0.1), (0.4, 1e-4)]:
        n, h = euler_substeps(f, dt)
        assert 2 * np.pi * f * h <= EULER_OMEGA_H * (1 + 1e-12)
        assert n * h == pytest.approx(dt)
    n, h = euler_substeps(2.0, 1e6)
    assert n == EULER_MAX_SUBSTEPS and 2 * np.pi * 2.0 * h == pytest.approx(EULER_OMEGA_H)
    t, x = run(1.0, 0.0, 1e6, 2e6, integrator="euler")  # clamped, never unstable
    assert np.all(np.isfinite(x)) and np.max(np.abs(x)) < 1.5
