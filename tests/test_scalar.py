"""The compiled passes' own scalar functions (physics/scalar.py) and the leaves' rotation by
them as vectors (leafjoint._laminas): numpy's and scipy's values to round-off, over the whole
range each is used on, the branches to libm included."""

from __future__ import annotations

import numpy as np
from numba import njit
from scipy.spatial.transform import Rotation

from treeanim.physics.leafjoint import _laminas
from treeanim.physics.scalar import SERIES_MAX, inv_cbrt, sin_turn, sinc_cos, sincos


@njit(cache=False)
def _each(x, which, out):
    for i in range(x.size):
        if which == 0:
            out[0, i], out[1, i] = sincos(x[i])
        elif which == 1:
            out[0, i], out[1, i] = sinc_cos(x[i] * x[i])
        elif which == 2:
            out[0, i] = sin_turn(x[i])
        else:
            out[0, i] = inv_cbrt(x[i])


def each(x, which):
    out = np.empty((2, x.size))
    _each(np.asarray(x, float), which, out)
    return out


def test_sines_and_cosines_are_numpys_to_round_off_on_every_branch():
    x = np.concatenate([np.linspace(-12.0, 12.0, 200001), [0.0, 1e-300, 0.5, -0.5, 1.6, -1.6, np.sqrt(SERIES_MAX)]])
    s, c = each(x, 0)
    assert np.abs(s - np.sin(x)).max() < 4.5e-16 and np.abs(c - np.cos(x)).max() < 4.5e-16
    sc, c = each(x, 1)  # sin x / x from x², its short series, its long one, libm's beyond
    ref = np.where(x == 0.0, 1.0, np.sin(x) / np.where(x == 0.0, 1.0, x))
    assert np.abs(sc - ref).max() < 4.5e-16 and np.abs(c - np.cos(x)).max() < 4.5e-16
    turn = np.linspace(0.0, 2 * np.pi, 100001)[:-1]  # the flutter's phase, folded without branches
    assert np.abs(each(turn, 2)[0] - np.sin(turn)).max() < 4.5e-16


def test_inverse_cube_root_is_numpys_to_a_few_ulps():
    rng = np.random.default_rng(1)
    x = np.concatenate([1.0 + rng.exponential(30.0, 100000) ** 2, np.geomspace(1e-300, 1e300, 100001),
                        [1.0, 8.0, 27.0, 1.0 + 2.0**-52]])
    y = each(x, 3)[0]
    assert np.abs(y * np.cbrt(x) - 1.0).max() < 1e-15


def test_every_leaf_turns_as_its_rotation_says_twists_past_the_series_included():
    """_laminas: each leaf's lever and normal turned by exp([θ₁b₁ + θ₂b₂]×)·exp(θ₀[a]×) (scipy),
    its bends up to the petiole's stop and its twists to 10 rad (past 3.2 rad the series give
    way to libm's sines for those leaves alone)."""
    rng = np.random.default_rng(2)
    L = 4001
    E = Rotation.random(L, random_state=3).as_matrix()
    rc, n = rng.normal(size=(L, 3)) * 0.05, rng.normal(size=(L, 3))
    th = np.column_stack([rng.uniform(-1.0, 1.0, L), rng.uniform(-2.0, 2.0, (L, 2))])
    th[::97, 0] = rng.uniform(-10.0, 10.0, len(th[::97]))  # some far past the series
    geo = np.ascontiguousarray(np.concatenate([E.reshape(L, 9), rc, n], axis=1).T)
    A = np.empty((6, L))
    _laminas(geo, th, A)
    bend = Rotation.from_rotvec(E[:, :, 1] * th[:, 1:2] + E[:, :, 2] * th[:, 2:3])
    G = (bend * Rotation.from_rotvec(E[:, :, 0] * th[:, 0:1])).as_matrix()
    for got, v in ((A[:3].T, rc), (A[3:].T, n)):
        err = np.linalg.norm(got - np.einsum("lij,lj->li", G, v), axis=1) / np.linalg.norm(v, axis=1)
        assert err.max() < 1e-14, err.max()  # (scipy rounds a 10 rad turn to 10⁻¹⁵ too)
