"""The physical wind (docs/design.md §12): a von Kármán tile carried downwind, a canopy profile,
gusts; :class:`PhysicalWind`, the model registered as ``"physical"`` (the default).

A call of ``PhysicalWind.sample`` works out what is the same for every point in Python (the
clocks, the downwind travel and the evolution in whole blocks and cycles, the wind frame, the
gusts' widths, the cached tile) and hands them to one compiled pass over the points
(``_sample_points``): each point's cell coordinates, its turbulence (the tile read through
its blocks, ``turbulence.py``), its canopy profile and its gust (its lane's, or two lanes'
blended).
"""

from __future__ import annotations

import math
from typing import Annotated

import numpy as np

from ...model.declare import Param, settings
from ..compiled import njit
from .field import WindField, WindParams, register_wind_model
from .settings import (
    _COORD_CLIP,
    _MAX_LENGTH,
    _MIN_LENGTH,
    _TIME_CLIP,
    EVOLUTION_LENGTH,
    MAX_BETA,
    MAX_GUST_RATE,
    MAX_GUST_STRENGTH,
    MIN_AUTO_LENGTH,
)
from .turbulence import (
    _CELLS_PER_L,
    _blocks,
    _eddies,
    _evolution,
    _hash_uniform,
    _physical_table,
    _stream,
    _substream,
    _travel,
)

#: σ_u : σ_v(vertical) : σ_w(lateral) in the wind frame (along, vertical, lateral).
SIGMA_RATIOS = (1.0, 0.5, 0.75)
#: Canopy profile: displacement height and roughness length in canopy heights, and the
#: attenuation inside the canopy (matches the log law's slope at the top), and of σ there.
DISPLACEMENT = 0.7
ROUGHNESS = 0.1
_LOG_TOP = math.log((1.0 - DISPLACEMENT) / ROUGHNESS)
CANOPY_ATTENUATION = 1.0 / ((1.0 - DISPLACEMENT) * _LOG_TOP)
SIGMA_ATTENUATION = 1.0
#: Gust shape: rise and decay widths (Gaussian σ) in the gusts' length scale L_g; jitter of
#: the gust times (fraction of the mean interval).
GUST_RISE = 0.5
GUST_DECAY = 1.5
_GUST_JITTER = 0.7
#: The gusts' length scale L_g is the atmospheric surface layer's along-wind integral scale at
#: the canopy top z = h over its roughness z0 = ROUGHNESS·h: L = L_t·(z/z_t)^α with
#: α = 0.67 + 0.05·ln(z0 / 1 m), L_t = 300 m, z_t = 200 m (EN 1991-1-4, Annex B; z at most
#: z_t), not the canopy's: (L_t, z_t, α at z0 = 1 m, α's slope in ln z0).
SURFACE_SCALE = (300.0, 200.0, 0.67, 0.05)
#: The gusts' lateral scale over their along-wind one: isotropic (von Kármán) turbulence's,
#: whose along-wind component's integral scale across the wind is half that along it.
GUST_ASPECT = 0.5
#: Lanes of gusts across the wind, each its own gusts: blocks GUST_LANE lateral scales wide
#: that share a ramp one lateral scale wide with each neighbour (as the turbulence's blocks
#: do), so a lane's gusts reach 4 lateral scales across, as a gust's length along the wind
#: (its rise and decay, two widths each) is 4 L_g.
GUST_LANE = 2.0 * (GUST_RISE + GUST_DECAY) - 1.0


def _surface_scale(h: float) -> float:
    """The surface layer's along-wind integral scale (m) at the top of a canopy ``h`` m tall
    (:data:`SURFACE_SCALE`)."""
    top, z_top, alpha, slope = SURFACE_SCALE
    return top * (min(h, z_top) / z_top) ** (alpha + slope * math.log(ROUGHNESS * h))


@njit(cache=True, fastmath=True, error_model="numpy", inline="always")
def _canopy(h: float, inv_top: float, cover: float) -> tuple[float, float]:
    """(mean speed, σ) over their values at the canopy top, at height ``h`` (m), ``inv_top``
    one over the canopy height, ``cover`` the canopy's cover (0–1): the log law above the
    canopy (σ constant there), exponential decay inside it, at a rate in proportion to the
    cover (a lone tree's crown stands in the open wind)."""
    z = min(max(h, 0.0), _COORD_CLIP) * inv_top
    inside = cover * (min(z, 1.0) - 1.0)  # ≤ 0
    sigma = math.exp(SIGMA_ATTENUATION * inside)
    if z > 1.0:
        return math.log((z - DISPLACEMENT) / ROUGHNESS) / _LOG_TOP, sigma
    return math.exp(CANOPY_ATTENUATION * inside), sigma


@njit(cache=True, fastmath=True, error_model="numpy")
def _canopy_means(h: np.ndarray, inv_top: float, cover: float) -> np.ndarray:
    """The mean of :func:`_canopy` at each of the heights ``h`` (1-D)."""
    out = np.empty(h.shape[0])
    for i in range(h.shape[0]):
        out[i] = _canopy(h[i], inv_top, cover)[0]
    return out


def _canopy_mean(h: np.ndarray, top: float, cover: float) -> np.ndarray:
    """Mean speed over the speed at the canopy top ``top`` at heights ``h`` (m)."""
    h = np.asarray(h, float)
    return _canopy_means(h.reshape(-1), 1.0 / top, cover).reshape(h.shape)


@njit(cache=True, fastmath=True, error_model="numpy")
def _gust_sum(base: np.uint64, gam: float, sr: float, sd: float) -> float:
    """Σ_k A_k·env(γ − c_k) − mean at ``gam`` = γ in gust counts: gust k centred at
    c_k = k + jitter, its envelope a Gaussian of width ``sr`` before its centre and ``sd``
    after, A_k uniform in [0.5, 1.5]; ``base`` the gusts' stream (:func:`_stream`). Gusts more
    than six widths away (each under 2·10⁻⁸ of a gust here) are left out."""
    gam = min(max(gam, -(2.0**50)), 2.0**50)
    kf = np.floor(gam)
    frac = gam - kf  # exact: γ's distance to each gust is read from its fraction
    total = 0.0
    reach = 0.5 * _GUST_JITTER
    for m in range(math.ceil(frac - 6.0 * sd - reach), math.floor(frac + 6.0 * sr + reach) + 1):
        key = np.int64(kf) + m
        x = frac - (m + _GUST_JITTER * (_hash_uniform(base, key, 2, 0) - 0.5))
        x /= sd if x >= 0.0 else sr
        x = min(max(x, -40.0), 40.0)  # exp(−800) is 0 already; no overflow for tiny widths
        total += math.exp(-0.5 * x * x) * (0.5 + _hash_uniform(base, key, 2, 1))
    return total - math.sqrt(0.5 * math.pi) * (sr + sd)  # mean of A (1) × area per gust


def _gust_params(wind: PhysicalWind, g: float) -> tuple[float, float, float, float, float, float, float]:
    """The gusts of one call: (strength, gust clock g, gusts per metre, rise and decay
    widths in gusts, lattice step and lane width in metres); strength 0 where there are none."""
    rg = wind.gust_rate / 60.0
    per_m = rg / max(wind.speed, 1e-6)  # gust count per metre (still air carries no gusts)
    length = wind.gust_length
    if not (wind.gust_strength > 0.0 and rg > 0.0 and GUST_RISE * length * per_m > 1e-12):
        return (0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0)  # none, or so rare they never come
    # A gust's rise and decay (two widths each) fit in the interval between gusts: they come
    # at their rate, however long.
    fit = min(length * per_m, 0.5 / (GUST_RISE + GUST_DECAY))
    sr, sd = GUST_RISE * fit, GUST_DECAY * fit
    step = 0.125 * sr / per_m  # metres, on a lattice fixed in space (whatever the points)
    return (wind.gust_strength, g, per_m, sr, sd, step, GUST_LANE * GUST_ASPECT * length)


@njit(cache=True, fastmath=True, error_model="numpy")
def _gust_lattice(lo: float, hi: float, lanes: tuple, budget: int, gusts: tuple,
                  base: np.uint64) -> tuple[int, np.ndarray]:
    """(first index, values) of each lane's gust sum on the lattice points from ⌊lo⌋ to
    ⌊hi⌋ + 1 (in lattice steps), the lanes ``lanes`` = (first key, last key), or (0, empty)
    where that is more than ``budget`` values or the span is beyond ±2⁵⁰ (int64 indices).
    ``gusts`` from :func:`_gust_params`, ``base`` their stream."""
    empty = np.empty((0, 0))
    if not (-(2.0**50) < lo and hi < 2.0**50 and hi - lo <= budget):
        return 0, empty
    n_lanes = lanes[1] - lanes[0] + 1
    first = np.int64(math.floor(lo))
    n = np.int64(math.floor(hi)) - first + 2
    if float(n) * float(n_lanes) > budget:  # (in float: no int64 overflow for lanes far apart)
        return 0, empty
    _, g, per_m, sr, sd, step, _ = gusts
    ys = np.empty((n_lanes, n))
    for k in range(n_lanes):
        stream = _substream(base, lanes[0] + k)
        for j in range(n):
            ys[k, j] = _gust_sum(stream, g - (step * (first + j)) * per_m, sr, sd)
    return first, ys


@njit(cache=True, fastmath=True, error_model="numpy", inline="always")
def _gust(qa: float, qc: float, cell: float, lane: float, gusts: tuple, base: np.uint64,
          lanes: tuple, first: int, ys: np.ndarray) -> float:
    """The gust sum (over the mean) at ``qa`` cells along and ``qc`` across the wind: its lane's
    sum (lanes ``lane`` cells wide), blended with the next lane's in a ramp between them (as
    the turbulence's blocks are), each read from the lattice ``ys`` (:func:`_gust_lattice`)
    where there is one, else summed here."""
    _, g, per_m, sr, sd, step, _ = gusts
    k0, k1, w0, w1 = _blocks(qc / lane, 0.5 / GUST_LANE)
    if ys.shape[0]:
        f = qa * (cell / step)
        # (within the lattice even where the span's ends round otherwise here)
        j = min(max(np.int64(np.floor(f)) - first, 0), ys.shape[1] - 2)
        x = f - (first + j)
        # (and within the lanes: a lane read off its edge has weight 0 there)
        i0 = min(max(k0 - lanes[0], 0), ys.shape[0] - 1)
        i1 = min(max(k1 - lanes[0], 0), ys.shape[0] - 1)
        y0 = (ys[i0, j + 1] - ys[i0, j]) * x + ys[i0, j]
        y1 = (ys[i1, j + 1] - ys[i1, j]) * x + ys[i1, j]
        return w0 * y0 + w1 * y1  # (w1 = 0 outside the ramps: any lane will do)
    gam = g - qa * (cell * per_m)
    y = w0 * _gust_sum(_substream(base, k0), gam, sr, sd)
    return y + w1 * _gust_sum(_substream(base, k1), gam, sr, sd) if w1 > 0.0 else y


@njit(cache=True, fastmath=True, error_model="numpy", inline="always")
def _along(p: np.ndarray, i: int, m: np.ndarray, row: int = 0) -> float:
    """Row ``row`` of ``m`` times the point ``p[i]`` clipped to ±1e12 m."""
    x = min(max(p[i, 0], -_COORD_CLIP), _COORD_CLIP)
    y = min(max(p[i, 1], -_COORD_CLIP), _COORD_CLIP)
    z = min(max(p[i, 2], -_COORD_CLIP), _COORD_CLIP)
    return m[row, 0] * x + m[row, 1] * y + m[row, 2] * z


@njit(cache=True, fastmath=True, error_model="numpy")
def _sample_points(p, out, frame, cell, travel, evolution, table, inv_top, cover, sigma_scale, mean_scale,
                   gusts, streams):
    """The physical wind at the points ``p`` into ``out``, world m/s: one pass over the points.

    Parameters
    ----------
    p, out : (K, 3) float64
        World positions (m); the velocities are written to ``out``.
    frame : (3, 3) float64
        The wind frame's rows (along, up, across), world.
    cell : float
        The tile's cell size (m).
    travel : tuple
        The downwind travel (:func:`~.turbulence._travel`).
    evolution : tuple
        The evolution's fraction and whole cycles (:func:`~.turbulence._evolution`).
    table : (cells, 3) float32
        The tile (:func:`~.turbulence._physical_table`).
    inv_top : float
        One over the canopy height (1/m).
    sigma_scale, mean_scale : float
        σ_u at the canopy top, and the mean speed there over σ_u's ratio (m/s).
    gusts : tuple
        :func:`_gust_params`.
    streams : tuple of two uint64
        The turbulence's blocks' and the gusts' streams of random numbers
        (:func:`~.turbulence._stream`).

    Notes
    -----
    A point's cell coordinates are its world position (clipped to ±1e12 m) in the wind
    frame, over the cell size. The turbulence reads them through its blocks
    (:func:`~.turbulence._eddies`). The gusts read the along-wind one and the across-wind
    one's lane: gusts are fronts across their lane, so each lane's sum is a function of the
    along-wind coordinate only, evaluated on a 1-D lattice of spacing an eighth of the rise
    width fixed in space over the points' span and interpolated (relative error < 0.5 %), or
    directly at each point where the lanes' lattices would cost more than the points
    (:func:`_gust`).
    """
    m = frame * (1.0 / cell)
    strength, _, _, _, _, step, lane = gusts
    lane /= cell
    lanes, first, ys = (0, 0), 0, np.empty((0, 0))
    if strength > 0.0 and p.shape[0]:
        lo = hi = _along(p, 0, m)
        clo = chi = _along(p, 0, m, 2)
        for i in range(1, p.shape[0]):
            along = _along(p, i, m)
            lo, hi = min(lo, along), max(hi, along)
            across = _along(p, i, m, 2)
            clo, chi = min(clo, across), max(chi, across)
        lanes = (np.int64(np.floor(clo / lane)) - 1, np.int64(np.floor(chi / lane)) + 1)
        first, ys = _gust_lattice(lo * (cell / step), hi * (cell / step), lanes, max(4096, p.shape[0]), gusts,
                                  streams[1])
    ratio = np.empty((3, 3))  # the frame's rows scaled by the components' σ ratios
    for c in range(3):
        for d in range(3):
            ratio[c, d] = frame[c, d] * SIGMA_RATIOS[c]
    for i in range(p.shape[0]):
        qa = _along(p, i, m)  # cells along, up, across the wind
        qb = _along(p, i, m, 1)
        qc = _along(p, i, m, 2)
        gust = 0.0
        if strength > 0.0:
            gust = _gust(qa, qc, cell, lane, gusts, streams[1], lanes, first, ys)
        u, v, w = _eddies(table, qa, qb, qc, travel, evolution, streams[0])
        mean, sigma = _canopy(p[i, 1], inv_top, cover)
        sigma *= sigma_scale
        mean *= strength * gust + 1.0
        mean *= mean_scale
        u = u * sigma + mean  # over their σ ratios
        v = v * sigma
        w = w * sigma
        for d in range(3):
            out[i, d] = u * ratio[0, d] + v * ratio[1, d] + w * ratio[2, d]


def _sample_physical(wind: PhysicalWind, p: np.ndarray, t: float, out: np.ndarray) -> None:
    """The physical wind at the points ``p`` (K, 3) and time ``t`` into ``out`` (K, 3): what
    is the same for every point, then :func:`_sample_points`."""
    length = wind.length_scale
    a, s, g = wind._clocks(t)
    g = math.fmod(g, 2.0**40)  # the gust sequence is hashed: any shift of it is as good
    cell = length / _CELLS_PER_L
    table = _physical_table(wind.beta_u, wind.beta_vw, wind.seed)
    _sample_points(np.ascontiguousarray(p), out, wind._frame, cell, _travel(a / cell), _evolution(s), table,
                   1.0 / wind.canopy_height, wind.canopy_cover, wind.turbulence * wind.speed, wind.speed / SIGMA_RATIOS[0],
                   _gust_params(wind, g), (_stream(wind.seed, 20), _stream(wind.seed, 31)))


def _length(help: str) -> Param:
    return Param(_MIN_LENGTH, _MAX_LENGTH, unit="m", fmt="%.1f", log=True, help=help)


def _beta(help: str) -> Param:
    return Param(-MAX_BETA, MAX_BETA, help=help + " (rebuilds the tile when changed).")


@settings("")
class PhysicalParams(WindParams):
    """The physical wind's settings; ``speed`` is the mean speed at the canopy top."""

    turbulence: Annotated[float, Param(0.0, 1.0, help="Along-wind turbulence intensity σ_u/U at the canopy "
                                       "top.")] = 0.3
    length_scale: Annotated[float, _length("Along-wind integral length scale L of the "
                                           "turbulence (of all three components); None: the canopy "
                                           "height, at least 1 m.")] | None = None
    canopy_height: Annotated[float, _length("Canopy height h: the height of speed and of "
                                            "the canopy profile; None: the top of the bounds.")] | None = None
    canopy_cover: Annotated[float, Param(0.0, 1.0, help="Fraction of the ground under crowns: 1 a closed "
                                         "stand, into which the wind decays; 0 a lone tree, whose "
                                         "crown stands in the open wind; None: measured from the tree "
                                         "or scene (physics.wind.canopy_cover).")] | None = None
    gust_strength: Annotated[float, Param(0.0, MAX_GUST_STRENGTH, help="Mean peak speed of a gust above the "
                                          "mean, as a fraction of it.")] = 0.3
    gust_rate: Annotated[float, Param(0.0, MAX_GUST_RATE, unit="per minute", fmt="%.1f",
                                      help="Gusts per minute passing a point.")] = 4.0
    beta_u: Annotated[float, _beta("Spectral exponent of the along-wind turbulence")] = 5.0 / 3.0
    beta_vw: Annotated[float, _beta("Spectral exponent of the vertical and lateral turbulence")] = 5.0 / 3.0
    seed: Annotated[int, Param(0, math.inf, integer=True, help="Seed of the turbulence and the gusts.")] = 0


def _canopy_height(params: PhysicalParams, bounds: np.ndarray) -> float:
    if params.canopy_height is not None:
        return params.canopy_height
    return min(max(float(bounds[1, 1]), _MIN_LENGTH), _MAX_LENGTH)


def _length_scale(params: PhysicalParams, bounds: np.ndarray) -> float:
    if params.length_scale is not None:
        return params.length_scale
    return max(_canopy_height(params, bounds), MIN_AUTO_LENGTH)


def _rates(params: PhysicalParams, bounds: np.ndarray) -> tuple[float, float, float]:
    """(downwind travel m/s, evolution cycles/s, gusts/s) at these settings."""
    u = params.speed
    return u, u / (EVOLUTION_LENGTH * _length_scale(params, bounds)), params.gust_rate / 60.0


@register_wind_model("physical")
class PhysicalWind(WindField):
    """Weather-like wind (docs/design.md §12, issue 11): turbulence in metres carried downwind at
    the wind speed (Taylor), evolving along its way so that it never repeats, with a von Kármán
    f^−β spectrum, a canopy profile and gusts; see :mod:`treeanim.physics.wind`.

    Settings: :class:`PhysicalParams` (``turbulence`` = σ_u/U, ``length_scale``,
    ``canopy_height``, ``canopy_cover``, ``gust_strength``, ``gust_rate``, ``beta_u``,
    ``beta_vw``, ``seed``) and :class:`WindField`'s. Only the top of ``bounds`` is used: the canopy height when
    ``canopy_height`` is None; the turbulence stays in metres whatever the box.

    Notes
    -----
    Changing the speed, the length scale or the gust rate (or the canopy height or box they
    follow) keeps the field continuous in time: the downwind travel, the evolution and the gust
    clock are integrated piecewise from the last sampled time, so ``sample`` is a pure function
    of ``t`` between changes. The turbulence reads one tile of 16 L × 3 L × 4 L (along, up,
    across the wind) through blocks that give each part of the landscape its own place in it
    (``turbulence.py``): it never repeats across the ground or in time (up it repeats every
    3 L). Gusts are the surface layer's eddies, not the canopy's: tens of metres long
    (``gust_length``) and in lanes 1.5 times that wide across the wind, each lane its own.
    Turning the wind rotates the field about the world origin.
    """

    Params = PhysicalParams

    def __init__(self, *args, **kwargs):
        # The clocks: (t0, travel a0 in m, evolution s0 in cycles, gusts g0) at t0; each
        # advances linearly from t0 at its current rate (see _changing).
        self._clock = (0.0, 0.0, 0.0, 0.0)
        self._t_last = 0.0
        self._auto_cover = 1.0
        super().__init__(*args, **kwargs)

    @property
    def length_scale(self) -> float:
        """Along-wind integral length scale L of the turbulence, m (set None for automatic: the
        canopy height, at least 1 m)."""
        return _length_scale(self._params, self._bounds)

    @length_scale.setter
    def length_scale(self, value) -> None:
        self._set(length_scale=value)

    @property
    def gust_length(self) -> float:
        """The gusts' along-wind length scale L_g, m: the atmospheric surface layer's integral
        scale at the canopy top (:data:`SURFACE_SCALE`; 22 m over a 2.5 m canopy, 40 m over a
        10 m one), at least ``length_scale``. A gust rises over 0.5 L_g and decays over
        1.5 L_g (Gaussian widths) and its lane is 1.5 L_g wide."""
        return max(self.length_scale, _surface_scale(self.canopy_height))

    @property
    def canopy_height(self) -> float:
        """Canopy height h, m: the height of ``speed`` and of the profile's displacement (0.7 h)
        and roughness (0.1 h). Set None for the top of ``bounds``."""
        return _canopy_height(self._params, self._bounds)

    @canopy_height.setter
    def canopy_height(self, value) -> None:
        self._set(canopy_height=value)

    @property
    def canopy_cover(self) -> float:
        """Fraction of the ground under crowns (0–1): the wind decays into the canopy at a rate
        in proportion to it. Set None for what ``fit_cover`` measured (1 until then)."""
        return self._auto_cover if self._params.canopy_cover is None else self._params.canopy_cover

    @canopy_cover.setter
    def canopy_cover(self, value) -> None:
        self._set(canopy_cover=value)

    def fit_cover(self, cover: float) -> None:
        """The cover measured from the tree or scene the field is fitted to (a Simulation
        calls it with :func:`~treeanim.physics.wind.canopy_cover`), used while ``canopy_cover`` is None."""
        self._auto_cover = min(max(float(cover), 0.0), 1.0)

    def _clocks(self, t: float) -> tuple[float, float, float]:
        """(travel a in m, evolution s in cycles, gust count g) at time t."""
        t0, a0, s0, g0 = self._clock
        dt = min(max(t - t0, -_TIME_CLIP), _TIME_CLIP)
        ra, rs, rg = _rates(self._params, self._bounds)
        return a0 + ra * dt, s0 + rs * dt, g0 + rg * dt

    def _changing(self, params: PhysicalParams, bounds: np.ndarray) -> None:
        # A rate changes: the clocks start afresh at the last sampled time.
        if _rates(params, bounds) != _rates(self._params, self._bounds):
            t = self._t_last
            self._clock = (t, *self._clocks(t))

    def _profile(self, h: np.ndarray) -> np.ndarray:
        """ln((h − d)/z0) / ln((h_c − d)/z0) above the canopy height h_c (d = 0.7 h_c,
        z0 = 0.1 h_c) and exp(c·a(h/h_c − 1)) inside it, with a = 1/(0.3 ln 3) ≈ 3.03 so the two
        meet smoothly under a closed canopy (cover c = 1); 1 at h_c."""
        return _canopy_mean(h, self.canopy_height, self.canopy_cover)

    def sample(self, points, t: float) -> np.ndarray:
        """:meth:`WindField.sample`; the time is kept (calm too): a later change of a rate
        restarts the clocks there."""
        out = super().sample(points, t)
        self._t_last = float(t)  # valid: sample checked it
        return out

    def _sample(self, p: np.ndarray, t: float, out: np.ndarray) -> None:
        _sample_physical(self, p, t, out)
