"""The paper's wind model (Hu, Chiba & He 2012, Eqs. 13–18): 1/f^β noise grids, their sampling
and :class:`PaperWind`, the model registered as ``"paper"``."""

from __future__ import annotations

import math
import threading
from functools import lru_cache
from typing import Annotated

import numpy as np
import scipy.fft

from ...model.declare import Param, settings
from ...validate import float_within
from .field import WindField, WindParams, register_wind_model
from .settings import _CHUNK, _COORD_CLIP, _GRID_CLIP, MAX_BETA, MAX_COEFF, MAX_GRID, _integer


def fbm_noise(n: int, beta: float, seed=0) -> np.ndarray:
    """One periodic 3-D 1/f^β noise grid (Eqs. 14–15).

    The Fourier amplitudes are |k|^−(β+2)/2 (the k = 0 term zero), with uniform random
    phases, so the 3-D power falls off as |k|^−(β+2) and the 1-D power spectrum along any
    axis, which sums the 3-D power over the two other wavenumbers, falls off as k^−β. The
    real field comes from an inverse real FFT; it has zero mean and is then mapped linearly
    onto exactly [−0.5, 0.5] (minimum → −0.5, maximum → +0.5), which leaves a small
    residual mean (typically |mean| ≈ 0.02–0.03).

    On a finite grid the transverse sum stops at the Nyquist wavenumber, so the measured
    1-D slope steepens towards k = n/2 (at n = 64, fitted over k = 2…16, by up to 0.23
    for β = 1); over k ≤ n/8 it is within 0.15 of −β.

    Parameters
    ----------
    n : int
        Grid edge; the result is (n, n, n). In [2, 256].
    beta : float
        Spectral exponent β (1.67 for the along-wind component, 1.33 across, Eq. 15), in
        [−10, 10].
    seed : int, sequence of int or numpy.random.SeedSequence
        Seed for ``numpy.random.default_rng``; the same seed gives the same grid, to the bit.

    Returns
    -------
    numpy.ndarray
        float64 array of shape (n, n, n) with min −0.5 and max +0.5, periodic in each axis.

    Raises
    ------
    ValueError
        If ``n`` is not an integer in [2, 256], ``beta`` is not finite or outside [−10, 10],
        or ``seed`` is not a seed.
    """
    n = _integer("n", n, 2, MAX_GRID)
    beta = float_within("beta", beta, -MAX_BETA, MAX_BETA)
    try:
        rng = np.random.default_rng(seed)
    except (TypeError, ValueError) as exc:
        raise ValueError(
            f"seed must be a non-negative integer (or a numpy SeedSequence), got {seed!r} ({exc})"
        ) from None
    return _fbm(n, beta, rng)


def _fbm(n: int, beta: float, rng: np.random.Generator) -> np.ndarray:
    # Uniform random phases with Hermitian symmetry built in: the phases of the real FFT of
    # Gaussian white noise are uniform and independent (real on the self-conjugate
    # wavenumbers), so the field is real and every |k| gets exactly its amplitude.
    white = scipy.fft.rfftn(rng.standard_normal((n, n, n)), axes=(0, 1, 2))
    mag = np.abs(white)
    mag[mag == 0.0] = 1.0
    phase = white / mag

    k = np.fft.fftfreq(n, 1.0 / n)
    kr = np.fft.rfftfreq(n, 1.0 / n)
    k2 = k[:, None, None] ** 2 + k[None, :, None] ** 2 + kr[None, None, :] ** 2
    k2[0, 0, 0] = 1.0
    # Eq. 14: S = |k|^−(β+2)/2, in log space and normalised so no finite β overflows.
    log_amp = -0.25 * (beta + 2.0) * np.log(k2)
    log_amp[0, 0, 0] = -np.inf  # zero-mean field
    log_amp -= log_amp[np.isfinite(log_amp)].max()
    spectrum = np.exp(log_amp) * phase

    # Eq. 15: inverse FFT, then standardise to [−0.5, 0.5].
    field = scipy.fft.irfftn(spectrum, s=(n, n, n), axes=(0, 1, 2))
    lo, hi = field.min(), field.max()
    if not hi > lo:  # pragma: no cover - only for a degenerate all-zero spectrum
        return np.zeros((n, n, n))
    out = (field - lo) * (1.0 / (hi - lo)) - 0.5
    np.clip(out, -0.5, 0.5, out=out)
    out.flat[np.argmin(field)] = -0.5
    out.flat[np.argmax(field)] = 0.5
    return out


@lru_cache(maxsize=24)
def _cached_grid(n: int, beta: float, seed: int, component: int) -> np.ndarray:
    g = fbm_noise(n, beta, (seed, component))
    g.setflags(write=False)
    return g




class _Workspace:
    """Scratch buffers reused between sample() calls (no page faults on every call)."""

    _SPEC = {
        "pc": (3, np.float64), "q": (3, np.float64), "fl": (3, np.float64),
        "i": (3, np.intp), "fr": (3, np.float32), "b": (1, np.intp), "c": (8, np.intp),
        "va": (8, np.complex64), "vb": (8, np.float32), "da": (4, np.complex64),
        "db": (4, np.float32), "up": (3, np.float64), "s": (2, np.float64),
    }

    def __init__(self, capacity: int):
        self.capacity = capacity
        self.buf = {k: np.empty(r * capacity, dtype=d) for k, (r, d) in self._SPEC.items()}

    def get(self, name: str, shape: tuple[int, ...]) -> np.ndarray:
        return self.buf[name][: math.prod(shape)].reshape(shape)


def _sample_chunk(p, out, ws, consts) -> None:
    (m, offset, n, (tab_uv, tab_w), c1, log_h0, c3, c4, inv_s1, lam, speed, frame) = consts
    k = p.shape[0]
    # Grid coordinates, component-major (3, k). Clipping keeps every product finite and
    # the modulo below exact.
    pc = ws.get("pc", (k, 3))
    np.clip(p, -_COORD_CLIP, _COORD_CLIP, out=pc)
    q = ws.get("q", (3, k))
    np.matmul(m, pc.T, out=q)
    q += offset[:, None]
    np.clip(q, -_GRID_CLIP, _GRID_CLIP, out=q)
    # Periodic: q mod N in [0, N], then cell index (np.floor) and fraction.
    fl = ws.get("fl", (3, k))
    np.multiply(q, 1.0 / n, out=fl)
    np.floor(fl, out=fl)
    fl *= n
    q -= fl
    i = ws.get("i", (3, k))
    np.copyto(i, q, casting="unsafe")  # q >= 0 (up to rounding): truncation is floor
    np.clip(i, 0, n - 1, out=i)
    fr = ws.get("fr", (3, k))
    np.subtract(q, i, out=fr, casting="same_kind")
    # Flattened index of each cell's lower corner in the padded (N+1)³ grid, then 8 corners.
    mp = n + 1
    b = ws.get("b", (k,))
    np.multiply(i[0], mp, out=b)
    b += i[1]
    b *= mp
    b += i[2]
    c = ws.get("c", (8, k))
    np.add(_corner_offsets(mp)[:, None], b, out=c)
    va = ws.get("va", (8, k))
    vb = ws.get("vb", (8, k))
    tab_uv.take(c, out=va, mode="clip")
    tab_w.take(c, out=vb, mode="clip")
    # Trilinear interpolation: lerp along, then vertical, then lateral.
    fa, fb, fc = fr
    res = []
    for vals, d in ((va, ws.get("da", (4, k))), (vb, ws.get("db", (4, k)))):
        np.subtract(vals[4:8], vals[0:4], out=d)
        d *= fa
        d += vals[0:4]
        e = vals[0:2]
        np.subtract(d[2:4], d[0:2], out=e)
        e *= fb
        e += d[0:2]
        r = e[1]
        r -= e[0]
        r *= fc
        r += e[0]
        res.append(r)
    # Eq. 17: U' = (FBM_u + 0.5, c3 FBM_v, c4 FBM_w).
    up = ws.get("up", (3, k))
    np.add(res[0].real, 0.5, out=up[0])
    np.multiply(res[0].imag, c3, out=up[1])
    np.multiply(res[1], c4, out=up[2])
    s2, mag = ws.get("s", (2, k))
    np.einsum("ij,ij->j", up, up, out=s2)
    np.sqrt(s2, out=s2)
    # Eq. 16: W(h) = c1 ln(c2 h) = c1 (ln h − ln(1/c2)), zero below h = 1/c2.
    np.maximum(p[:, 1], math.exp(log_h0), out=mag)
    np.log(mag, out=mag)
    mag -= log_h0
    mag *= c1 * speed
    # Eq. 17: s = W (1 + λ(s2/s1 − 0.5)) / s2, with no wind where s2 = 0.
    scale = ws.get("fl", (k,))
    np.multiply(s2, lam * inv_s1, out=scale)
    scale += 1.0 - 0.5 * lam
    mag *= scale
    np.divide(mag, s2, out=mag, where=s2 > 1e-12)
    mag[s2 <= 1e-12] = 0.0
    # Eq. 18: U = speed (U_u û + U_v v̂ + U_w ŵ).
    np.matmul(up.T, frame, out=out)
    out *= mag[:, None]


def _wrap_shift(rate: float, t: float, n: int) -> float:
    """rate·t modulo n, computed without overflow for any finite rate and t."""
    if rate == 0.0:
        return 0.0
    period = n / abs(rate)
    if math.isfinite(period):
        t = math.fmod(t, period)
    return math.fmod(rate * t, n)


@lru_cache(maxsize=8)
def _corner_offsets(mp: int) -> np.ndarray:
    d = np.arange(2)
    off = (d[:, None, None] * mp + d[None, :, None]) * mp + d[None, None, :]
    return off.reshape(8)


def profile_constants(b: np.ndarray, c1: float | None, c2: float | None) -> tuple[float, float]:
    """(c1, c2) of Eq. 16 for the bounds ``b``: None gives the defaults, c2 = 50 / y1 (the
    profile starts at 2 % of the top) and c1 = 1 / ln(c2·y1) (W = 1 at the top). ValueError
    where the bounds cannot carry them."""
    top = float(b[1, 1])
    if c2 is None:
        if not top > 0.0:
            raise ValueError(
                "bounds top y1 must be above the ground (y1 > 0) for the default log "
                f"wind profile (c2 = 50 / y1), got y1 = {top}"
            )
        c2 = 50.0 / top
    if c1 is None:
        log_top = math.log(c2) + math.log(top) if top > 0.0 else -math.inf
        if not log_top >= 1.0 / MAX_COEFF:
            raise ValueError(
                "with c1 = None (W = 1 at the top of the bounds), c2·y1 must exceed "
                f"{math.exp(1.0 / MAX_COEFF):.4f}; got c2 = {c2}, y1 = {top}"
            )
        c1 = 1.0 / log_top
    return c1, c2


def lookup_tables(grids: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The noise grids (3, N, N, N) as :func:`_sample_chunk` reads them: one wrap layer on the
    high side of each axis, so the upper corner of a cell is always index + 1, and raveled so
    one np.take gathers a corner for every point; FBM_u and FBM_v travel together as one
    complex64 (8-byte gathers), FBM_w alone as float32."""
    g = np.pad(grids, ((0, 0), (0, 1), (0, 1), (0, 1)), mode="wrap")
    uv = np.empty(g[0].size, dtype=np.complex64)
    uv.real = g[0].ravel()
    uv.imag = g[1].ravel()
    return uv, g[2].astype(np.float32).ravel()


def _sample_paper(wind: PaperWind, p: np.ndarray, t: float, out: np.ndarray) -> None:
    """Eqs. 13–18 at the points ``p`` (K, 3) and time ``t``, into ``out`` (K, 3), in chunks."""
    k = p.shape[0]
    w = wind._params
    n = w.grid
    tables = wind._lookup_tables()
    lo = wind._bounds[0]
    scale = (n - 1) / (wind._bounds[1] - wind._bounds[0])
    # Eq. 17: x(N−1) − c5 t, y(N−1), z(N−1) − c6 t, in the wind frame (see module doc):
    # grid coordinates q = M (p − lo) − shift, M = frame · diag(scale). The shifts are
    # reduced modulo the period N first, so no finite t overflows.
    shift = np.array([_wrap_shift(w.c5, t, n), 0.0, _wrap_shift(w.c6, t, n)])
    m = wind._frame * scale[None, :]
    offset = -(m @ lo) - shift
    c1, c2 = profile_constants(wind._bounds, w.c1, w.c2)
    c3, c4 = w.c3, w.c4
    consts = (
        m, offset, n, tables,
        c1, -math.log(c2), c3, c4,
        1.0 / math.sqrt(1.0 + 0.25 * c3 * c3 + 0.25 * c4 * c4),  # 1 / s1
        w.turbulence, w.speed, wind._frame,
    )
    ws = wind._workspace(min(k, _CHUNK))
    for start in range(0, k, _CHUNK):
        stop = min(start + _CHUNK, k)
        _sample_chunk(p[start:stop], out[start:stop], ws, consts)


def _coefficient(hi: float, help: str, **kw) -> Param:
    return Param(0.0, hi, help=help, **kw)


@settings("")
class PaperParams(WindParams):
    """The paper's settings (Eqs. 13–18); ``speed`` is the mean-profile speed at the tree top."""

    grid: Annotated[int, Param(4, MAX_GRID, integer=True, help="Edge N of the three N³ noise grids "
                               "(rebuilds them when changed).")] = 32
    beta_u: Annotated[float, Param(-MAX_BETA, MAX_BETA, label="β_u", help="Spectral exponent of the "
                                   "along-wind noise (Eq. 15; rebuilds the grids).")] = 1.67
    beta_vw: Annotated[float, Param(-MAX_BETA, MAX_BETA, label="β_vw", help="Spectral exponent of the "
                                    "vertical and lateral noise (Eq. 15; rebuilds the grids).")] = 1.33
    turbulence: Annotated[float, Param(1.0, 2.0, label="turbulence λ", help="λ of Eq. 17.")] = 1.5
    c1: Annotated[float, _coefficient(MAX_COEFF, "c1 of Eq. 16; None: 1 / ln(c2·H), so W(H) = 1.")] | None = None
    c2: Annotated[float, Param(1e-12, 1e12, unit="1/m", help="c2 of Eq. 16, W = 0 below h = 1/c2; "
                               "None: 50 / H (2 % of the tree top H).")] | None = None
    c3: Annotated[float, _coefficient(MAX_COEFF, "Vertical turbulence scale of Eq. 17.")] = 0.5
    c4: Annotated[float, _coefficient(MAX_COEFF, "Lateral turbulence scale of Eq. 17.")] = 1.0
    c5: Annotated[float, Param(-math.inf, math.inf, unit="cells/s", help="Downwind speed of the frozen "
                               "turbulence (Eq. 17).")] = 4.0
    c6: Annotated[float, Param(-math.inf, math.inf, unit="cells/s", help="Lateral drift of the frozen "
                               "turbulence (Eq. 17).")] = 0.5
    seed: Annotated[int, Param(0, math.inf, integer=True, help="Seed of the noise grids (rebuilds them).")] = 0


@register_wind_model("paper")
class PaperWind(WindField):
    """The paper's wind: Hu, Chiba & He (2012) Eqs. 13–18 exactly as before issue 11 (same
    samples, bit for bit, for the same settings; ``tests/data/wind_paper_reference.npz``).

    Three periodic N³ 1/f^β noise grids (:func:`fbm_noise`) sampled trilinearly in the wind's
    frame in the tree's box (``bounds``, N − 1 cells across it), drifting c5 cells/s downwind
    and c6 across; the log profile W(h) = c1·ln(c2·h) (Eq. 16), Eq. 17's normalisation and
    Eq. 18's frame. Outside the box the field repeats periodically. Settings: :class:`PaperParams`
    (``grid``, ``beta_u``, ``beta_vw``, ``turbulence`` = λ, ``c1`` … ``c6``, ``seed``) and
    :class:`WindField`'s. The bounds' top y1 is H (and must be above the ground while c1 or c2
    is automatic).

    Notes
    -----
    Eq. 17 makes the speed of each sample W·(1 + λ(s2/s1 − 0.5)); the mean of that factor over
    one seed's grids is near 1 (about 0.85–1.0). The grids are standardised to exactly
    [−0.5, 0.5], which leaves each a small residual mean, so one seed's mean wind can be a few
    degrees off ``direction``. Interpolation runs in float32. Changing the direction rotates
    the sampling frame about the bounds, so the turbulence seen by a fixed point jumps.
    """

    Params = PaperParams

    def __init__(self, *args, **kwargs):
        self._tables = None  # padded, raveled float32 grids, built on first use
        self._local = threading.local()  # per-thread scratch buffers for sample()
        super().__init__(*args, **kwargs)

    def _check(self, params: PaperParams, bounds: np.ndarray) -> None:
        profile_constants(bounds, params.c1, params.c2)

    def _changing(self, params: PaperParams, bounds: np.ndarray) -> None:
        old = self._params
        if (params.grid, params.beta_u, params.beta_vw, params.seed) != (old.grid, old.beta_u, old.beta_vw, old.seed):
            self._tables = None

    @property
    def c1(self) -> float:
        """Effective c1 of Eq. 16 (set None for 1 / ln(c2·H))."""
        return profile_constants(self._bounds, self._params.c1, self._params.c2)[0]

    @c1.setter
    def c1(self, value) -> None:
        self._set(c1=value)

    @property
    def c2(self) -> float:
        """Effective c2 of Eq. 16 in 1/m (set None for 50 / H)."""
        return profile_constants(self._bounds, self._params.c1, self._params.c2)[1]

    @c2.setter
    def c2(self, value) -> None:
        self._set(c2=value)

    def _profile(self, h: np.ndarray) -> np.ndarray:
        """W(h) = c1·ln(c2·h) of Eq. 16: 0 below h = 1/c2, 1 at the top of the bounds by default."""
        c1, c2 = self.c1, self.c2
        log_h0 = -math.log(c2)
        # ln(c2·h) = ln h − ln(1/c2), written so that no finite h overflows.
        return c1 * (np.log(np.maximum(h, math.exp(log_h0))) - log_h0)

    @property
    def grids(self) -> np.ndarray:
        """(3, N, N, N) float64 noise grids FBM_u, FBM_v, FBM_w (Eq. 15), read-only.

        Axes are (along wind, vertical, lateral) grid indices, i.e. (i, j, k) of Eq. 15.
        """
        w = self._params
        g = np.stack([_cached_grid(w.grid, w.beta_u, w.seed, 0), _cached_grid(w.grid, w.beta_vw, w.seed, 1),
                      _cached_grid(w.grid, w.beta_vw, w.seed, 2)])
        g.setflags(write=False)
        return g

    def _lookup_tables(self) -> tuple[np.ndarray, np.ndarray]:
        if self._tables is None:
            self._tables = lookup_tables(self.grids)
        return self._tables

    def _workspace(self, n: int) -> _Workspace:
        ws = getattr(self._local, "ws", None)
        if ws is None or ws.capacity < n:
            ws = self._local.ws = _Workspace(max(n, 256))
        return ws

    def _sample(self, p: np.ndarray, t: float, out: np.ndarray) -> None:
        _sample_paper(self, p, t, out)
