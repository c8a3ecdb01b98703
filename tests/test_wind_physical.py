"""The physical wind field, WindField(model="physical") (issue 11, docs/design.md §12).

Everything is measured from time series the field produces at fixed points: advection lags
by cross-correlation, spectra by Welch and a log-log fit, autocorrelations, intensities,
mean profiles and mean directions over long runs.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import signal

import treeanim as ta
from treeanim.physics.wind import WIND_PRESETS, WindField, wind_preset

H = 10.0  # the default canopy height (top of the default bounds)


def series(wind: WindField, points, seconds: float, fs: float) -> np.ndarray:
    """(n, K, 3) samples at ``points`` every 1/fs s."""
    pts = np.asarray(points, dtype=float)
    return np.stack([wind.sample(pts, i / fs) for i in range(int(seconds * fs))])


def across(x: float, y: float, n: int = 8, spread: float = 60.0) -> np.ndarray:
    """n points at (x, y, z) spread across a +x wind."""
    return np.array([[x, y, z] for z in np.linspace(-spread / 2, spread / 2, n)])


def fitted_slope(x: np.ndarray, fs: float, lo: float = 0.05, hi: float = 2.0) -> float:
    f, p = signal.welch(x, fs=fs, nperseg=int(80 * fs), axis=0)
    p = p.reshape(len(f), -1).mean(axis=1)
    m = (f >= lo) & (f <= hi)
    return float(np.polyfit(np.log(f[m]), np.log(p[m]), 1)[0])


def lag_of_peak(a: np.ndarray, b: np.ndarray, fs: float) -> float:
    """Lag (s) by which b follows a, from the cross-correlation summed over columns."""
    a = a - a.mean(0)
    b = b - b.mean(0)
    n = a.shape[0]
    cc = sum(signal.correlate(b[:, i], a[:, i], "full") for i in range(a.shape[1]))
    lags = (np.arange(cc.size) - (n - 1)) / fs
    return float(lags[np.argmax(cc)])


# ----------------------------------------------------------------------------- Taylor


@pytest.mark.parametrize("speed", [4.0, 12.0])
def test_a_gust_reaches_a_point_6_m_downwind_6_over_u_seconds_later(speed):
    fs = 50.0
    wind = WindField(speed=speed, seed=2, gust_strength=0.0)
    up = series(wind, across(0.0, H), 60.0, fs)[..., 0]
    down = series(wind, across(6.0, H), 60.0, fs)[..., 0]
    assert lag_of_peak(up, down, fs) == pytest.approx(6.0 / speed, abs=1.5 / fs)


def test_gusts_come_faster_in_stronger_wind():
    fs = 20.0
    times = []
    for speed in (4.0, 12.0):
        x = series(WindField(speed=speed, seed=5, gust_strength=0.0), across(0.0, H), 300.0, fs)
        u = x[..., 0] - x[..., 0].mean(0)
        ac = sum(signal.correlate(u[:, i], u[:, i], "full")[len(u) - 1:] for i in range(8))
        ac /= ac[0]
        times.append(np.argmax(ac < 0.5) / fs)  # time to decorrelate to 0.5
    assert times[0] / times[1] == pytest.approx(3.0, rel=0.25)


def test_the_field_is_independent_of_the_tree_box_but_for_the_canopy_height():
    a = WindField(seed=4)
    b = WindField(seed=4)
    b.fit(((-40.0, 0.0, -3.0), (2.0, 10.0, 90.0)))  # another box, the same top
    p = np.random.default_rng(0).uniform((-20, 0, -20), (20, 15, 20), (500, 3))
    for t in (0.0, 3.3, 100.0):
        np.testing.assert_array_equal(a.sample(p, t), b.sample(p, t))
    b.fit(((-1.0, 0.0, -1.0), (1.0, 3.0, 1.0)))
    assert b.canopy_height == 3.0 and b.length_scale == 3.0


# ----------------------------------------------------------------------------- no loop


@pytest.mark.parametrize("speed", [5.0, 20.0])
def test_nothing_repeats_within_ten_minutes(speed):
    fs = 4.0
    x = series(WindField(speed=speed, seed=8), across(0.0, H, n=4), 1500.0, fs)
    for c in range(3):
        for i in range(4):
            y = x[:, i, c] - x[:, i, c].mean()
            ac = signal.correlate(y, y, "full")[len(y) - 1:] / (y @ y)
            lags = np.arange(len(y)) / fs
            far = (lags >= 20.0) & (lags <= 600.0)
            assert ac[far].max() < 0.3, (c, i, lags[far][np.argmax(ac[far])], ac[far].max())


# ----------------------------------------------------------------------------- spectrum


@pytest.mark.parametrize("beta_u,beta_vw", [(5 / 3, 5 / 3), (1.4, 2.0)])
def test_spectrum_at_a_point_follows_f_to_the_minus_beta(beta_u, beta_vw):
    fs = 10.0
    wind = WindField(speed=5.0, seed=1, gust_strength=0.0, beta_u=beta_u, beta_vw=beta_vw)
    x = series(wind, across(0.0, H), 1200.0, fs)
    assert fitted_slope(x[..., 0], fs) == pytest.approx(-beta_u, abs=0.2)
    assert fitted_slope(x[..., 1], fs) == pytest.approx(-beta_vw, abs=0.2)  # vertical
    assert fitted_slope(x[..., 2], fs) == pytest.approx(-beta_vw, abs=0.2)  # lateral
    # the inertial range alone, above the energy-containing eddies
    assert fitted_slope(x[..., 0], fs, 0.3, 2.0) == pytest.approx(-beta_u, abs=0.15)


@pytest.mark.parametrize("speed", [5.0, 12.0, 20.0])
def test_the_inertial_range_keeps_its_slope_as_the_wind_rises(speed):
    """Above the energy-containing eddies (f > 3·U / (2π·1.339·L), the von Kármán knee, which
    rises with U: 0.18 Hz at 5 m/s, 0.71 Hz at 20 m/s) the spectrum falls as f^−5/3 at every
    speed; below the knee it flattens, as measured spectra do."""
    fs = 10.0
    wind = WindField(speed=speed, seed=1, gust_strength=0.0)
    x = series(wind, across(0.0, H), 1200.0, fs)
    knee = speed / (2 * np.pi * 1.339 * wind.length_scale)
    assert fitted_slope(x[..., 0], fs, 3 * knee, 2.0) == pytest.approx(-5 / 3, abs=0.2)
    assert fitted_slope(x[..., 2], fs, 3 * knee, 2.0) == pytest.approx(-5 / 3, abs=0.2)
    if knee > 0.1:  # enough of the spectrum below the knee to fit: flatter there
        assert fitted_slope(x[..., 0], fs, 0.05, knee) > -1.0


# ----------------------------------------------------------------------------- profile


def test_intensities_at_the_canopy_top():
    fs = 5.0
    x = series(WindField(speed=8.0, seed=3, gust_strength=0.0), across(0.0, H), 1200.0, fs)
    s = x.std(axis=0).mean(axis=0) / 8.0  # (along, vertical, lateral)
    assert s[0] == pytest.approx(0.3, rel=0.1)
    assert s[0] > s[2] > s[1]
    assert s[2] / s[0] == pytest.approx(0.75, rel=0.12)
    assert s[1] / s[0] == pytest.approx(0.5, rel=0.12)
    # the default field, gusts included, is in the canopy-top range 0.2 - 0.5
    x = series(WindField(speed=8.0, seed=3), across(0.0, H), 1200.0, fs)
    assert 0.2 < x[..., 0].std(axis=0).mean() / 8.0 < 0.5


def test_canopy_profile_log_law_above_and_decay_inside():
    wind = WindField(speed=6.0, seed=6)
    h = np.array([1.0, 3.0, 5.0, 7.0, 9.0, 10.0, 12.0, 15.0, 20.0, 30.0])
    d, z0 = 0.7 * H, 0.1 * H
    want = np.where(h >= H, np.log((np.maximum(h, H) - d) / z0) / np.log((H - d) / z0),
                    np.exp((h / H - 1) / (0.3 * np.log(3.0))))
    np.testing.assert_allclose(wind.profile(h), want, rtol=1e-12)
    assert wind.profile(H) == pytest.approx(1.0)
    # measured: the mean along-wind speed over a long run follows the profile
    pts = np.array([[0.0, y, z] for y in h for z in (-20.0, 0.0, 20.0)])
    x = series(wind, pts, 900.0, 2.0)[..., 0].mean(axis=0).reshape(len(h), 3).mean(axis=1)
    np.testing.assert_allclose(x / 6.0, want, rtol=0.06)
    # the intensity rises into the canopy, along-wind σ falls
    sd = series(wind, pts, 300.0, 2.0)[..., 0].std(axis=0).reshape(len(h), 3).mean(axis=1)
    assert sd[0] < sd[5] and sd[0] / x[0] > sd[5] / x[5]


def test_a_lone_crown_stands_in_the_open_wind_and_a_closed_stand_shelters_its_inside():
    """The wind decays into a canopy at a rate in proportion to its cover: a lone tree's crown
    (a quarter of the ground around it) meets most of the wind, a closed stand's inside little."""
    from treeanim.physics.wind import canopy_cover

    lone = {name: canopy_cover(ta.load_preset(name).rest_positions) for name in ("small_cherry", "large_cherry",
                                                                                    "tulip_poplar")}
    woodland = canopy_cover(ta.load_scene("woodland").rest_positions)
    assert max(lone.values()) < 0.35 and woodland > 0.6, (lone, woodland)
    h = np.array([0.3, 0.5, 0.8]) * H
    for cover in (0.0, 0.3, 1.0):
        wind = WindField(speed=6.0, canopy_height=H, canopy_cover=cover)
        np.testing.assert_allclose(wind.profile(h), np.exp(cover * (h / H - 1) / (0.3 * np.log(3.0))), rtol=1e-12)
    # a Simulation measures its tree's cover: mid-crown gets 0.7 of the top's wind or more
    tree = ta.load_preset("large_cherry")
    sim = ta.Simulation(tree, wind=WindField(speed=6.0))
    assert sim.wind.canopy_cover == pytest.approx(lone["large_cherry"])
    top = tree.rest_positions[:, 1].max()
    assert sim.wind.profile(0.6 * top) > 0.7 > WindField(speed=6.0, canopy_height=top).profile(0.6 * top)
    with pytest.raises(ValueError, match="canopy_cover"):
        WindField(speed=6.0, canopy_cover=1.5)


# ----------------------------------------------------------------------------- direction


@pytest.mark.parametrize("seed", [0, 1, 2, 3, 4])
def test_mean_wind_points_where_set_per_seed(seed):
    d = np.array([1.0, 0.0, -0.6])
    wind = WindField(direction=d, speed=6.0, seed=seed)
    pts = np.random.default_rng(seed).uniform((-3, 6, -3), (3, 12, 3), (24, 3))  # a crown
    x = series(wind, pts, 3600.0, 2.0).reshape(-1, 3).mean(axis=0)  # over an hour
    angle = math.degrees(math.acos(x @ d / (np.linalg.norm(x) * np.linalg.norm(d))))
    assert angle < 1.0


# ----------------------------------------------------------------------------- gusts


def test_gusts_sweep_downwind_at_the_wind_speed_and_come_at_their_rate():
    fs, speed, rate = 20.0, 8.0, 6.0
    wind = WindField(speed=speed, seed=9, turbulence=0.0, gust_strength=1.0, gust_rate=rate)
    pts = [[0.0, H, 0.0], [20.0, H, 0.0]]
    x = series(wind, pts, 1200.0, fs)[..., 0]
    assert lag_of_peak(x[:, :1], x[:, 1:], fs) == pytest.approx(20.0 / speed, abs=1.5 / fs)
    # gusts per minute: peaks well above the lulls either side (gusts 40 m long, 80 m apart,
    # fill most of the time, so the lulls between them lie below the mean)
    peaks, _ = signal.find_peaks(x[:, 0], prominence=speed * 0.3, distance=int(2 * fs))
    assert len(peaks) / 20.0 == pytest.approx(rate, rel=0.25)
    assert x.mean() == pytest.approx(speed, rel=0.03)  # gusts and lulls about the mean
    # no turbulence, no gusts: the steady profile
    wind.gust_strength = 0.0
    np.testing.assert_allclose(wind.sample(pts, 3.0), [[speed, 0, 0]] * 2, atol=1e-9)


def test_deterministic_per_seed_and_a_pure_function_of_time():
    p = np.random.default_rng(1).uniform((-5, 0, -5), (5, 12, 5), (200, 3))
    ts = (0.0, 17.3, 2.5, 600.0, -3.0)
    a = [WindField(seed=7).sample(p, t) for t in ts]
    b = WindField(seed=7)
    for t, want in reversed(list(zip(ts, a))):
        np.testing.assert_array_equal(b.sample(p, t), want)
    assert np.abs(WindField(seed=8).sample(p, 17.3) - a[1]).mean() > 0.1


def test_changing_the_speed_keeps_the_field_continuous():
    wind = WindField(seed=3, gust_strength=0.0)
    p = np.random.default_rng(2).uniform((-5, 0, -5), (5, 12, 5), (100, 3))
    before = wind.sample(p, 40.0)
    wind.speed = 10.0  # twice: the same pattern, twice as fast, from t = 40 s on
    np.testing.assert_allclose(wind.sample(p, 40.0), 2 * before, rtol=1e-6, atol=1e-9)
    later = wind.sample(p, 40.5)
    assert np.abs(later - 2 * before).max() < 0.5 * np.abs(2 * before).max()


def test_calm_and_shapes():
    assert not WindField(speed=0.0).sample([[0, 5, 0], [1, 2, 3]], 1.0).any()
    assert not WindField(direction=(0, 0, 0)).sample([[0, 5, 0]], 1.0).any()
    wind = WindField()
    assert wind.sample([0.0, 5.0, 0.0], 0.0).shape == (1, 3)
    assert wind.sample(np.empty((0, 3)), 0.0).shape == (0, 3)
    big = np.random.default_rng(3).uniform((-9, 0, -9), (9, 12, 9), (40000, 3))
    np.testing.assert_array_equal(wind.sample(big, 0.5)[-10:], wind.sample(big[-10:], 0.5))


# ----------------------------------------------------------------------------- presets


def test_presets_follow_the_beaufort_scale():
    bands = {0: (0, 0.5), 1: (0.5, 1.5), 3: (3.4, 5.4), 5: (8.0, 10.7), 8: (17.2, 20.7),
             10: (24.5, 28.4)}
    speeds = []
    for name in ("calm", "breeze", "windy", "gale", "storm"):
        wind = WindField.from_preset(name, seed=1)
        lo, hi = bands[WIND_PRESETS[name]["beaufort"]]
        assert lo <= wind.speed <= hi and wind.model == "physical"
        speeds.append(wind.speed)
        assert wind_preset(name)["speed"] == wind.speed
    assert speeds == sorted(speeds)
    assert WindField.from_preset("gale", speed=3.0).speed == 3.0
    with pytest.raises(ValueError, match="wind preset"):
        wind_preset("hurricane")


def test_settings_rebuild_the_field():
    wind = WindField(seed=5, speed=7.0, length_scale=4.0, gust_rate=2.0, direction=(1, 0, 1))
    copy = WindField(**wind.settings())
    p = np.random.default_rng(4).uniform((-5, 0, -5), (5, 12, 5), (50, 3))
    np.testing.assert_array_equal(copy.sample(p, 2.0), wind.sample(p, 2.0))


# ----------------------------------------------------------------------------- bad input

NAN, INF = float("nan"), float("inf")


@pytest.mark.parametrize(
    "kwargs,name",
    [
        (dict(model="real"), "model"),
        (dict(model=None), "model"),
        (dict(turbulence=-0.1), "turbulence"),
        (dict(turbulence=1.5), "turbulence"),
        (dict(turbulence=NAN), "turbulence"),
        (dict(length_scale=0.0), "length_scale"),
        (dict(length_scale=-3.0), "length_scale"),
        (dict(length_scale=INF), "length_scale"),
        (dict(length_scale="big"), "length_scale"),
        (dict(canopy_height=0.0), "canopy_height"),
        (dict(canopy_height=NAN), "canopy_height"),
        (dict(canopy_height=1e6), "canopy_height"),
        (dict(gust_strength=-0.1), "gust_strength"),
        (dict(gust_strength=3.0), "gust_strength"),
        (dict(gust_strength=NAN), "gust_strength"),
        (dict(gust_rate=-1.0), "gust_rate"),
        (dict(gust_rate=100.0), "gust_rate"),
        (dict(gust_rate=INF), "gust_rate"),
        (dict(speed=-1.0), "speed"),
        (dict(beta_u=NAN), "beta_u"),
        (dict(direction=(0, 1, 0)), "horizontal component"),
    ],
)
def test_constructor_refuses_bad_input_in_one_line(kwargs, name):
    with pytest.raises(ValueError, match=name) as e:
        WindField(**kwargs)
    assert "\n" not in str(e.value)


@pytest.mark.parametrize(
    "attr,value",
    [("turbulence", 1.2), ("length_scale", -1.0), ("canopy_height", INF), ("gust_strength", NAN),
     ("gust_rate", 31.0), ("speed", NAN)],
)
def test_setters_refuse_bad_input_and_keep_the_old_value(attr, value):
    wind = WindField(seed=2)
    p = np.random.default_rng(1).uniform((-5, 0, -5), (5, 12, 5), (50, 3))
    before = wind.sample(p, 0.5)
    with pytest.raises(ValueError, match=attr):
        setattr(wind, attr, value)
    np.testing.assert_array_equal(wind.sample(p, 0.5), before)


_SHARED = WindField(seed=12)
_f = st.floats(allow_nan=False, allow_infinity=False)


@settings(max_examples=150)
@given(
    speed=st.floats(0.0, 1000.0),
    turbulence=st.floats(0.0, 1.0),
    length=st.floats(0.01, 1e4),
    height=st.floats(0.01, 1e4),
    gust_strength=st.floats(0.0, 2.0),
    gust_rate=st.floats(0.0, 30.0),
    points=st.lists(st.tuples(_f, _f, _f), min_size=1, max_size=10),
    t=_f,
)
def test_any_valid_input_gives_a_finite_field(speed, turbulence, length, height, gust_strength,
                                             gust_rate, points, t):
    w = _SHARED
    w.speed, w.turbulence, w.length_scale, w.canopy_height = speed, turbulence, length, height
    w.gust_strength, w.gust_rate = gust_strength, gust_rate
    u = w.sample(points, t)
    assert u.shape == (len(points), 3) and np.all(np.isfinite(u))
