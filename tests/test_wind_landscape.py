"""The physical wind over a landscape (issue 28): no spatial period, coherence that falls with
distance as measured wind's does, gusts that cross the scene at the wind speed.

Measured from the public API at canopy height over a 10 m canopy (the default box: the
length scale L is 10 m): correlations and coherences of time series at fixed points, lags of
cross-correlation peaks, autocorrelations of long spatial transects.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy import signal

from treeanim.physics.wind import WindField, wind_preset

H = 10.0  # the canopy height, and the length scale L


def series(wind: WindField, points, seconds: float, fs: float) -> np.ndarray:
    """(n, K, 3) samples at ``points`` every 1/fs s."""
    pts = np.asarray(points, dtype=float)
    return np.stack([wind.sample(pts, i / fs) for i in range(int(seconds * fs))])


def corr(a: np.ndarray, b: np.ndarray) -> float:
    a, b = a - a.mean(), b - b.mean()
    return float(a @ b / np.sqrt((a @ a) * (b @ b)))


def test_two_trees_20_m_apart_across_the_wind_and_any_farther_see_their_own_wind():
    """The along-wind speed at canopy height, 20 m apart across the wind: correlation below
    0.5 (0.08; 0.13 before); and so at every separation out to 1.5 km (now at most 0.04),
    where the old tile's period (6 L = 60 m) gave 1.000 at 60, 120, 240, 600 and 1,500 m."""
    fs, speed = 2.0, 8.0
    seps = [20.0, 40.0, 60.0, 80.0, 120.0, 240.0, 600.0, 1000.0, 1500.0]
    origins = [(0.0, 0.0), (37.0, -210.0), (-125.0, 60.0)]
    pts = [[x, H, z + dz] for x, z in origins for dz in [0.0] + seps]
    u = series(WindField(speed=speed, seed=3), pts, 1800.0, fs)[..., 0].reshape(-1, len(origins), len(seps) + 1)
    r = {d: np.mean([corr(u[:, k, 0], u[:, k, i + 1]) for k in range(len(origins))]) for i, d in enumerate(seps)}
    assert r[20.0] < 0.5, r
    assert max(r.values()) < 0.5, r


def test_no_two_points_1_to_2_km_apart_repeat():
    """Time series at 40 pairs of points 1–2 km apart in every direction, and at four pairs
    whole periods of the old tile apart (8 L along, 6 L across): no pair correlates (now at
    most 0.08; before 1.000 at the periods, up to 0.66 at the random pairs)."""
    fs = 2.0
    rng = np.random.default_rng(5)
    a = np.column_stack([rng.uniform(-1000, 1000, 40), np.full(40, H), rng.uniform(-1000, 1000, 40)])
    angle, dist = rng.uniform(0, 2 * np.pi, 40), rng.uniform(1000.0, 2000.0, 40)
    b = a + np.column_stack([dist * np.cos(angle), np.zeros(40), dist * np.sin(angle)])
    steps = np.array([[0.0, 0, 60 * 17], [80.0 * 13, 0, 0], [80.0 * 15, 0, 60 * 20], [80.0 * 12, 0, -60.0 * 16]])
    a = np.vstack([a, np.tile([[3.0, H, -7.0]], (4, 1))])
    b = np.vstack([b, a[-4:] + steps])
    x = series(WindField(speed=8.0, seed=3), np.vstack([a, b]), 900.0, fs)
    n = len(a)
    worst = max(abs(corr(x[:, i, c], x[:, n + i, c])) for i in range(n) for c in range(3))
    assert worst < 0.3, worst


@pytest.mark.parametrize("t", [0.0, 1000.0])
@pytest.mark.parametrize("axis", [0, 2])
def test_a_transect_2_km_long_has_no_period(axis, t):
    """The wind at one moment along a line 4 km long, along or across the wind: its
    autocorrelation has no peak beyond 3 L (30 m) out to 2 km (now at most 0.12; before 0.98
    at every whole period of the old tile)."""
    wind = WindField(speed=8.0, seed=11, gust_strength=0.0)
    s = np.arange(0.0, 4000.0, 0.5)
    p = np.zeros((s.size, 3))
    p[:, 1], p[:, axis] = H, s - 2000.0
    x = wind.sample(p, t)
    for c in range(3):
        y = x[:, c] - x[:, c].mean()
        ac = signal.correlate(y, y, "full")[y.size - 1:] / (y @ y)
        far = (s >= 3 * H) & (s <= 2000.0)
        assert ac[far].max() < 0.5, (c, s[far][np.argmax(ac[far])], ac[far].max())


def test_coherence_across_the_wind_falls_with_distance_as_davenports():
    """Points 2, 5, 10, 20 and 40 m apart across the wind in the default wind at 8 m/s: the
    correlation of the along-wind speed and its coherence between 0.1 and 0.3 Hz fall with
    distance to nothing at 40 m, and at 10 m the coherence lies within a factor of two of
    Davenport's exp(−2a·f·Δ/U) for a between 7 and 10 (REALISM.md), 0.008–0.092 here: 0.03
    (before 0.15, the old tile's few across-wind modes and the gusts' fronts across the whole
    landscape keeping it high)."""
    fs, speed, seconds = 2.0, 8.0, 3600.0
    seps = [2.0, 5.0, 10.0, 20.0, 40.0]
    origins = [(0.0, 0.0), (55.0, 300.0), (-230.0, -120.0), (410.0, -640.0)]
    pts = [[x, H, z + dz] for x, z in origins for dz in [0.0] + seps]
    u = series(WindField(speed=speed, seed=4), pts, seconds, fs)[..., 0]
    u = u.reshape(-1, len(origins), len(seps) + 1)
    nper = int(64 * fs)
    f = signal.coherence(u[:, 0, 0], u[:, 0, 1], fs=fs, nperseg=nper)[0]
    band = (f >= 0.1) & (f <= 0.3)
    coh = [np.mean([signal.coherence(u[:, k, 0], u[:, k, i + 1], fs=fs, nperseg=nper)[1][band]
                    for k in range(len(origins))]) for i in range(len(seps))]
    r = [np.mean([corr(u[:, k, 0], u[:, k, i + 1]) for k in range(len(origins))]) for i in range(len(seps))]
    assert r[0] > r[1] > r[2] > r[3] and abs(r[4]) < 0.1, r
    floor = 2.0 / (2 * seconds / 64)  # bias of the estimate where there is no coherence
    assert coh[0] > coh[1] > coh[2] > coh[3] and coh[3] < floor + 0.02 and coh[4] < floor + 0.02, coh
    davenport = [np.mean(np.exp(-2 * a * f[band] * 10.0 / speed)) for a in (10.0, 7.0)]
    assert 0.5 * davenport[0] < coh[2] < 2.0 * davenport[1], (coh, davenport)


@pytest.mark.parametrize("speed", [5.0, 15.0])
def test_a_gust_front_takes_d_over_u_to_cross_the_scene(speed):
    """Gusts (no turbulence) at points 50, 100 and 200 m downwind of one another, inside a
    lane of gusts and where two lanes blend: the cross-correlation peaks d/U later, the gusts
    carried across the scene at the wind speed."""
    fs = 10.0
    wind = WindField(speed=speed, seed=6, turbulence=0.0)
    for z in (0.0, 11.0, 47.0):
        pts = [[x, H, z] for x in (-100.0, -50.0, 0.0, 100.0)]
        u = series(wind, pts, 600.0, fs)[..., 0]
        u -= u.mean(axis=0)
        for i, d in ((1, 50.0), (2, 100.0), (3, 200.0)):
            cc = signal.correlate(u[:, i], u[:, 0], "full")
            lags = (np.arange(cc.size) - (len(u) - 1)) / fs
            assert lags[np.argmax(cc)] == pytest.approx(d / speed, abs=1.5 / fs), (z, d)


def test_far_across_the_wind_other_gusts_come():
    """Gusts alone (no turbulence): points 1 km apart across the wind see gusts of their own
    (correlation 0.07–0.09; before, every gust was one front across the whole landscape:
    1.000), while points 5 m apart inside one lane (lanes 1.5 L_g = 60 m wide) see the same
    gusts."""
    fs = 4.0
    wind = WindField(speed=8.0, seed=9, turbulence=0.0, gust_strength=1.0, gust_rate=6.0)
    pts = [[0.0, H, 11.0], [0.0, H, 1011.0], [0.0, H, -1489.0], [0.0, H, 16.0]]
    u = series(wind, pts, 1200.0, fs)[..., 0]
    assert abs(corr(u[:, 0], u[:, 1])) < 0.2 and abs(corr(u[:, 0], u[:, 2])) < 0.2
    assert corr(u[:, 0], u[:, 3]) > 0.9


def test_the_blocks_join_without_a_seam_in_space_or_time():
    """The wind is continuous: along lines 800 m long across and along the wind, and at
    points over 200 s, a step of 10 µm or 1 µs changes it by float32 rounding only."""
    wind = WindField(speed=8.0, seed=3, direction=(1.0, 0.0, 0.3))
    for axis in (0, 2):
        p = np.zeros((60000, 3))
        p[:, 1], p[:, axis] = 9.0, np.linspace(-400.0, 400.0, 60000)
        q = p.copy()
        q[:, axis] += 1e-5
        assert np.abs(wind.sample(q, 3.3) - wind.sample(p, 3.3)).max() < 5e-4
    p = np.random.default_rng(0).uniform((-50, 1, -50), (50, 20, 50), (500, 3))
    jumps = [np.abs(wind.sample(p, t + 1e-6) - wind.sample(p, t)).max() for t in np.linspace(0.0, 200.0, 2001)]
    assert max(jumps) < 5e-4


def test_a_gale_sends_gusts_across_a_young_woodland_that_trees_16_m_downwind_repeat():
    """The along-wind speed at the top of a 2.5 m canopy (the woodland's saplings) in a gale,
    averaged over a second (a sapling's sway period, REALISM.md: saplings sway at 0.6–0.8 Hz,
    so they follow the wind averaged so), at points on a 4 m grid over 64 m × 64 m: each
    point's speed correlates with the point's 16 m upwind at its peak d/U later, at 0.56
    (0.47–0.56 over six seeds; before 0.05, gusts of the canopy's scale, 6 m long, lost in
    the turbulence), held above 0.4: with the turbulence uncorrelated 16 m apart,
    r = σ_g²/(σ_g² + σ_t²), so the gusts that travel are at least two-thirds as strong in
    variance as the turbulence that does not."""
    fs, h, d = 10.0, 2.5, 16.0
    wind = WindField(**wind_preset("gale"), canopy_height=h, seed=1)
    speed = wind.speed
    grid = np.arange(-30.0, 32.0, 4.0)
    pts = [[x, h, z] for x in grid for z in grid]
    u = series(wind, pts, 300.0, fs)[..., 0]
    u = signal.convolve(u, np.ones((int(fs), 1)) / fs, "valid").reshape(-1, grid.size, grid.size)
    up, down = u[:, :-4].reshape(len(u), -1), u[:, 4:].reshape(len(u), -1)  # 4 cells: 16 m
    up, down = up - up.mean(0), down - down.mean(0)
    cc = sum(signal.correlate(down[:, i], up[:, i], "full") for i in range(up.shape[1]))
    lags = (np.arange(cc.size) - (len(u) - 1)) / fs
    peak = np.argmax(cc)
    assert lags[peak] == pytest.approx(d / speed, abs=1.5 / fs)
    r = cc[peak] / np.sqrt(np.sum(up * up) * np.sum(down * down))
    assert r > 0.4, r
