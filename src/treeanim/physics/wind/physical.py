"""The physical wind (docs/design.md §12): a von Kármán tile carried downwind, a canopy profile,
gusts; :class:`PhysicalWind`, the model registered as ``"physical"`` (the default).

A call of ``PhysicalWind.sample`` works out what is the same for every point in Python (the
clocks, the two layers' whole-cell offsets and weights, the wind frame, the gusts' widths,
the cached tile) and hands them to one compiled pass over the points (``_sample_points``):
each point's cell coordinates, its periodic trilinear look-up of the two blended layers,
its canopy profile and its gust.
"""

from __future__ import annotations

import math
from functools import lru_cache
from typing import Annotated

import numpy as np
import scipy.fft

from ...model.declare import Param, settings
from ..compiled import njit
from .field import WindField, WindParams, register_wind_model
from .settings import (
    _COORD_CLIP,
    _GRID_CLIP,
    _MAX_LENGTH,
    _MIN_LENGTH,
    _TIME_CLIP,
    EVOLUTION_LENGTH,
    MAX_BETA,
    MAX_GUST_RATE,
    MAX_GUST_STRENGTH,
    MIN_AUTO_LENGTH,
)

#: The physical tile: cells along, up and across the wind; cells per length scale L.
_TILE = (128, 48, 96)
_CELLS_PER_L = 16.0
#: von Kármán: k0 = 1 / (1.339 L) puts the integral scale of (k² + k0²)^−5/6 at L.
_VON_KARMAN = 1.339
#: Integral scales of the vertical and lateral components, in L (canopy flows: L_w ≈ h/3).
_CROSS_SCALE = 1.0
#: σ_u : σ_v(vertical) : σ_w(lateral) in the wind frame (along, vertical, lateral).
SIGMA_RATIOS = (1.0, 0.5, 0.75)
#: Canopy profile: displacement height and roughness length in canopy heights, and the
#: attenuation inside the canopy (matches the log law's slope at the top), and of σ there.
DISPLACEMENT = 0.7
ROUGHNESS = 0.1
_LOG_TOP = math.log((1.0 - DISPLACEMENT) / ROUGHNESS)
CANOPY_ATTENUATION = 1.0 / ((1.0 - DISPLACEMENT) * _LOG_TOP)
SIGMA_ATTENUATION = 1.0
#: Gust shape: rise and decay widths (Gaussian σ) in length scales; jitter of the gust
#: times (fraction of the mean interval); widths are capped at this many intervals.
GUST_RISE = 0.5
GUST_DECAY = 1.5
_GUST_JITTER = 0.7
_GUST_MAX_WIDTH = (1.0, 3.0)


@njit(cache=True, fastmath=True, error_model="numpy", inline="always")
def _canopy(h: float, inv_top: float) -> tuple[float, float]:
    """(mean speed, σ) over their values at the canopy top, at height ``h`` (m), ``inv_top``
    one over the canopy height: the log law above the canopy (σ constant there), exponential
    decay inside it."""
    z = min(max(h, 0.0), _COORD_CLIP) * inv_top
    inside = min(z, 1.0) - 1.0  # ≤ 0
    sigma = math.exp(SIGMA_ATTENUATION * inside)
    if z > 1.0:
        return math.log((z - DISPLACEMENT) / ROUGHNESS) / _LOG_TOP, sigma
    return math.exp(CANOPY_ATTENUATION * inside), sigma


@njit(cache=True, fastmath=True, error_model="numpy")
def _canopy_means(h: np.ndarray, inv_top: float) -> np.ndarray:
    """The mean of :func:`_canopy` at each of the heights ``h`` (1-D)."""
    out = np.empty(h.shape[0])
    for i in range(h.shape[0]):
        out[i] = _canopy(h[i], inv_top)[0]
    return out


def _canopy_mean(h: np.ndarray, top: float) -> np.ndarray:
    """Mean speed over the speed at the canopy top ``top`` at heights ``h`` (m)."""
    h = np.asarray(h, float)
    return _canopy_means(h.reshape(-1), 1.0 / top).reshape(h.shape)


@lru_cache(maxsize=16)
def _stream(seed: int, stream: int) -> np.uint64:
    """The key of one stream of :func:`_hash_uniform`'s numbers for a seed (any size)."""
    return np.uint64((seed * 0xD1B54A32D192ED03 + stream * 0x8CB92BA72F3D8DD7 + 0x632BE59BD9B4E019)
                     & ((1 << 64) - 1))


@njit(cache=True, fastmath=True, error_model="numpy")
def _hash_uniform(base: np.uint64, k: int, lanes: int, lane: int) -> float:
    """A deterministic uniform [0, 1) number: lane ``lane`` of ``lanes`` for the integer key
    ``k`` in the stream ``base`` (:func:`_stream`), by splitmix64's finaliser (wrapping
    uint64 arithmetic)."""
    x = np.uint64(k) * np.uint64(lanes) + np.uint64(lane)
    x = x * np.uint64(0x9E3779B97F4A7C15) + base
    x ^= x >> np.uint64(30)
    x *= np.uint64(0xBF58476D1CE4E5B9)
    x ^= x >> np.uint64(27)
    x *= np.uint64(0x94D049BB133111EB)
    x ^= x >> np.uint64(31)
    return np.float64(x >> np.uint64(11)) * (1.0 / 9007199254740992.0)


@lru_cache(maxsize=4)
def _physical_table(beta_u: float, beta_vw: float, seed: int) -> np.ndarray:
    """The padded tile's look-up table: (cells, 3) float32 (u, v, w), the cells of the padded
    (nx + 1, ny + 1, nz + 1) tile raveled, so a corner's three components are one 12-byte read."""
    nx, ny, nz = _TILE
    kx = 2 * np.pi * np.fft.fftfreq(nx)
    ky = 2 * np.pi * np.fft.fftfreq(ny)
    kz = 2 * np.pi * np.fft.rfftfreq(nz)
    k2 = kx[:, None, None] ** 2 + ky[None, :, None] ** 2 + kz[None, None, :] ** 2
    # Trilinear interpolation: along the wind a point's series is the piecewise-linear
    # interpolation of the grid line, whose amplitude transfer is sinc²; across, the
    # variance transfer averaged over the cell is (2 + cos k)/3 per axis.
    across = lambda k: (2.0 + np.cos(k)) / 3.0  # noqa: E731
    comp = (np.sinc(kx / (2 * np.pi)) ** -2)[:, None, None] \
        * (across(ky) ** -0.5)[None, :, None] * (across(kz) ** -0.5)[None, None, :]
    seen = across(kx)[:, None, None] * across(ky)[None, :, None] * across(kz)[None, None, :]
    weight = np.full(k2.shape, 2.0)
    weight[..., 0] = 1.0
    if nz % 2 == 0:
        weight[..., -1] = 1.0
    gain = comp * comp * seen * weight
    tile = np.zeros((nx + 1, ny + 1, nz + 1, 3), dtype=np.float32)
    scales = (1.0, _CROSS_SCALE, _CROSS_SCALE)
    for c, beta in enumerate((beta_u, beta_vw, beta_vw)):
        k0 = 1.0 / (_VON_KARMAN * _CELLS_PER_L * scales[c])
        log_amp = -0.25 * (beta + 2.0) * np.log(k2 + k0 * k0)
        log_amp -= log_amp.max()
        amp = np.exp(log_amp)
        amp[0, 0, 0] = 0.0  # zero mean over the tile
        if c:  # across the wind every line along it has zero mean: no long-run veer
            amp[0] = 0.0
        rng = np.random.default_rng((seed, 11, c))
        spec = scipy.fft.rfftn(rng.standard_normal((nx, ny, nz)), axes=(0, 1, 2)) * amp
        var = float(np.sum(gain * (spec.real**2 + spec.imag**2))) / float(nx * ny * nz) ** 2
        spec *= comp / math.sqrt(var) if var > 0 else 0.0
        field = scipy.fft.irfftn(spec, s=(nx, ny, nz), axes=(0, 1, 2))
        tile[:nx, :ny, :nz, c] = field
    tile[nx] = tile[0]
    tile[:, ny] = tile[:, 0]
    tile[:, :, nz] = tile[:, :, 0]
    table = tile.reshape(-1, 3)
    table.setflags(write=False)
    return table


@njit(cache=True, fastmath=True, error_model="numpy")
def _gust_sum(base: np.uint64, gam: float, sr: float, sd: float) -> float:
    """Σ_k A_k·env(γ − c_k) − mean at ``gam`` = γ in gust counts: gust k centred at
    c_k = k + jitter, its envelope a Gaussian of width ``sr`` before its centre and ``sd``
    after, A_k uniform in [0.5, 1.5]; ``base`` the gusts' stream (:func:`_stream`)."""
    gam = min(max(gam, -(2.0**50)), 2.0**50)
    kf = np.floor(gam)
    frac = gam - kf  # exact: γ's distance to each gust is read from its fraction
    total = 0.0
    for m in range(-math.ceil(4.0 * sd + 1.0), math.ceil(4.0 * sr + 1.0) + 1):
        key = np.int64(kf) + m
        x = frac - (m + _GUST_JITTER * (_hash_uniform(base, key, 2, 0) - 0.5))
        x /= sd if x >= 0.0 else sr
        x = min(max(x, -40.0), 40.0)  # exp(−800) is 0 already; no overflow for tiny widths
        total += math.exp(-0.5 * x * x) * (0.5 + _hash_uniform(base, key, 2, 1))
    return total - math.sqrt(0.5 * math.pi) * (sr + sd)  # mean of A (1) × area per gust


def _gust_params(wind: PhysicalWind, g: float) -> tuple[float, float, float, float, float, float]:
    """The gusts of one call: (strength, gust clock g, gusts per metre, rise and decay
    widths in gusts, lattice step in metres); strength 0 where there are none."""
    rg = wind.gust_rate / 60.0
    per_m = rg / max(wind.speed, 1e-6)  # gust count per metre (still air carries no gusts)
    length = wind.length_scale
    if not (wind.gust_strength > 0.0 and rg > 0.0 and GUST_RISE * length * per_m > 1e-12):
        return (0.0, 0.0, 0.0, 1.0, 1.0, 1.0)  # none, or so rare they never come
    sr = min(GUST_RISE * length * per_m, _GUST_MAX_WIDTH[0])
    sd = min(GUST_DECAY * length * per_m, _GUST_MAX_WIDTH[1])
    step = 0.125 * sr / per_m  # metres, on a lattice fixed in space (whatever the points)
    return (wind.gust_strength, g, per_m, sr, sd, step)


@njit(cache=True, fastmath=True, error_model="numpy")
def _gust_lattice(lo: float, hi: float, gusts: tuple, base: np.uint64) -> tuple[int, np.ndarray]:
    """(first index, values) of the gust sum on the lattice points from ⌊lo⌋ to ⌊hi⌋ + 1
    (in lattice steps), or (0, empty) where the span is beyond 4096 steps or ±2⁵⁰ (int64
    indices). ``gusts`` from :func:`_gust_params`, ``base`` their stream."""
    if not (-(2.0**50) < lo and hi < 2.0**50 and hi - lo <= 4096.0):
        return 0, np.empty(0)
    _, g, per_m, sr, sd, step = gusts
    first = np.int64(math.floor(lo))
    ys = np.empty(np.int64(math.floor(hi)) - first + 2)
    for j in range(ys.shape[0]):
        ys[j] = _gust_sum(base, g - (step * (first + j)) * per_m, sr, sd)
    return first, ys


@lru_cache(maxsize=8)
def _layer_offset(seed: int, layer: int, cycle: int) -> tuple[int, int, int]:
    """Whole-cell shift (along, up, across) of a layer of the tile during one of its cycles."""
    base = _stream(seed, 20 + layer)
    return tuple(min(int(_hash_uniform(base, cycle, 3, c) * n), n - 1) for c, n in enumerate(_TILE))


#: Flat strides of the padded tile along and up the wind (across: 1).
_DX = (_TILE[1] + 1) * (_TILE[2] + 1)
_DY = _TILE[2] + 1


@njit(cache=True, fastmath=True, error_model="numpy", inline="always")
def _cell(q: float, n: int) -> tuple[int, np.float32]:
    """(index, float32 fraction) of the cell coordinate ``q`` in a periodic axis of ``n`` cells,
    ``q`` clipped to ±2⁴⁰ cells first (where q mod n is still exact)."""
    q = min(max(q, -_GRID_CLIP), _GRID_CLIP)
    q -= np.floor(q / n) * n
    i = min(int(q), n - 1)  # q ≥ −ε here: truncation gives 0 for it; q may round up to n
    return i, np.float32(q - i)


@njit(cache=True, fastmath=True, error_model="numpy", inline="always")
def _along(p: np.ndarray, i: int, m: np.ndarray, row: int = 0) -> float:
    """Row ``row`` of ``m`` times the point ``p[i]`` clipped to ±1e12 m."""
    x = min(max(p[i, 0], -_COORD_CLIP), _COORD_CLIP)
    y = min(max(p[i, 1], -_COORD_CLIP), _COORD_CLIP)
    z = min(max(p[i, 2], -_COORD_CLIP), _COORD_CLIP)
    return m[row, 0] * x + m[row, 1] * y + m[row, 2] * z


@njit(cache=True, fastmath=True, error_model="numpy", inline="always")
def _corner(ia: int, ib: int, ic: int, off: tuple) -> int:
    """Flat index in the padded tile of the first corner of cell (``ia``, ``ib``, ``ic``)
    moved by a layer's whole-cell offset ``off``, periodically."""
    nx, ny, nz = _TILE
    ja, jb, jc = ia + off[0], ib + off[1], ic + off[2]
    ja -= nx if ja >= nx else 0
    jb -= ny if jb >= ny else 0
    jc -= nz if jc >= nz else 0
    return (ja * (ny + 1) + jb) * (nz + 1) + jc


@njit(cache=True, fastmath=True, error_model="numpy", inline="always")
def _trilinear(table: np.ndarray, c: int, r0: int, r1: int, w0: np.float32, w1: np.float32,
               fa: np.float32, fb: np.float32, fc: np.float32) -> np.float32:
    """Component ``c`` of the tile at a point: the corner values of its cell in the two layers
    (flat indices ``r0``, ``r1`` of the cells' first corners) blended with the weights
    ``w0``, ``w1``, then interpolated along (fraction ``fa``), up (``fb``) and across (``fc``),
    all in float32."""
    v000 = table[r0, c] * w0 + table[r1, c] * w1
    v001 = table[r0 + 1, c] * w0 + table[r1 + 1, c] * w1
    v010 = table[r0 + _DY, c] * w0 + table[r1 + _DY, c] * w1
    v011 = table[r0 + _DY + 1, c] * w0 + table[r1 + _DY + 1, c] * w1
    v100 = table[r0 + _DX, c] * w0 + table[r1 + _DX, c] * w1
    v101 = table[r0 + _DX + 1, c] * w0 + table[r1 + _DX + 1, c] * w1
    v110 = table[r0 + _DX + _DY, c] * w0 + table[r1 + _DX + _DY, c] * w1
    v111 = table[r0 + _DX + _DY + 1, c] * w0 + table[r1 + _DX + _DY + 1, c] * w1
    d00 = (v100 - v000) * fa + v000
    d01 = (v101 - v001) * fa + v001
    d10 = (v110 - v010) * fa + v010
    d11 = (v111 - v011) * fa + v011
    e0 = (d10 - d00) * fb + d00
    e1 = (d11 - d01) * fb + d01
    return (e1 - e0) * fc + e0


@njit(cache=True, fastmath=True, error_model="numpy")
def _sample_points(p, out, frame, cell, shift, table, offsets, weights, inv_top, sigma_scale,
                   mean_scale, gusts, gust_stream):
    """The physical wind at the points ``p`` into ``out``, world m/s: one pass over the points.

    Parameters
    ----------
    p, out : (K, 3) float64
        World positions (m); the velocities are written to ``out``.
    frame : (3, 3) float64
        The wind frame's rows (along, up, across), world.
    cell : float
        The tile's cell size (m).
    shift : float
        The downwind travel in cells, modulo the tile's length.
    table : (cells, 3) float32
        The tile (:func:`_physical_table`).
    offsets : tuple of two (int, int, int)
        Each layer's whole-cell shift in the tile (:func:`_layer_offset`).
    weights : tuple of two floats
        The layers' weights (applied in float32).
    inv_top : float
        One over the canopy height (1/m).
    sigma_scale, mean_scale : float
        σ_u at the canopy top, and the mean speed there over σ_u's ratio (m/s).
    gusts : tuple
        :func:`_gust_params`.
    gust_stream : uint64
        The gusts' stream of random numbers (:func:`_stream`).

    Notes
    -----
    A point's cell coordinates are its world position (clipped to ±1e12 m) in the wind
    frame, over the cell size. The gusts read the along-wind one: gusts are plane fronts, so
    their sum is a function of it only, evaluated on a 1-D lattice of spacing GUST_RISE·L/8
    fixed in space over the points' span and interpolated (relative error < 0.5 %), or
    directly at each point where the span is too long for that (:func:`_gust_lattice`). The
    turbulence reads all three, moved upwind by the travel and reduced into the tile
    (:func:`_cell`). Whole-cell layer offsets share the fractions, so the layers' corner
    values blend first (in float32, as the table) and one trilinear interpolation serves
    both.
    """
    nx, ny, nz = _TILE
    m = frame * (1.0 / cell)
    strength, g, per_m, sr, sd, step = gusts
    scale = cell / step  # gust lattice steps per cell
    first, ys = 0, np.empty(0)
    if strength > 0.0 and p.shape[0]:
        lo = hi = _along(p, 0, m)
        for i in range(1, p.shape[0]):
            along = _along(p, i, m)
            lo = min(lo, along)
            hi = max(hi, along)
        first, ys = _gust_lattice(lo * scale, hi * scale, gusts, gust_stream)
    ratio = np.empty((3, 3))  # the frame's rows scaled by the components' σ ratios
    for c in range(3):
        for d in range(3):
            ratio[c, d] = frame[c, d] * SIGMA_RATIOS[c]
    w0, w1 = np.float32(weights[0]), np.float32(weights[1])
    for i in range(p.shape[0]):
        qa = _along(p, i, m)  # cells along, up, across the wind
        qb = _along(p, i, m, 1)
        qc = _along(p, i, m, 2)
        gust = 0.0
        if strength > 0.0:
            if ys.shape[0]:
                f = qa * scale
                # (within the lattice even where the span's ends round otherwise here)
                j = min(max(np.int64(np.floor(f)) - first, 0), ys.shape[0] - 2)
                gust = (ys[j + 1] - ys[j]) * (f - (first + j)) + ys[j]
            else:
                gust = _gust_sum(gust_stream, g - qa * (cell * per_m), sr, sd)
        ia, fa = _cell(qa - shift, nx)
        ib, fb = _cell(qb, ny)
        ic, fc = _cell(qc, nz)
        r0 = _corner(ia, ib, ic, offsets[0])
        r1 = _corner(ia, ib, ic, offsets[1])
        mean, sigma = _canopy(p[i, 1], inv_top)
        sigma *= sigma_scale
        mean *= strength * gust + 1.0
        mean *= mean_scale
        u = _trilinear(table, 0, r0, r1, w0, w1, fa, fb, fc) * sigma + mean  # over their σ ratios
        v = _trilinear(table, 1, r0, r1, w0, w1, fa, fb, fc) * sigma
        w = _trilinear(table, 2, r0, r1, w0, w1, fa, fb, fc) * sigma
        for d in range(3):
            out[i, d] = u * ratio[0, d] + v * ratio[1, d] + w * ratio[2, d]


def _sample_physical(wind: PhysicalWind, p: np.ndarray, t: float, out: np.ndarray) -> None:
    """The physical wind at the points ``p`` (K, 3) and time ``t`` into ``out`` (K, 3): what
    is the same for every point, then :func:`_sample_points`."""
    length = wind.length_scale
    a, s, g = wind._clocks(t)
    g = math.fmod(g, 2.0**40)  # the gust sequence is hashed: any shift of it is as good
    cell = length / _CELLS_PER_L
    weights, offsets = [], []
    for j in (0, 1):
        phase = min(max(s + 0.5 * j, -2.0**62), 2.0**62)
        cycle = math.floor(phase)
        weights.append(math.sin(math.pi * (phase - cycle)))
        offsets.append(_layer_offset(wind.seed, j, cycle))
    table = _physical_table(wind.beta_u, wind.beta_vw, wind.seed)
    _sample_points(np.ascontiguousarray(p), out, wind._frame, cell, math.fmod(a / cell, _TILE[0]),
                   table, tuple(offsets), tuple(weights), 1.0 / wind.canopy_height,
                   wind.turbulence * wind.speed, wind.speed / SIGMA_RATIOS[0], _gust_params(wind, g),
                   _stream(wind.seed, 31))


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
                                           "turbulence (L/3 vertically and laterally); None: the canopy "
                                           "height, at least 1 m.")] | None = None
    canopy_height: Annotated[float, _length("Canopy height h: the height of speed and of "
                                            "the canopy profile; None: the top of the bounds.")] | None = None
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
    ``canopy_height``, ``gust_strength``, ``gust_rate``, ``beta_u``, ``beta_vw``, ``seed``) and
    :class:`WindField`'s. Only the top of ``bounds`` is used: the canopy height when
    ``canopy_height`` is None; the turbulence stays in metres whatever the box.

    Notes
    -----
    Changing the speed, the length scale or the gust rate (or the canopy height or box they
    follow) keeps the field continuous in time: the downwind travel, the evolution and the gust
    clock are integrated piecewise from the last sampled time, so ``sample`` is a pure function
    of ``t`` between changes. The turbulence repeats every 8 L along the wind, 6 L across and
    3 L up, in space only; in time it never repeats. Turning the wind rotates the field about
    the world origin.
    """

    Params = PhysicalParams

    def __init__(self, *args, **kwargs):
        # The clocks: (t0, travel a0 in m, evolution s0 in cycles, gusts g0) at t0; each
        # advances linearly from t0 at its current rate (see _changing).
        self._clock = (0.0, 0.0, 0.0, 0.0)
        self._t_last = 0.0
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
    def canopy_height(self) -> float:
        """Canopy height h, m: the height of ``speed`` and of the profile's displacement (0.7 h)
        and roughness (0.1 h). Set None for the top of ``bounds``."""
        return _canopy_height(self._params, self._bounds)

    @canopy_height.setter
    def canopy_height(self, value) -> None:
        self._set(canopy_height=value)

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
        z0 = 0.1 h_c) and exp(a(h/h_c − 1)) inside it, with a = 1/(0.3 ln 3) ≈ 3.03 so the two
        meet smoothly; 1 at h_c."""
        return _canopy_mean(h, self.canopy_height)

    def sample(self, points, t: float) -> np.ndarray:
        """:meth:`WindField.sample`; the time is kept (calm too): a later change of a rate
        restarts the clocks there."""
        out = super().sample(points, t)
        self._t_last = float(t)  # valid: sample checked it
        return out

    def _sample(self, p: np.ndarray, t: float, out: np.ndarray) -> None:
        _sample_physical(self, p, t, out)
