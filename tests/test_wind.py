"""The paper's 3-D 1/f^β wind field, WindField(model="paper") (§4.3, Eqs. 13–18; docs/design.md §7).

Everything here is measured from what the code produces: spectra from the noise grids,
profiles and directions from many samples, and the sampler against an independent
reference built on scipy.ndimage.map_coordinates.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from scipy import stats
from scipy.ndimage import map_coordinates

from treeanim.physics.wind import WindField as _WindField
from treeanim.physics.wind import fbm_noise


def WindField(*args, **kwargs) -> _WindField:  # noqa: N802 - the paper's field, by its name
    """The paper's field (these tests check Eqs. 13–18)."""
    return _WindField(*args, **{"model": "paper", **kwargs})

BETAS = (1.0, 1.33, 1.67, 2.0)


def test_paper_model_reproduces_the_recorded_samples_bit_for_bit():
    """tests/data/make_wind_paper_reference.py recorded these at 3e9ef3c, before issue 11."""
    import sys
    from pathlib import Path

    data = Path(__file__).with_name("data")
    sys.path.insert(0, str(data))
    try:
        import make_wind_paper_reference as ref_script
    finally:
        sys.path.remove(str(data))
    ref = np.load(data / "wind_paper_reference.npz")
    np.testing.assert_array_equal(ref["points"], ref_script.points())
    for name, kw in ref_script.CASES.items():
        wind = _WindField(model="paper", **kw)
        got = np.stack([wind.sample(ref["points"], t) for t in ref["times"]])
        np.testing.assert_array_equal(got, ref[name], err_msg=name)


# ----------------------------------------------------------------------------- helpers


def axis_spectrum(field: np.ndarray, axis: int) -> np.ndarray:
    """Periodogram along ``axis``, averaged over all lines parallel to it; k = 0 … n/2."""
    f = np.fft.rfft(field, axis=axis)
    p = np.abs(f) ** 2
    other = tuple(a for a in range(3) if a != axis)
    return p.mean(axis=other)


def loglog_slope(spectrum: np.ndarray, k_lo: int, k_hi: int) -> float:
    k = np.arange(k_lo, k_hi + 1)
    return float(np.polyfit(np.log(k), np.log(spectrum[k]), 1)[0])


def reference_wind(wind: WindField, p: np.ndarray, t: float) -> np.ndarray:
    """Eqs. 16–18 written out independently, trilinear by scipy (periodic 'grid-wrap')."""
    g = wind.grids
    n = wind.grid
    lo, hi = wind.bounds
    scaled = (p - lo) / (hi - lo) * (n - 1)  # [0, 1]³ then × (N − 1)
    u, v, w = wind.frame
    q = np.stack([scaled @ u - wind.c5 * t, scaled @ v, scaled @ w - wind.c6 * t])
    fbm = np.stack([map_coordinates(g[c], q, order=1, mode="grid-wrap") for c in range(3)])
    up = np.stack([fbm[0] + 0.5, wind.c3 * fbm[1], wind.c4 * fbm[2]])
    s1 = math.sqrt(1 + wind.c3**2 / 4 + wind.c4**2 / 4)
    s2 = np.sqrt((up**2).sum(0))
    h = p[:, 1]
    big_w = np.where(wind.c2 * h > 1, wind.c1 * np.log(np.maximum(wind.c2 * h, 1.0)), 0.0)
    s = big_w * (1 + wind.turbulence * (s2 / s1 - 0.5)) / s2
    comps = s * up
    return wind.speed * (comps[0][:, None] * u + comps[1][:, None] * v + comps[2][:, None] * w)


def uniform_points(wind: WindField, k: int, seed: int) -> np.ndarray:
    lo, hi = wind.bounds
    return np.random.default_rng(seed).uniform(lo, hi, (k, 3))


def world_step(wind: WindField, cells: np.ndarray) -> np.ndarray:
    """World displacement that moves a point by ``cells`` (a world-axis vector of grid units)."""
    lo, hi = wind.bounds
    return cells * (hi - lo) / (wind.grid - 1)


# ----------------------------------------------------------------------------- fbm_noise


@pytest.mark.parametrize("n,beta,seed", [(32, 1.67, 0), (32, 1.33, 7), (17, 2.0, 3), (64, 1.0, 1)])
def test_fbm_shape_dtype_and_exact_range(n, beta, seed):
    f = fbm_noise(n, beta, seed)
    assert f.shape == (n, n, n)
    assert f.dtype == np.float64
    assert f.min() == -0.5
    assert f.max() == 0.5
    assert np.all(np.isfinite(f))


@pytest.mark.parametrize("beta", BETAS)
def test_fbm_mean_is_near_zero(beta):
    # The field has zero mean before the min/max map onto [−0.5, 0.5]; that affine map
    # shifts it by −(max + min)/(2 (max − min)), small but not zero for one seed.
    means = np.array([fbm_noise(32, beta, s).mean() for s in range(16)])
    assert np.median(np.abs(means)) < 0.05
    assert np.abs(means).max() < 0.15
    assert abs(means.mean()) < 0.03  # no systematic bias across seeds


@pytest.mark.parametrize("beta", BETAS)
def test_fbm_one_dimensional_spectrum_falls_off_as_k_to_minus_beta(beta):
    # The 3-D power |k|^−(β+2) summed over two transverse wavenumbers gives k^−β in 1-D.
    # On a finite grid that sum stops at Nyquist, which steepens the spectrum towards
    # k = n/2, so the fit uses the band k = 2 … n/8 where the asymptotic law holds.
    n = 128
    f = fbm_noise(n, beta, seed=11)
    spectrum = np.mean([axis_spectrum(f, a) for a in range(3)], axis=0)
    slope = loglog_slope(spectrum, 2, n // 8)
    assert slope == pytest.approx(-beta, abs=0.15)
    # and each axis alone (isotropy)
    for a in range(3):
        assert loglog_slope(axis_spectrum(f, a), 2, n // 8) == pytest.approx(-beta, abs=0.15)


@pytest.mark.parametrize("beta", BETAS)
def test_fbm_amplitude_is_exactly_k_to_minus_beta_plus_2_over_2(beta):
    # Averaged over lines, the 1-D periodogram equals Σ over the transverse wavenumbers of
    # the 3-D power |k|^−(β+2) (Parseval), whatever the phases: a check of Eq. 14 itself.
    n = 64
    f = fbm_noise(n, beta, seed=4)
    k = np.fft.fftfreq(n, 1.0 / n)
    kk = np.sqrt(k[:, None, None] ** 2 + k[None, :, None] ** 2 + k[None, None, :] ** 2)
    with np.errstate(divide="ignore"):
        power = kk ** -(beta + 2.0)
    power[0, 0, 0] = 0.0
    predicted = power.sum(axis=(1, 2))[: n // 2 + 1]
    for a in range(3):
        measured = axis_spectrum(f, a)
        ratio = measured[1:] / predicted[1:]
        assert np.ptp(ratio) / ratio.mean() < 1e-6


def test_fbm_phases_are_uniform():
    f = fbm_noise(32, 1.67, seed=5)
    spec = np.fft.rfftn(f)[:, :, 1:16]  # away from the self-conjugate planes (real there)
    phases = np.angle(spec).ravel()
    assert stats.kstest(phases, stats.uniform(-np.pi, 2 * np.pi).cdf).pvalue > 1e-3


def test_fbm_is_deterministic_per_seed_and_differs_across_seeds():
    a = fbm_noise(32, 1.33, seed=3)
    b = fbm_noise(32, 1.33, seed=3)
    c = fbm_noise(32, 1.33, seed=4)
    assert np.array_equal(a, b)
    assert abs(np.corrcoef(a.ravel(), c.ravel())[0, 1]) < 0.5
    assert not np.allclose(a, c)


def test_fbm_smaller_beta_is_rougher():
    rough = fbm_noise(32, 1.0, seed=2)
    smooth = fbm_noise(32, 2.0, seed=2)
    assert np.abs(np.diff(rough, axis=0)).mean() > 1.3 * np.abs(np.diff(smooth, axis=0)).mean()


@pytest.mark.parametrize(
    "kwargs,name",
    [
        (dict(n=1), "n"),
        (dict(n=2.5), "n"),
        (dict(n="32"), "n"),
        (dict(n=1000), "n"),
        (dict(beta=float("nan")), "beta"),
        (dict(beta=float("inf")), "beta"),
        (dict(beta=50.0), "beta"),
        (dict(seed=-1), "seed"),
        (dict(seed="x"), "seed"),
    ],
)
def test_fbm_refuses_bad_input(kwargs, name):
    args = dict(n=8, beta=1.0, seed=0) | kwargs
    with pytest.raises(ValueError, match=name):
        fbm_noise(**args)


def test_fbm_extreme_finite_betas_stay_finite():
    for beta in (-10.0, -3.0, 0.0, 10.0):
        f = fbm_noise(16, beta, seed=1)
        assert np.all(np.isfinite(f)) and f.min() == -0.5 and f.max() == 0.5


# ----------------------------------------------------------------------------- the grids


def test_wind_grids_are_three_independent_fbm_streams():
    wind = WindField(grid=16, beta_u=1.67, beta_vw=1.33, seed=9)
    g = wind.grids
    assert g.shape == (3, 16, 16, 16)
    assert np.array_equal(g[0], fbm_noise(16, 1.67, (9, 0)))
    assert np.array_equal(g[1], fbm_noise(16, 1.33, (9, 1)))
    assert np.array_equal(g[2], fbm_noise(16, 1.33, (9, 2)))
    assert abs(np.corrcoef(g[1].ravel(), g[2].ravel())[0, 1]) < 0.5
    with pytest.raises(ValueError):
        g[0, 0, 0, 0] = 1.0  # read-only


# ----------------------------------------------------------------------------- sampling


@pytest.mark.parametrize("direction", [(1, 0, 0), (0, 0, 1), (-1, 0, -1), (3, 0.8, -2)])
def test_sample_matches_independent_reference(direction):
    wind = WindField(direction=direction, speed=7.0, seed=3, turbulence=1.8, c3=0.7, c4=0.9)
    p = uniform_points(wind, 3000, seed=1)
    p[:500] *= 3.0  # well outside the bounds too (periodic)
    for t in (0.0, 0.37, 12.3, -4.0):
        got = wind.sample(p, t)
        want = reference_wind(wind, p, t)
        assert got.shape == (3000, 3)
        np.testing.assert_allclose(got, want, rtol=0, atol=2e-5 * np.abs(want).max())


def test_trilinear_reproduces_grid_values_at_grid_points():
    wind = WindField(grid=8, seed=2, c3=0.6, c4=0.8, c5=4.0, c6=2.0, turbulence=1.2)
    n = wind.grid
    g = wind.grids
    idx = np.stack(np.meshgrid(*(np.arange(n),) * 3, indexing="ij"), -1).reshape(-1, 3)
    idx = idx[idx[:, 1] > 0]  # W = 0 on the ground
    p = wind.bounds[0] + world_step(wind, idx.astype(float))
    # t = 1.5 s moves the turbulence by whole cells: c5 t = 6, c6 t = 3.
    for t, shift in ((0.0, (0, 0)), (1.5, (6, 3))):
        got = wind.sample(p, t)
        i = (idx[:, 0] - shift[0]) % n
        k = (idx[:, 2] - shift[1]) % n
        up = np.stack([g[0][i, idx[:, 1], k] + 0.5, 0.6 * g[1][i, idx[:, 1], k],
                       0.8 * g[2][i, idx[:, 1], k]])
        # Invert Eq. 17–18 by hand: the direction of U is that of U', its size fixes s2.
        s1 = math.sqrt(1 + 0.36 / 4 + 0.64 / 4)
        s2 = np.sqrt((up**2).sum(0))
        h = p[:, 1]
        big_w = np.log(wind.c2 * h) / np.log(wind.c2 * wind.bounds[1, 1])
        size = wind.speed * big_w * (1 + 1.2 * (s2 / s1 - 0.5))
        want = (size / s2) * up  # frame of (1, 0, 0) is the world frame
        np.testing.assert_allclose(got, want.T, rtol=1e-5, atol=1e-6)


@pytest.mark.parametrize("direction", [(1, 0, 0), (0, 0, -1), (2, 0, 1), (-1, 0, 3)])
def test_field_is_periodic_along_and_across_the_wind(direction):
    wind = WindField(direction=direction, seed=5)
    u, v, w = wind.frame
    n = wind.grid
    p = uniform_points(wind, 400, seed=2)
    base = wind.sample(p, 1.7)
    for axis in (u, w, u - 2 * w):
        shifted = wind.sample(p + world_step(wind, n * axis), 1.7)
        np.testing.assert_allclose(shifted, base, atol=1e-4 * np.abs(base).max())
    # vertically the noise repeats too; only the mean profile W(h) differs.
    up = p + world_step(wind, n * v)
    ok = wind.profile(p[:, 1]) > 0.05
    ratio = wind.profile(up[ok, 1]) / wind.profile(p[ok, 1])
    np.testing.assert_allclose(
        wind.sample(up, 1.7)[ok], base[ok] * ratio[:, None], atol=1e-4 * np.abs(base).max()
    )


def test_field_is_continuous_across_cell_faces_and_the_periodic_seam():
    wind = WindField(seed=6)
    n = wind.grid
    rng = np.random.default_rng(3)
    cells = rng.uniform(0, n - 1, (300, 3))
    cells[:, 1] = rng.uniform(3, n - 1, 300)
    for axis in (0, 1, 2):
        for face in (5.0, n - 1.0, float(n), 0.0):  # interior face, last cell, seam, origin
            c = cells.copy()
            c[:, axis] = face
            eps = np.zeros(3)
            eps[axis] = 1e-7
            lo = wind.sample(wind.bounds[0] + world_step(wind, c - eps), 0.0)
            hi = wind.sample(wind.bounds[0] + world_step(wind, c + eps), 0.0)
            assert np.abs(hi - lo).max() < 1e-4


def test_small_displacements_give_small_changes():
    wind = WindField(direction=(1, 0, 2), seed=8)
    p = uniform_points(wind, 2000, seed=4)
    p[:, 1] += 1.0  # away from the ground, where W(h) has its kink
    d = np.random.default_rng(5).normal(size=(2000, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    base = wind.sample(p, 0.3)
    change = [np.abs(wind.sample(p + eps * d, 0.3) - base).max() for eps in (1e-2, 1e-4, 1e-6)]
    assert change[0] < 0.2 * wind.speed
    assert change[1] < 0.05 * change[0]  # shrinks with the step: no jumps
    assert change[2] < 1e-3


def test_frozen_turbulence_moves_downwind_and_drifts_laterally():
    wind = WindField(direction=(-2, 0, 1), seed=4, c5=3.0, c6=0.7)
    u, _, w = wind.frame
    p = uniform_points(wind, 500, seed=6)
    dt = 1.3
    moved = p + world_step(wind, (wind.c5 * u + wind.c6 * w) * dt)
    np.testing.assert_allclose(wind.sample(moved, 5.0 + dt), wind.sample(p, 5.0), atol=1e-4)
    # and a point standing still sees the field change
    assert np.abs(wind.sample(p, 5.0 + dt) - wind.sample(p, 5.0)).max() > 0.5


def test_mean_profile_follows_the_log_law():
    heights = np.array([1.0, 2.0, 4.0, 7.0, 10.0])
    rng = np.random.default_rng(7)
    mean_speed = np.zeros(len(heights))
    seeds = range(16)  # each seed's noise differs per height slice; average it out
    for seed in seeds:
        wind = WindField(seed=seed)
        for j, h in enumerate(heights):
            p = np.column_stack(
                [rng.uniform(-5, 5, 1500), np.full(1500, h), rng.uniform(-5, 5, 1500)]
            )
            mean_speed[j] += np.mean(
                [np.linalg.norm(wind.sample(p, t), axis=1).mean() for t in np.linspace(0, 40, 8)]
            )
    mean_speed /= len(seeds)
    c1, c2 = wind.c1, wind.c2
    law = c1 * np.log(c2 * heights)
    np.testing.assert_allclose(mean_speed / mean_speed[-1], law / law[-1], rtol=0.08)
    # speed is (on average) the wind speed at the tree top
    assert 0.75 * wind.speed < mean_speed[-1] < 1.25 * wind.speed


def test_profile_is_one_at_the_top_and_zero_below_one_over_c2():
    wind = WindField(bounds=((-2, 0, -3), (4, 6, 1)))
    assert wind.profile(6.0) == pytest.approx(1.0)
    assert wind.c1 == pytest.approx(1.0 / math.log(wind.c2 * 6.0))
    h0 = 1.0 / wind.c2
    assert 0 < h0 < 0.05 * 6.0
    assert wind.profile(0.99 * h0) == 0.0
    assert wind.profile(-3.0) == 0.0
    p = np.array([[0.0, 0.5 * h0, 0.0], [1.0, 0.0, 0.0], [2.0, -5.0, 0.0]])
    assert np.array_equal(wind.sample(p, 1.0), np.zeros((3, 3)))
    assert np.abs(wind.sample([[0.0, 3.0, 0.0]], 1.0)).max() > 0
    # explicit constants
    fixed = WindField(c1=0.4, c2=10.0)
    assert fixed.profile(2.0) == pytest.approx(0.4 * math.log(20.0))


@pytest.mark.parametrize("direction", [(1, 0, 0), (0, 0, 1), (-1, 0, 1), (3, 0, -4), (1, 0.2, 0.5)])
def test_mean_wind_points_along_the_user_direction(direction):
    d = np.asarray(direction, float) / np.linalg.norm(direction)
    means = []
    for seed in range(8):
        wind = WindField(direction=direction, seed=seed)
        p = uniform_points(wind, 4000, seed=seed)
        u = np.concatenate([wind.sample(p, t) for t in np.linspace(0, 30, 6)])
        means.append(u.mean(axis=0))
    angles = [math.degrees(math.acos(np.clip(m @ d / np.linalg.norm(m), -1, 1))) for m in means]
    # one seed is off by the residual mean of its lateral / vertical grid (a few degrees)
    assert max(angles) < 12.0
    m = np.mean(means, axis=0)
    assert math.degrees(math.acos(m @ d / np.linalg.norm(m))) < 3.0


def _component_std(c3, c4, seed=2):
    wind = WindField(c3=c3, c4=c4, seed=seed)  # direction +x: v̂ = y, ŵ = z
    p = uniform_points(wind, 10000, seed=seed)
    u = np.concatenate([wind.sample(p, t) for t in np.linspace(0, 30, 6)])
    return u.std(axis=0)


def test_vertical_and_lateral_spread_scale_with_c3_and_c4():
    base = _component_std(0.5, 0.5)
    double_c3 = _component_std(1.0, 0.5)
    double_c4 = _component_std(0.5, 1.0)
    assert 1.6 < double_c3[1] / base[1] < 2.2
    assert 1.6 < double_c4[2] / base[2] < 2.2
    # the other components barely move
    assert 0.8 < double_c3[2] / base[2] < 1.1
    assert 0.8 < double_c4[1] / base[1] < 1.1
    zero = WindField(c3=0.0, c4=0.0, seed=2)
    u = zero.sample(uniform_points(zero, 1000, seed=1), 0.5)
    assert np.abs(u[:, 1:]).max() == 0.0
    assert np.all(u[:, 0] >= 0.0)


def test_frame_is_right_handed_with_lateral_horizontal():
    for d in [(1, 0, 0), (0, 0, 1), (1, 0.5, -2), (-3, -1, 0.2)]:
        wind = WindField(direction=d)
        u, v, w = wind.frame
        assert np.allclose(wind.frame @ wind.frame.T, np.eye(3))
        assert np.allclose(u, np.asarray(d) / np.linalg.norm(d))
        assert abs(w[1]) < 1e-12  # lateral is horizontal
        assert v[1] > 0  # vertical points up
        assert np.allclose(np.cross(u, v), w)
    assert np.allclose(WindField().frame, np.eye(3))  # +x wind: (u, v, w) = (x, y, z)


def test_turning_the_wind_turns_the_field():
    # With cubic bounds, rotating the direction and the points about the bounds' corner
    # about y rotates the velocities: the grid is sampled in the wind's own frame.
    a = WindField(direction=(1, 0, 0), seed=3)
    b = WindField(direction=(0, 0, -1), seed=3)
    angle = math.pi / 2  # +x → −z is a +90° turn about y
    rot = np.array(
        [[math.cos(angle), 0, math.sin(angle)], [0, 1, 0], [-math.sin(angle), 0, math.cos(angle)]]
    )
    assert np.allclose(rot @ [1, 0, 0], [0, 0, -1])
    lo = a.bounds[0]
    p = uniform_points(a, 500, seed=3)
    turned = lo + (p - lo) @ rot.T
    np.testing.assert_allclose(b.sample(turned, 0.8), a.sample(p, 0.8) @ rot.T, atol=1e-4)


def test_deterministic_per_seed_and_different_across_seeds():
    p = uniform_points(WindField(), 1000, seed=8)
    a = WindField(seed=21).sample(p, 3.0)
    b = WindField(seed=21).sample(p, 3.0)
    c = WindField(seed=22).sample(p, 3.0)
    assert np.array_equal(a, b)
    assert np.abs(a - c).mean() > 0.1


def test_speed_and_direction_change_without_rebuilding_grids():
    wind = WindField(seed=1)
    p = uniform_points(wind, 300, seed=9)
    before = wind.sample(p, 1.0)
    tables = wind._tables
    wind.speed = 10.0
    np.testing.assert_allclose(wind.sample(p, 1.0), 2 * before, rtol=1e-12)
    wind.direction = (0, 0, 1)
    wind.direction = (5, 0, 0)  # same direction, another length
    np.testing.assert_allclose(wind.sample(p, 1.0), 2 * before, rtol=1e-12)
    assert wind._tables is tables
    # the spectral parameters rebuild them
    wind.beta_u = 1.2
    assert not np.allclose(wind.sample(p, 1.0), 2 * before)
    wind.beta_u = 1.67
    np.testing.assert_allclose(wind.sample(p, 1.0), 2 * before, rtol=1e-12)
    wind.seed = 2
    assert not np.allclose(wind.sample(p, 1.0), 2 * before)
    wind.seed = 1
    wind.grid = 16
    assert wind.grids.shape == (3, 16, 16, 16)
    assert not np.allclose(wind.sample(p, 1.0), 2 * before)


def test_calm_and_shapes():
    wind = WindField(direction=(0, 0, 0))
    assert wind.calm
    assert np.array_equal(wind.sample([[1, 2, 3], [4, 5, 6]], 1.0), np.zeros((2, 3)))
    still = WindField(speed=0.0)
    assert np.array_equal(still.sample(uniform_points(still, 10, 1), 2.0), np.zeros((10, 3)))
    wind = WindField()
    assert wind.sample([0.0, 5.0, 0.0], 0.0).shape == (1, 3)
    assert wind.sample(np.empty((0, 3)), 0.0).shape == (0, 3)
    big = uniform_points(wind, 40000, seed=2)  # more than one internal chunk
    np.testing.assert_array_equal(wind.sample(big, 0.5)[-10:], wind.sample(big[-10:], 0.5))


def test_fit_adopts_the_tree_box_and_widens_flat_axes():
    wind = WindField()
    wind.fit(((-1.0, 0.0, -2.0), (3.0, 4.0, 2.0)))
    assert np.array_equal(wind.bounds, [[-1, 0, -2], [3, 4, 2]])
    assert wind.profile(4.0) == pytest.approx(1.0)
    # a straight vertical beam has no width: x and z are widened, the top is kept
    wind.fit(((0.0, 0.0, 0.0), (0.0, 2.0, 0.0)))
    b = wind.bounds
    assert np.allclose(b[:, 1], [0, 2]) and np.allclose(b[:, 0], [-0.1, 0.1])
    assert np.all(np.isfinite(wind.sample([[0.0, 1.0, 0.0]], 0.0)))
    for bad in (((0, 0, 0), (0, 0, 0)), ((1, 0, 0), (0, 1, 1)), ((0, np.nan, 0), (1, 1, 1))):
        with pytest.raises(ValueError, match="bounds"):
            wind.fit(bad)


# ----------------------------------------------------------------------------- bad input


NAN, INF = float("nan"), float("inf")


@pytest.mark.parametrize(
    "kwargs,name",
    [
        (dict(direction=(0, 1, 0)), "horizontal component"),
        (dict(direction=(0, -3, 0)), "horizontal component"),
        (dict(direction=(1e-9, 1, 0)), "horizontal component"),
        (dict(direction=(NAN, 0, 0)), "direction"),
        (dict(direction=(1, INF, 0)), "direction"),
        (dict(direction=(1, 0)), "direction"),
        (dict(direction="east"), "direction"),
        (dict(speed=-1.0), "speed"),
        (dict(speed=NAN), "speed"),
        (dict(speed=INF), "speed"),
        (dict(speed=1e4), "speed"),
        (dict(turbulence=0.5), "turbulence"),
        (dict(turbulence=2.5), "turbulence"),
        (dict(turbulence=NAN), "turbulence"),
        (dict(beta_u=NAN), "beta_u"),
        (dict(beta_u=INF), "beta_u"),
        (dict(beta_vw=NAN), "beta_vw"),
        (dict(beta_vw=-INF), "beta_vw"),
        (dict(c1=NAN), "c1"),
        (dict(c1=-0.5), "c1"),
        (dict(c2=0.0), "c2"),
        (dict(c2=-2.0), "c2"),
        (dict(c2=INF), "c2"),
        (dict(c1=0.5, c2=1e-320), "c2"),
        (dict(c2=0.05), "c2"),  # c2·H = 0.5 < 1: no positive profile at the top
        (dict(c3=NAN), "c3"),
        (dict(c3=-1.0), "c3"),
        (dict(c4=INF), "c4"),
        (dict(c5=NAN), "c5"),
        (dict(c6=INF), "c6"),
        (dict(grid=3), "grid"),
        (dict(grid=0), "grid"),
        (dict(grid=2.5), "grid"),
        (dict(grid="32"), "grid"),
        (dict(grid=100000), "grid"),
        (dict(seed=-1), "seed"),
        (dict(seed=1.5), "seed"),
        (dict(bounds=((0, 0, 0), (1, 0, 1))), "bounds"),
        (dict(bounds=((0, 0, 0), (1, 1, -1))), "bounds"),
        (dict(bounds=((0, 0, 0), (NAN, 1, 1))), "bounds"),
        (dict(bounds=((0, 0, 0), (INF, 1, 1))), "bounds"),
        (dict(bounds=(0, 0, 1, 1)), "bounds"),
        (dict(bounds=((-1, -5, -1), (1, -1, 1))), "bounds"),  # below the ground
    ],
)
def test_constructor_refuses_bad_input(kwargs, name):
    with pytest.raises(ValueError, match=name):
        WindField(**kwargs)


@pytest.mark.parametrize(
    "attr,value,name",
    [
        ("direction", (0, 2, 0), "horizontal component"),
        ("direction", (NAN, 0, 1), "direction"),
        ("speed", -0.1, "speed"),
        ("speed", NAN, "speed"),
        ("turbulence", 0.99, "turbulence"),
        ("turbulence", INF, "turbulence"),
        ("beta_u", NAN, "beta_u"),
        ("beta_vw", INF, "beta_vw"),
        ("c1", NAN, "c1"),
        ("c2", NAN, "c2"),
        ("c3", INF, "c3"),
        ("c4", NAN, "c4"),
        ("c5", INF, "c5"),
        ("c6", NAN, "c6"),
        ("grid", 2, "grid"),
        ("seed", -3, "seed"),
        ("bounds", ((0, 0, 0), (0, 1, 1)), "bounds"),
        ("bounds", ((0, 0, 0), (1, NAN, 1)), "bounds"),
    ],
)
def test_setters_refuse_bad_input_and_keep_the_old_value(attr, value, name):
    wind = WindField()
    p = uniform_points(wind, 50, seed=1)
    before = wind.sample(p, 0.5)
    with pytest.raises(ValueError, match=name):
        setattr(wind, attr, value)
    np.testing.assert_array_equal(wind.sample(p, 0.5), before)


@pytest.mark.parametrize(
    "points,t,name",
    [
        ([[0, NAN, 0]], 0.0, "points"),
        ([[INF, 1, 0]], 0.0, "points"),
        ([[0, 1]], 0.0, "points"),
        (np.zeros((2, 3, 3)), 0.0, "points"),
        ("here", 0.0, "points"),
        ([[0, 1, 0]], NAN, "t"),
        ([[0, 1, 0]], -INF, "t"),
        ([[0, 1, 0]], "now", "t"),
    ],
)
def test_sample_refuses_bad_input(points, t, name):
    for wind in (WindField(), WindField(speed=0.0)):  # calm too: bad input is still bad
        with pytest.raises(ValueError, match=name):
            wind.sample(points, t)


# ----------------------------------------------------------------------------- finiteness

_SHARED = WindField(seed=12)
_finite_float = st.floats(allow_nan=False, allow_infinity=False)


@settings(max_examples=200)
@given(
    direction=st.tuples(_finite_float, _finite_float, _finite_float),
    speed=st.floats(0.0, 60.0),
    points=st.lists(st.tuples(_finite_float, _finite_float, _finite_float), min_size=1,
                    max_size=20),
    t=_finite_float,
)
def test_any_finite_input_gives_a_finite_field(direction, speed, points, t):
    d = np.asarray(direction)
    big = np.abs(d).max()
    assume(big > 0)
    dn = d / big
    assume(math.hypot(dn[0], dn[2]) > 1e-5 * np.linalg.norm(dn))
    _SHARED.direction = direction
    _SHARED.speed = speed
    u = _SHARED.sample(points, t)
    assert u.shape == (len(points), 3)
    assert np.all(np.isfinite(u))
    if speed == 0.0:
        assert not u.any()


@settings(max_examples=60)
@given(
    c3=st.floats(0.0, 1000.0),
    c4=st.floats(0.0, 1000.0),
    c5=_finite_float,
    c6=_finite_float,
    turbulence=st.floats(1.0, 2.0),
    c1=st.floats(0.0, 1000.0),
    c2=st.floats(1e-12, 1e12),
    lo=st.tuples(*(st.floats(-1e6, 1e6),) * 3),
    size=st.tuples(*(st.floats(1e-3, 1e6),) * 3),
    t=_finite_float,
)
def test_any_valid_coefficients_give_a_finite_field(c3, c4, c5, c6, turbulence, c1, c2, lo,
                                                    size, t):
    lo = np.asarray(lo)
    hi = lo + np.asarray(size)
    assume(np.all(hi > lo))
    wind = WindField(grid=8, c1=c1, c2=c2, c3=c3, c4=c4, c5=c5, c6=c6, turbulence=turbulence,
                     bounds=(lo, hi), speed=1000.0)
    p = np.concatenate([np.random.default_rng(0).uniform(lo, hi, (20, 3)),
                        [[1e300, 1e300, -1e300], [-1e-300, 0.0, 5e-324]]])
    u = wind.sample(p, t)
    assert np.all(np.isfinite(u))
