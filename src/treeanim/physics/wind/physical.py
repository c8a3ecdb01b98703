"""The physical wind (docs/design.md §12): a von Kármán tile carried downwind, a canopy profile, gusts."""

from __future__ import annotations

import math
from functools import lru_cache
from typing import TYPE_CHECKING

import numpy as np
import scipy.fft

from .settings import _CHUNK, _COORD_CLIP, _GRID_CLIP

if TYPE_CHECKING:
    from .field import WindField


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


def _canopy_mean(h: np.ndarray, top: float) -> np.ndarray:
    """Mean speed over the speed at the canopy top ``top`` at heights ``h`` (m)."""
    h = np.asarray(h, float)
    return _canopy(h.reshape(-1), top)[0].reshape(h.shape)


def _canopy(h: np.ndarray, top: float) -> tuple[np.ndarray, np.ndarray]:
    """(mean speed, σ) over their values at the canopy top ``top``, at heights ``h`` (m): the
    log law above the canopy (σ constant there), exponential decay inside it."""
    z = np.minimum(np.maximum(h, 0.0), _COORD_CLIP)
    z *= 1.0 / top
    inside = np.minimum(z, 1.0)
    inside -= 1.0  # ≤ 0
    sigma = np.exp(SIGMA_ATTENUATION * inside)
    inside *= CANOPY_ATTENUATION
    mean = np.exp(inside, out=inside)
    above = z > 1.0
    if above.any():
        mean[above] = np.log((z[above] - DISPLACEMENT) / ROUGHNESS) / _LOG_TOP
    return mean, sigma


_M64 = (1 << 64) - 1


def _mix(x: np.ndarray) -> np.ndarray:
    """splitmix64's finaliser on a uint64 array (wrapping arithmetic)."""
    x = x ^ (x >> np.uint64(30))
    x = x * np.uint64(0xBF58476D1CE4E5B9)
    x = x ^ (x >> np.uint64(27))
    x = x * np.uint64(0x94D049BB133111EB)
    return x ^ (x >> np.uint64(31))


def _hash_uniform(seed: int, stream: int, k: np.ndarray, lanes: int) -> np.ndarray:
    """Deterministic uniform [0, 1) numbers, (len(k), lanes), for integer keys ``k``."""
    base = (seed * 0xD1B54A32D192ED03 + stream * 0x8CB92BA72F3D8DD7 + 0x632BE59BD9B4E019) & _M64
    kk = np.asarray(k, dtype=np.int64).astype(np.uint64)
    x = kk[:, None] * np.uint64(lanes) + np.arange(lanes, dtype=np.uint64)[None, :]
    x = _mix(x * np.uint64(0x9E3779B97F4A7C15) + np.uint64(base))
    return (x >> np.uint64(11)).astype(np.float64) * (1.0 / 9007199254740992.0)


@lru_cache(maxsize=4)
def _physical_table(beta_u: float, beta_vw: float, seed: int) -> np.ndarray:
    """The padded tile's look-up tables: (u + i·v as complex64, w as float32), raveled."""
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
    # u and v travel together as one complex64 (8-byte gathers), w alone (as the paper's).
    uv = np.empty(tile[..., 0].size, dtype=np.complex64)
    uv.real = tile[..., 0].ravel()
    uv.imag = tile[..., 1].ravel()
    w = np.ascontiguousarray(tile[..., 2]).ravel()
    uv.setflags(write=False)
    w.setflags(write=False)
    return uv, w


def _tile_corners() -> np.ndarray:
    """(8, 1) int32 flat offsets of a cell's corners in the padded tile."""
    nx, ny, nz = _TILE
    d = np.arange(2)
    off = (d[:, None, None] * (ny + 1) + d[None, :, None]) * (nz + 1) + d[None, None, :]
    return off.reshape(8, 1).astype(np.int32)


# Index arithmetic in int32 (the padded tile has 613,000 cells): half the memory traffic.
_TILE_DIMS = np.array(_TILE, dtype=np.float64)[:, None]
_TILE_INT = np.array(_TILE, dtype=np.int32)[:, None]
_TILE_LAST = _TILE_INT - 1
_TILE_CORNERS = _tile_corners()


def _trilinear(tables, q: np.ndarray, offsets, weights) -> tuple[np.ndarray, np.ndarray]:
    """Periodic trilinear look-up of the tile, blending layers before the interpolation.

    ``q`` (3, n) cell coordinates (overwritten); ``offsets`` whole-cell shifts (3, 1) int32 of each
    layer and ``weights`` their weights. Whole-cell offsets share the fractions, so the
    layers' corner values blend first and one interpolation serves them all. Returns
    ((n,) complex64 u + i·v, (n,) float32 w)."""
    tab_uv, tab_w = tables
    np.clip(q, -_GRID_CLIP, _GRID_CLIP, out=q)
    fl = np.floor(q / _TILE_DIMS)
    fl *= _TILE_DIMS
    q -= fl
    i = q.astype(np.int32)  # q ≥ −ε here: truncation gives 0 for it
    np.minimum(i, _TILE_LAST, out=i)  # q may round up to the tile's size
    fr = np.subtract(q, i, dtype=np.float32)
    nx, ny, nz = _TILE
    blend_uv = blend_w = None
    for off, wt in zip(offsets, weights):
        ij = i + off
        ij -= (ij > _TILE_LAST) * _TILE_INT
        base = ij[0] * np.int32(ny + 1)
        base += ij[1]
        base *= np.int32(nz + 1)
        base += ij[2]
        idx = np.add(_TILE_CORNERS, base).astype(np.intp)
        vuv = tab_uv.take(idx, mode="clip")
        vw = tab_w.take(idx, mode="clip")
        vuv *= np.float32(wt)
        vw *= np.float32(wt)
        if blend_uv is None:
            blend_uv, blend_w = vuv, vw
        else:
            blend_uv += vuv
            blend_w += vw
    fa, fb, fc = fr
    out = []
    for vals in (blend_uv, blend_w):
        d = vals[4:8] - vals[0:4]
        d *= fa
        d += vals[0:4]
        e = d[2:4] - d[0:2]
        e *= fb
        e += d[0:2]
        r = e[1] - e[0]
        r *= fc
        r += e[0]
        out.append(r)
    return out[0], out[1]


def _gusts(wind: "WindField", along: np.ndarray, unit: float, g: float, length: float) -> np.ndarray:
    """Sum of gust envelopes minus their mean, at along-wind positions ``along`` (in units of
    ``unit`` metres).

    Gusts are plane fronts, so the sum is a function of ``along`` only: it is evaluated on
    a 1-D grid of spacing GUST_RISE·L/8 over the points' span and interpolated (relative
    error < 0.5 %), or directly where the span is too long for that."""
    rg = wind.gust_rate / 60.0
    per_m = rg / max(wind.speed, 1e-6)  # gust count per metre (still air carries no gusts)
    if not GUST_RISE * length * per_m > 1e-12:  # gusts so rare they never come
        return np.zeros_like(along)
    sr = min(GUST_RISE * length * per_m, _GUST_MAX_WIDTH[0])
    sd = min(GUST_DECAY * length * per_m, _GUST_MAX_WIDTH[1])
    step = 0.125 * sr / per_m  # metres, on a lattice fixed in space (chunk-independent)
    f = along * (unit / step)
    lo, hi = float(f.min()), float(f.max())
    if -(2.0**50) < lo and hi < 2.0**50 and hi - lo <= 4096:  # (a lattice of int64 indices)
        lo_i = math.floor(lo)
        ys = _gust_sum(wind.seed, g - (step * np.arange(lo_i, math.floor(hi) + 2)) * per_m, sr, sd)
        i = np.floor(f)
        f -= i
        j = i.astype(np.intp)
        j -= lo_i
        out = ys[j + 1]
        y0 = ys[j]
        out -= y0
        out *= f
        out += y0
        return out
    return _gust_sum(wind.seed, g - along * (unit * per_m), sr, sd)


def _gust_sum(seed: int, gam: np.ndarray, sr: float, sd: float) -> np.ndarray:
    """Σ_k A_k·env(γ − c_k) − mean, gust k centred at c_k = k + jitter, γ in gust counts."""
    gam = np.clip(gam, -(2.0**50), 2.0**50)
    kf = np.floor(gam)
    lo, hi = -math.ceil(4.0 * sd + 1.0), math.ceil(4.0 * sr + 1.0)
    m = np.arange(lo, hi + 1, dtype=np.float64)[:, None]
    k = kf[None, :] + m  # (neighbours, n)
    u = _hash_uniform(seed, 31, k.astype(np.int64).ravel(), 2).reshape(*k.shape, 2)
    x = gam[None, :] - (k + _GUST_JITTER * (u[..., 0] - 0.5))
    x /= np.where(x >= 0.0, sd, sr)
    np.clip(x, -40.0, 40.0, out=x)  # exp(−800) is 0 already; no overflow for tiny widths
    env = np.exp(-0.5 * x * x)
    env *= 0.5 + u[..., 1]
    total = env.sum(axis=0)
    total -= math.sqrt(0.5 * math.pi) * (sr + sd)  # mean of A (1) × area per gust
    return total


def _ratio_frame(frame: np.ndarray) -> np.ndarray:
    """The wind frame's rows (along, up, across) scaled by the components' σ ratios."""
    return frame * np.asarray(SIGMA_RATIOS)[:, None]


@lru_cache(maxsize=8)
def _layer_offset(seed: int, layer: int, cycle: int) -> np.ndarray:
    """(3, 1) int32 whole-cell shift of a layer of the tile during one of its cycles."""
    where = _hash_uniform(seed, 20 + layer, np.array([cycle]), 3)[0] * _TILE
    off = np.minimum(where.astype(np.int32), np.array(_TILE, np.int32) - 1)[:, None]
    off.setflags(write=False)
    return off


def _sample_physical(wind: "WindField", p: np.ndarray, t: float, out: np.ndarray) -> None:
    for start in range(0, p.shape[0], _CHUNK):
        stop = min(start + _CHUNK, p.shape[0])
        _physical_chunk(wind, p[start:stop], t, out[start:stop])


def _physical_chunk(wind: "WindField", p: np.ndarray, t: float, out: np.ndarray) -> None:
    length = wind.length_scale
    top = wind.canopy_height
    speed = wind.speed
    frame = wind._frame
    a, s, g = wind._clocks(t)
    g = math.fmod(g, 2.0**40)  # the gust sequence is hashed: any shift of it is as good
    table = _physical_table(wind.beta_u, wind.beta_vw, wind.seed)
    cell = length / _CELLS_PER_L
    k = p.shape[0]
    pc = np.clip(p, -_COORD_CLIP, _COORD_CLIP)
    q = (frame * (1.0 / cell)) @ pc.T  # (3, k) cells along, up, across the wind
    gust = None
    if wind.gust_strength > 0.0 and wind.gust_rate > 0.0:
        gust = _gusts(wind, q[0], cell, g, length)
    weights, offsets = [], []
    for j in (0, 1):
        phase = min(max(s + 0.5 * j, -2.0**62), 2.0**62)
        cycle = math.floor(phase)
        weights.append(math.sin(math.pi * (phase - cycle)))
        offsets.append(_layer_offset(wind.seed, j, cycle))
    q[0] -= math.fmod(a / cell, _TILE[0])
    uv, lat = _trilinear(table, q, offsets, weights)
    mean, sigma = _canopy(p[:, 1], top)
    sigma *= wind.turbulence * speed
    comps = np.empty((3, k))  # along, up, across, each over its σ ratio
    for c, x in enumerate((uv.real, uv.imag, lat)):
        np.multiply(x, sigma, out=comps[c])
    if gust is not None:
        gust *= wind.gust_strength
        gust += 1.0
        mean *= gust
    mean *= speed / SIGMA_RATIOS[0]
    comps[0] += mean
    np.matmul(comps.T, _ratio_frame(frame), out=out)
