"""The physical wind's turbulence (docs/design.md §12): one periodic von Kármán tile, and the
blocks through which a landscape reads it without repeating.

The tile (:func:`_physical_table`) is 256 × 48 × 64 cells, 16 to the length scale L: 16 L
along the wind, 3 L up and 4 L across; read as it is, it would repeat every 16 L along and
4 L across. :func:`_eddies` reads it through blocks instead, laid out in the frame carried
downwind at the wind speed (so Taylor's frozen turbulence holds): blocks 7 L long along the
wind and, within each, blocks L wide across it. Every pair of blocks reads the tile at its
own whole-cell offset (along, up and across), a hash of the seed and the two blocks' keys
(:func:`_block_offset`). Neighbouring blocks share a ramp L wide about their common edge,
where their weights rise and fall smoothly with w₀² + w₁² = 1 (:func:`_blocks`): the
variance stays exactly one and the field continuous (a block's offset matters only where
its weight is above zero). Across the wind the ramps meet, so a point always blends two
blocks; along it a point is in one block, or in two in a ramp (one point in seven): two or
four places of the tile, 2.3 on average. A block with its ramps reaches half the tile's
period (8 L along, 2 L across), so no two of its points are more than half a period apart,
and points farther apart than that never share an offset: nothing repeats in space (up the
tile still repeats, every 3 L). The across-wind blocks slide across, one block for every
``EVOLUTION_LENGTH`` (4 L) the air travels, one way in the even along-wind blocks and the
other way in the odd ones: so each eddy lives for about 4 L of travel, as before, and
nothing comes back, in space or in time.
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np
import scipy.fft

from ..compiled import njit
from .settings import _GRID_CLIP

#: The physical tile: cells along, up and across the wind; cells per length scale L.
_TILE = (256, 48, 64)
_CELLS_PER_L = 16.0
#: von Kármán: k0 = 1 / (1.339 L) puts the integral scale of (k² + k0²)^−5/6 at L.
_VON_KARMAN = 1.339
#: Integral scales of the vertical and lateral components, in L: the same as the along-wind
#: component's (canopy flows have L_w ≈ h/3; not modelled).
_CROSS_SCALE = 1.0
#: Block lengths along and across the wind and the ramp two neighbours share (cells; the
#: ramp is L): a block with its ramps reaches half the tile's period on its axis, 8 L along
#: and 2 L across.
BLOCK_ALONG = _TILE[0] // 2 - 16
BLOCK_ACROSS = _TILE[2] // 2 - 16
RAMP = 16
#: Flat strides of the padded tile along and up the wind (across: 1).
_DX = (_TILE[1] + 1) * (_TILE[2] + 1)
_DY = _TILE[2] + 1
#: Odd 64-bit constants that spread keys before mixing.
_SPREAD = (np.uint64(0x9E3779B97F4A7C15), np.uint64(0xC2B2AE3D27D4EB4F), np.uint64(0x165667B19E3779F9))


@lru_cache(maxsize=16)
def _stream(seed: int, stream: int) -> np.uint64:
    """The key of one stream of :func:`_hash_uniform`'s numbers for a seed (any size)."""
    return np.uint64((seed * 0xD1B54A32D192ED03 + stream * 0x8CB92BA72F3D8DD7 + 0x632BE59BD9B4E019)
                     & ((1 << 64) - 1))


@njit(cache=True, fastmath=True, error_model="numpy", inline="always")
def _mix(x: np.uint64) -> np.uint64:
    """splitmix64's finaliser: a bijection of uint64 that scatters every bit (wrapping)."""
    x ^= x >> np.uint64(30)
    x *= np.uint64(0xBF58476D1CE4E5B9)
    x ^= x >> np.uint64(27)
    x *= np.uint64(0x94D049BB133111EB)
    x ^= x >> np.uint64(31)
    return x


@njit(cache=True, fastmath=True, error_model="numpy")
def _hash_uniform(base: np.uint64, k: int, lanes: int, lane: int) -> float:
    """A deterministic uniform [0, 1) number: lane ``lane`` of ``lanes`` for the integer key
    ``k`` in the stream ``base`` (:func:`_stream`), by splitmix64 (wrapping uint64)."""
    x = np.uint64(k) * np.uint64(lanes) + np.uint64(lane)
    x = _mix(x * _SPREAD[0] + base)
    return np.float64(x >> np.uint64(11)) * (1.0 / 9007199254740992.0)


@njit(cache=True, fastmath=True, error_model="numpy", inline="always")
def _substream(base: np.uint64, k: int) -> np.uint64:
    """A stream of its own for the integer key ``k`` (a block, a lane of gusts) in ``base``."""
    return _mix(base + np.uint64(k) * _SPREAD[1])


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


@njit(cache=True, fastmath=True, error_model="numpy", inline="always")
def _cell(q: float, n: int) -> tuple[int, np.float32]:
    """(index, float32 fraction) of the cell coordinate ``q`` in a periodic axis of ``n`` cells,
    ``q`` clipped to ±2⁴⁰ cells first (where q mod n is still exact)."""
    q = min(max(q, -_GRID_CLIP), _GRID_CLIP)
    q -= np.floor(q / n) * n
    i = min(int(q), n - 1)  # q ≥ −ε here: truncation gives 0 for it; q may round up to n
    return i, np.float32(q - i)


@njit(cache=True, fastmath=True, error_model="numpy", inline="always")
def _blocks(u: float, half: float) -> tuple[int, int, float, float]:
    """The blocks at ``u`` (in block lengths, blocks [n, n + 1)) with ramps ``half`` blocks
    either side of each edge: (key of the block, key of its nearer neighbour, their
    weights). Across a ramp (τ from 0 to 1) the weights are S(1 − τ) and S(τ) scaled so their
    squares sum to one, S(τ) = τ²(3 − 2τ): a smooth rise, flat at both ends. Outside the
    ramps the neighbour's weight is 0. (No branches: where a point lies is no guess.)"""
    n = np.floor(u)
    t = u - n
    k = np.int64(n)
    right = t >= 0.5
    tau = max(0.5 - 0.5 * (1.0 - t if right else t) / half, 0.0)  # the neighbour's way in
    p = tau * tau * (3.0 - 2.0 * tau)
    q = 1.0 - p  # S(1 − τ)
    norm = 1.0 / math.sqrt(p * p + q * q)  # ≤ √2
    return k, k + (1 if right else -1), q * norm, p * norm


@njit(cache=True, fastmath=True, error_model="numpy", inline="always")
def _block_offset(h: np.uint64, kc: int) -> int:
    """(along, up, across) whole-cell shift into the tile of the across-wind block ``kc`` of
    the along-wind block whose stream is ``h`` (:func:`_substream`): 21 bits of one hash each."""
    nx, ny, nz = _TILE
    x = _mix(h + np.uint64(kc) * _SPREAD[2])
    m = np.uint64(0x1FFFFF)
    oa = np.int64(((x & m) * np.uint64(nx)) >> np.uint64(21))
    ob = np.int64((((x >> np.uint64(21)) & m) * np.uint64(ny)) >> np.uint64(21))
    oc = np.int64((((x >> np.uint64(42)) & m) * np.uint64(nz)) >> np.uint64(21))
    return oa, ob, oc


@njit(cache=True, fastmath=True, error_model="numpy", inline="always")
def _flat(cell: tuple, off: tuple) -> int:
    """Flat index in the padded tile of the first corner of the cell ``cell`` (indices along,
    up, across first) moved by the whole-cell shift ``off``, periodically."""
    nx, ny, nz = _TILE
    ja, jb, jc = cell[0] + off[0], cell[1] + off[1], cell[2] + off[2]
    ja -= nx if ja >= nx else 0
    jb -= ny if jb >= ny else 0
    jc -= nz if jc >= nz else 0
    return (ja * (ny + 1) + jb) * (nz + 1) + jc


@njit(cache=True, fastmath=True, error_model="numpy", inline="always")
def _lerp2(table: np.ndarray, r0: int, r1: int, c: int, w0: np.float32, w1: np.float32, fa: np.float32,
           fb: np.float32, fc: np.float32) -> np.float32:
    """Component ``c`` of two places of the tile (cells' first corners ``r0``, ``r1``) blended
    with the weights ``w0``, ``w1`` at the corners, then interpolated (fractions ``fa``,
    ``fb``, ``fc``), in float32."""
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


@njit(cache=True, fastmath=True, error_model="numpy", inline="always")
def _across_at(qc: float, k: int, s_frac: float) -> tuple[int, float]:
    """(±1, where a point ``qc`` cells across the wind is among the across-wind blocks of the
    along-wind block ``k``, in blocks, less the whole cycles of the evolution): they slide
    one block a cycle, across one way in the even along-wind blocks and the other way in the
    odd ones (see :func:`_eddies`)."""
    way = 1 - 2 * (k & 1)
    return way, qc * (1.0 / BLOCK_ACROSS) + way * s_frac


@njit(cache=True, fastmath=True, error_model="numpy", inline="always")
def _across(table: np.ndarray, cell: tuple, k: int, qc: float, travel: tuple, evolution: tuple,
            base: np.uint64, weight: float) -> tuple:
    """``weight`` times (u, v, w) of the turbulence in the along-wind block ``k`` at ``qc``
    cells across the wind: its across-wind blocks (:func:`_across_at`) and their offsets."""
    way, at = _across_at(qc, k, evolution[0])
    k0, k1, w0, w1 = _blocks(at, 0.5 * RAMP / BLOCK_ACROSS)
    if w1 == 0.0:
        k1 = k0  # (outside a ramp: the same place again, already in the cache)
    h = _substream(base, k - travel[0])
    shift = way * evolution[1]
    r0 = _flat(cell, _block_offset(h, k0 + shift))
    r1 = _flat(cell, _block_offset(h, k1 + shift))
    x0, x1 = np.float32(weight * w0), np.float32(weight * w1)
    fa, fb, fc = cell[3], cell[4], cell[5]
    return (_lerp2(table, r0, r1, 0, x0, x1, fa, fb, fc), _lerp2(table, r0, r1, 1, x0, x1, fa, fb, fc),
            _lerp2(table, r0, r1, 2, x0, x1, fa, fb, fc))


@njit(cache=True, fastmath=True, error_model="numpy", inline="always")
def _eddies(table: np.ndarray, qa: float, qb: float, qc: float, travel: tuple, evolution: tuple,
            base: np.uint64) -> tuple:
    """(u, v, w) of the turbulence in σ units at a point (``qa``, ``qb``, ``qc``) cells along,
    up and across the wind: ``travel`` (:func:`_travel`) the air's downwind travel,
    ``evolution`` (:func:`_evolution`) its evolution, ``base`` the blocks' stream
    (:func:`_stream`).

    The along-wind blocks are counted from where the air was at the start (the travel's
    whole blocks taken off a block's key) and the across-wind ones from where they were (the
    evolution's whole cycles added to, or taken off, theirs), so the cell coordinates stay
    small and exact whatever the time."""
    nx, ny, nz = _TILE
    ia, fa = _cell(qa - travel[2], nx)
    ib, fb = _cell(qb, ny)
    ic, fc = _cell(qc, nz)
    cell = (ia, ib, ic, fa, fb, fc)
    k0, k1, w0, w1 = _blocks((qa - travel[1]) * (1.0 / BLOCK_ALONG), 0.5 * RAMP / BLOCK_ALONG)
    u = v = w = np.float32(0.0)
    for j in range(1 + (w1 > 0.0)):  # (one body: the block, then its neighbour in a ramp)
        du, dv, dw = _across(table, cell, k1 if j else k0, qc, travel, evolution, base, w1 if j else w0)
        u, v, w = u + du, v + dv, w + dw
    return u, v, w

def _travel(a_cells: float) -> tuple[int, float, float]:
    """(whole along-wind blocks, the rest in cells, the travel modulo the tile in cells) of a
    downwind travel of ``a_cells`` cells (clipped to ±2⁶⁰)."""
    a_cells = min(max(a_cells, -2.0**60), 2.0**60)
    blocks = math.floor(a_cells / BLOCK_ALONG)
    rest = a_cells - blocks * BLOCK_ALONG
    return blocks, rest, rest + (blocks * BLOCK_ALONG) % _TILE[0]


def _evolution(s: float) -> tuple[float, int]:
    """(fraction, whole cycles) of the evolution ``s`` cycles (clipped to ±2⁶⁰)."""
    s = min(max(s, -2.0**60), 2.0**60)
    whole = math.floor(s)
    return s - whole, whole
