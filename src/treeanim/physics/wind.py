"""The three-dimensional 1/f^β wind field of Hu, Chiba & He (2012), §4.3 (Eqs. 13–18).

Three independent periodic noise grids (``fbm_noise``) give the along-wind (u), vertical (v)
and lateral (w) turbulence. ``WindField`` samples them by periodic trilinear interpolation,
shapes them with the logarithmic mean profile (Eq. 16) and the normalisation of Eq. 17, and
turns the result into a world velocity along the user's wind direction (Eq. 18).

Choices made here (DESIGN §7 leaves them open):

* **Grid frame.** The grids are sampled in the *wind's own frame*: a point is scaled by the
  bounds to [0, 1]³, then to grid units (× (N − 1)), and its grid coordinates are its
  components along (û, v̂, ŵ) = (along wind, vertical, lateral). For a wind along +x this is
  exactly Eq. 17; for any other direction the frozen turbulence still travels downwind (at
  c5 cells/s) and drifts laterally (c6 cells/s). Changing the direction rotates the sampling
  frame, so the turbulence seen by a fixed point jumps when the direction changes.
* **Height.** The mean profile uses the world height h = y in metres (ground at y = 0), not
  the scaled coordinate: W(h) = c1·ln(c2·h) for h > 1/c2, else 0.
* **Defaults.** ``c2 = 50 / H`` (the profile starts at 2 % of the tree top H, the top of
  the bounds) and ``c1 = 1 / ln(c2·H)`` so W(H) = 1 and ``speed`` is the mean-profile speed at
  the tree top. ``c3 = 0.5``, ``c4 = 1.0``, ``c5 = 4`` cells/s, ``c6 = 0.5`` cells/s.
"""

from __future__ import annotations

import math
import operator
import threading
from functools import lru_cache

import numpy as np
import scipy.fft

from .checks import finite_float, finite_vector3

__all__ = ["fbm_noise", "WindField"]

#: Default bounds ((x0, y0, z0), (x1, y1, z1)) in metres, until a Simulation fits the field.
DEFAULT_BOUNDS = ((-5.0, 0.0, -5.0), (5.0, 10.0, 5.0))
#: Refused above this wind speed (m/s): far beyond any wind, and it keeps the field finite.
MAX_SPEED = 1000.0
#: Largest grid edge accepted (memory grows as N³).
MAX_GRID = 256
#: Largest |β| accepted (β of 1/f noise is 0 … 3 in practice).
MAX_BETA = 10.0
#: Largest c1, c3, c4 accepted (anything near it is meaningless; it keeps the field finite).
MAX_COEFF = 1000.0
#: Bounds must lie within ±_MAX_COORD m and be at least _MIN_EXTENT m thick on each axis.
_MAX_COORD = 1e9
_MIN_EXTENT = 1e-9
#: Points per vectorised pass of sample() (bounds the scratch memory).
_CHUNK = 16384
#: A direction whose horizontal part is at most this fraction of its length is "vertical".
_VERTICAL_TOL = 1e-6
#: Noise look-ups clip world coordinates to ±this (m); float64 still resolves a cell there.
_COORD_CLIP = 1e12
#: ... and grid coordinates to ±2^40 cells, where q mod N is still exact.
_GRID_CLIP = 2.0**40


# ----------------------------------------------------------------------------- validation


def _in_range(name: str, value, lo: float, hi: float, what: str = "") -> float:
    x = finite_float(name, value)
    if not lo <= x <= hi:
        raise ValueError(f"{name} must be in [{lo:g}, {hi:g}]{what}, got {value!r}")
    return x


def _integer(name: str, value, lo: int, hi: int | None = None) -> int:
    if isinstance(value, bool):
        raise ValueError(f"{name} must be an integer, got {value!r}")
    try:
        n = operator.index(value)
    except TypeError:
        raise ValueError(f"{name} must be an integer, got {value!r}") from None
    if n < lo or (hi is not None and n > hi):
        upper = f" and at most {hi}" if hi is not None else ""
        raise ValueError(f"{name} must be at least {lo}{upper}, got {n}")
    return n


def _bounds(value, name: str = "bounds") -> np.ndarray:
    try:
        b = np.array(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(
            f"{name} must be ((x0, y0, z0), (x1, y1, z1)) in metres, got {value!r}"
        ) from None
    if b.shape != (2, 3):
        raise ValueError(
            f"{name} must be ((x0, y0, z0), (x1, y1, z1)) in metres, got shape {b.shape}"
        )
    if not np.all(np.isfinite(b)):
        raise ValueError(f"{name} must be finite, got {value!r}")
    return b


def _check_extent(b: np.ndarray, name: str = "bounds") -> None:
    if np.abs(b).max() > _MAX_COORD:
        raise ValueError(f"{name} must lie within ±{_MAX_COORD:g} m, got {b.tolist()}")
    ext = b[1] - b[0]
    if not np.all(ext >= _MIN_EXTENT):
        raise ValueError(
            f"{name} must have a positive extent on every axis (x1 > x0, y1 > y0, z1 > z0), "
            f"got extents {tuple(float(e) for e in ext)}"
        )


# ----------------------------------------------------------------------------- 1/f^β noise


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
    beta = _in_range("beta", beta, -MAX_BETA, MAX_BETA)
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


# ----------------------------------------------------------------------------- wind field


class WindField:
    """Turbulent 3-D wind over a tree (Eqs. 13–18), sampled at any points and time.

    Parameters
    ----------
    direction : array_like of 3 floats, default (1, 0, 0)
        Wind direction in world coordinates (y up); only its direction is used. It must have
        a horizontal part; a zero vector means calm (``sample`` returns zeros).
    speed : float, default 5.0
        Wind speed in m/s at the tree top (the mean profile is 1 there), in [0, 1000].
        0 means calm.
    grid : int, default 32
        Edge N of the three N³ noise grids, in [4, 256].
    beta_u, beta_vw : float, default 1.67 and 1.33
        Spectral exponents of the along-wind and of the vertical and lateral noise (Eq. 15),
        in [−10, 10].
    turbulence : float, default 1.5
        λ of Eq. 17, the noise scaling factor, in [1, 2].
    c1 : float or None, default None
        Mean-profile scale of Eq. 16, in [0, 1000]. None: 1 / ln(c2·H), so W(H) = 1 at the
        top H of the bounds.
    c2 : float or None, default None
        Mean-profile constant of Eq. 16 in 1/m, in [1e-12, 1e12]; the profile is zero below
        h = 1/c2. None: 50 / H, i.e. the wind starts at 2 % of the tree's height.
    c3 : float, default 0.5
        Vertical turbulence scale of Eq. 17, in [0, 1000].
    c4 : float, default 1.0
        Lateral turbulence scale of Eq. 17, in [0, 1000].
    c5 : float, default 4.0
        Downwind speed of the frozen turbulence, in grid cells per second (Eq. 17).
    c6 : float, default 0.5
        Lateral drift of the frozen turbulence, in grid cells per second (Eq. 17).
    seed : int, default 0
        Seed of the noise; component c (0 = u, 1 = v, 2 = w) is
        ``fbm_noise(grid, beta, (seed, c))``.
    bounds : ((x0, y0, z0), (x1, y1, z1)) or None
        Box in metres that maps onto the grid; None means ((−5, 0, −5), (5, 10, 5)) until a
        Simulation calls ``fit`` with its tree's rest bounding box. Every extent must be
        positive (at least 1e-9 m) and the box within ±1e9 m; its top y1 is H.

    Notes
    -----
    The grids are sampled in the wind frame (û along the wind, v̂ vertical, ŵ lateral):
    a point's grid coordinates are its components along (û, v̂, ŵ) after scaling the bounds
    to [0, N − 1]³, shifted by (c5·t, 0, c6·t). ``direction``, ``speed``, ``turbulence`` and
    c1 … c6 can be changed at any time at no cost; changing ``grid``, ``beta_u``,
    ``beta_vw`` or ``seed`` rebuilds the grids (cached). All setters validate their value
    and raise ``ValueError`` naming the argument.

    Eq. 17 makes the speed of each sample W·(1 + λ(s2/s1 − 0.5)); the mean of that factor
    over one seed's grids is near 1 (about 0.85–1.0), so ``speed`` is the tree-top speed of
    the mean profile, and the measured mean there is a little lower. The noise grids are
    standardised to exactly [−0.5, 0.5], which leaves each a small residual mean, so one
    seed's mean wind can be a few degrees off ``direction`` (the average over seeds is not).
    Where s2 = 0 (no direction) the wind is zero. Interpolation runs in float32 (relative
    error ~1e-7); ``sample`` keeps per-thread scratch buffers, so it is thread-safe.

    Examples
    --------
    >>> wind = WindField(direction=(1, 0, 1), speed=8.0)
    >>> wind.sample([[0.0, 5.0, 0.0], [1.0, 9.0, 2.0]], t=0.5).shape
    (2, 3)
    """

    def __init__(
        self,
        direction=(1, 0, 0),
        speed: float = 5.0,
        grid: int = 32,
        beta_u: float = 1.67,
        beta_vw: float = 1.33,
        turbulence: float = 1.5,
        c1: float | None = None,
        c2: float | None = None,
        c3: float = 0.5,
        c4: float = 1.0,
        c5: float = 4.0,
        c6: float = 0.5,
        seed: int = 0,
        bounds=None,
    ):
        self._grid = _integer("grid", grid, 4, MAX_GRID)
        self._beta_u = _in_range("beta_u", beta_u, -MAX_BETA, MAX_BETA)
        self._beta_vw = _in_range("beta_vw", beta_vw, -MAX_BETA, MAX_BETA)
        self._seed = _integer("seed", seed, 0)
        self._c1 = None if c1 is None else _in_range("c1", c1, 0.0, MAX_COEFF)
        self._c2 = None if c2 is None else self._check_c2(c2)
        b = _bounds(DEFAULT_BOUNDS if bounds is None else bounds)
        _check_extent(b)
        self._constants(b, self._c1, self._c2)
        self._bounds = b
        self.direction = direction
        self.speed = speed
        self.turbulence = turbulence
        self.c3 = c3
        self.c4 = c4
        self.c5 = c5
        self.c6 = c6
        self._tables = None  # padded, raveled float32 grids, built on first use
        self._local = threading.local()  # per-thread scratch buffers for sample()

    # -- cheap parameters ------------------------------------------------------------------

    @property
    def direction(self) -> np.ndarray:
        """Wind direction as given (3,), world; a zero vector means calm."""
        return self._direction.copy()

    @direction.setter
    def direction(self, value) -> None:
        d = finite_vector3("direction", value)
        big = np.abs(d).max()
        if big == 0.0:
            self._direction, self._frame = d, np.zeros((3, 3))
            return
        u = d / big
        u /= np.sqrt(u @ u)
        horizontal = math.hypot(u[0], u[2])
        if horizontal <= _VERTICAL_TOL:
            raise ValueError(
                "wind direction must have a horizontal component (x or z); "
                f"{tuple(float(x) for x in d)} points straight up or down. "
                "Use a zero vector or speed 0 for calm."
            )
        # Eq. 18: û = v_wind/|v_wind|, ŵ = û × ŷ normalised (lateral), v̂ = ŵ × û (vertical).
        w = np.array([-u[2], 0.0, u[0]]) / horizontal
        v = np.cross(w, u)
        self._direction, self._frame = d, np.stack([u, v, w])

    @property
    def frame(self) -> np.ndarray:
        """(3, 3) rows û (along wind), v̂ (vertical), ŵ (lateral), world; zeros when calm."""
        return self._frame.copy()

    @property
    def speed(self) -> float:
        """Wind speed at the tree top, m/s, in [0, 1000]."""
        return self._speed

    @speed.setter
    def speed(self, value) -> None:
        self._speed = _in_range("speed", value, 0.0, MAX_SPEED, " m/s")

    @property
    def calm(self) -> bool:
        """True when the speed is 0 or the direction is a zero vector."""
        return self._speed == 0.0 or not self._frame.any()

    @property
    def turbulence(self) -> float:
        """λ of Eq. 17, in [1, 2]."""
        return self._turbulence

    @turbulence.setter
    def turbulence(self, value) -> None:
        self._turbulence = _in_range("turbulence", value, 1.0, 2.0)

    @property
    def c1(self) -> float:
        """Effective c1 of Eq. 16 (set None for 1 / ln(c2·H))."""
        return self._profile_constants()[0]

    @c1.setter
    def c1(self, value) -> None:
        c1 = None if value is None else _in_range("c1", value, 0.0, MAX_COEFF)
        self._constants(self._bounds, c1, self._c2)
        self._c1 = c1

    @property
    def c2(self) -> float:
        """Effective c2 of Eq. 16 in 1/m (set None for 50 / H)."""
        return self._profile_constants()[1]

    @c2.setter
    def c2(self, value) -> None:
        c2 = None if value is None else self._check_c2(value)
        self._constants(self._bounds, self._c1, c2)
        self._c2 = c2

    @property
    def c3(self) -> float:
        """Vertical turbulence scale of Eq. 17."""
        return self._c3

    @c3.setter
    def c3(self, value) -> None:
        self._c3 = _in_range("c3", value, 0.0, MAX_COEFF)

    @property
    def c4(self) -> float:
        """Lateral turbulence scale of Eq. 17."""
        return self._c4

    @c4.setter
    def c4(self, value) -> None:
        self._c4 = _in_range("c4", value, 0.0, MAX_COEFF)

    @property
    def c5(self) -> float:
        """Downwind speed of the frozen turbulence, grid cells per second."""
        return self._c5

    @c5.setter
    def c5(self, value) -> None:
        self._c5 = finite_float("c5", value)

    @property
    def c6(self) -> float:
        """Lateral drift of the frozen turbulence, grid cells per second."""
        return self._c6

    @c6.setter
    def c6(self, value) -> None:
        self._c6 = finite_float("c6", value)

    # -- bounds and the mean profile ---------------------------------------------------------

    @property
    def bounds(self) -> np.ndarray:
        """(2, 3) box ((x0, y0, z0), (x1, y1, z1)) in metres that maps onto the grid."""
        return self._bounds.copy()

    @bounds.setter
    def bounds(self, value) -> None:
        b = _bounds(value)
        _check_extent(b)
        self._constants(b, self._c1, self._c2)
        self._bounds = b

    def fit(self, bounds) -> None:
        """Fit the field to a tree's rest bounding box (what a Simulation calls).

        Like setting ``bounds``, except that an axis of (near) zero extent — a straight
        vertical beam has no width — is widened symmetrically to 10 % of the largest extent.

        Parameters
        ----------
        bounds : ((x0, y0, z0), (x1, y1, z1))
            The box in metres, e.g. ``(rest_positions.min(0), rest_positions.max(0))``.

        Raises
        ------
        ValueError
            If the box is not finite, is inverted on some axis, is a single point, or its
            top is not above the ground (with the default profile).
        """
        b = _bounds(bounds)
        ext = b[1] - b[0]
        if np.any(ext < 0):
            raise ValueError(f"bounds must have x1 >= x0, y1 >= y0, z1 >= z0, got {b.tolist()}")
        largest = ext.max()
        if not largest > 0:
            raise ValueError(f"bounds must not be a single point, got {b.tolist()}")
        thin = ext <= 1e-6 * largest
        if thin.any():
            mid = 0.5 * (b[0] + b[1])
            half = 0.05 * largest
            b[0, thin] = mid[thin] - half
            b[1, thin] = mid[thin] + half
        self.bounds = b

    @staticmethod
    def _check_c2(value) -> float:
        c2 = finite_float("c2", value)
        if not 1e-12 <= c2 <= 1e12:
            raise ValueError(f"c2 must be in [1e-12, 1e12] (1/m), got {value!r}")
        return c2

    @staticmethod
    def _constants(b, c1, c2):
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

    def _profile_constants(self) -> tuple[float, float]:
        return self._constants(self._bounds, self._c1, self._c2)

    def profile(self, h) -> np.ndarray:
        """Mean wind profile W(h) = c1·ln(c2·h) of Eq. 16, 0 below h = 1/c2.

        Parameters
        ----------
        h : array_like
            Heights above the ground in metres (world y).

        Returns
        -------
        numpy.ndarray
            W(h), dimensionless (1 at the top of the bounds by default), same shape as h.
        """
        h = np.asarray(h, dtype=np.float64)
        if not np.all(np.isfinite(h)):
            raise ValueError("h must be finite")
        c1, c2 = self._profile_constants()
        log_h0 = -math.log(c2)
        # ln(c2·h) = ln h − ln(1/c2), written so that no finite h overflows.
        return c1 * (np.log(np.maximum(h, math.exp(log_h0))) - log_h0)

    # -- the grids -----------------------------------------------------------------------------

    @property
    def grid(self) -> int:
        """Grid edge N (rebuilds the grids when changed)."""
        return self._grid

    @grid.setter
    def grid(self, value) -> None:
        self._grid = _integer("grid", value, 4, MAX_GRID)
        self._tables = None

    @property
    def beta_u(self) -> float:
        """Spectral exponent of the along-wind noise (rebuilds the grids when changed)."""
        return self._beta_u

    @beta_u.setter
    def beta_u(self, value) -> None:
        self._beta_u = _in_range("beta_u", value, -MAX_BETA, MAX_BETA)
        self._tables = None

    @property
    def beta_vw(self) -> float:
        """Spectral exponent of the vertical and lateral noise (rebuilds the grids)."""
        return self._beta_vw

    @beta_vw.setter
    def beta_vw(self, value) -> None:
        self._beta_vw = _in_range("beta_vw", value, -MAX_BETA, MAX_BETA)
        self._tables = None

    @property
    def seed(self) -> int:
        """Noise seed (rebuilds the grids when changed)."""
        return self._seed

    @seed.setter
    def seed(self, value) -> None:
        self._seed = _integer("seed", value, 0)
        self._tables = None

    @property
    def grids(self) -> np.ndarray:
        """(3, N, N, N) float64 noise grids FBM_u, FBM_v, FBM_w (Eq. 15), read-only.

        Axes are (along wind, vertical, lateral) grid indices, i.e. (i, j, k) of Eq. 15.
        """
        n, s = self._grid, self._seed
        g = np.stack(
            [
                _cached_grid(n, self._beta_u, s, 0),
                _cached_grid(n, self._beta_vw, s, 1),
                _cached_grid(n, self._beta_vw, s, 2),
            ]
        )
        g.setflags(write=False)
        return g

    def _lookup_tables(self) -> tuple[np.ndarray, np.ndarray]:
        if self._tables is None:
            # One wrap layer on the high side of each axis, so the upper corner of a cell is
            # always index + 1; raveled so one np.take gathers a corner for every point.
            # FBM_u and FBM_v travel together as one complex64 (8-byte gathers), FBM_w alone.
            g = np.pad(self.grids, ((0, 0), (0, 1), (0, 1), (0, 1)), mode="wrap")
            uv = np.empty(g[0].size, dtype=np.complex64)
            uv.real = g[0].ravel()
            uv.imag = g[1].ravel()
            w = g[2].astype(np.float32).ravel()
            self._tables = (uv, w)
        return self._tables

    def _workspace(self, n: int) -> "_Workspace":
        ws = getattr(self._local, "ws", None)
        if ws is None or ws.capacity < n:
            ws = self._local.ws = _Workspace(max(n, 256))
        return ws

    # -- sampling ------------------------------------------------------------------------------

    def sample(self, points, t: float) -> np.ndarray:
        """World wind velocity at ``points`` and time ``t`` (Eqs. 16–18).

        Parameters
        ----------
        points : array_like, shape (K, 3) or (3,)
            World positions in metres (y up). Any finite values; outside the bounds the field
            repeats periodically (the mean profile keeps growing with height).
        t : float
            Time in seconds (moves the frozen turbulence, Eq. 17).

        Returns
        -------
        numpy.ndarray
            (K, 3) float64 wind velocities in m/s ((1, 3) for a single point).

        Raises
        ------
        ValueError
            If ``points`` is not (K, 3) / (3,) or not finite, or ``t`` is not finite.
        """
        try:
            p = np.asarray(points, dtype=np.float64)
        except (TypeError, ValueError):
            raise ValueError(f"points must be an array of shape (K, 3), got {points!r}") from None
        if p.ndim == 1:
            p = p[None, :]
        if p.ndim != 2 or p.shape[1] != 3:
            raise ValueError(f"points must have shape (K, 3), got {np.shape(points)}")
        if not np.all(np.isfinite(p)):
            raise ValueError("points must be finite (found NaN or inf)")
        t = finite_float("t", t)
        k = p.shape[0]
        out = np.zeros((k, 3))
        if self.calm or k == 0:
            return out

        n = self._grid
        tables = self._lookup_tables()
        lo = self._bounds[0]
        scale = (n - 1) / (self._bounds[1] - self._bounds[0])
        # Eq. 17: x(N−1) − c5 t, y(N−1), z(N−1) − c6 t, in the wind frame (see module doc):
        # grid coordinates q = M (p − lo) − shift, M = frame · diag(scale). The shifts are
        # reduced modulo the period N first, so no finite t overflows.
        shift = np.array([_wrap_shift(self._c5, t, n), 0.0, _wrap_shift(self._c6, t, n)])
        m = self._frame * scale[None, :]
        offset = -(m @ lo) - shift
        c1, c2 = self._profile_constants()
        c3, c4 = self._c3, self._c4
        consts = (
            m, offset, n, tables,
            c1, -math.log(c2), c3, c4,
            1.0 / math.sqrt(1.0 + 0.25 * c3 * c3 + 0.25 * c4 * c4),  # 1 / s1
            self._turbulence, self._speed, self._frame,
        )
        ws = self._workspace(min(k, _CHUNK))
        for start in range(0, k, _CHUNK):
            stop = min(start + _CHUNK, k)
            _sample_chunk(p[start:stop], out[start:stop], ws, consts)
        return out

    def __repr__(self) -> str:
        d = ", ".join(f"{x:g}" for x in self._direction)
        return (
            f"WindField(direction=({d}), speed={self._speed:g}, grid={self._grid}, "
            f"beta_u={self._beta_u:g}, beta_vw={self._beta_vw:g}, "
            f"turbulence={self._turbulence:g}, c1={self.c1:.4g}, c2={self.c2:.4g}, "
            f"c3={self._c3:g}, c4={self._c4:g}, c5={self._c5:g}, c6={self._c6:g}, "
            f"seed={self._seed}, bounds={self._bounds.tolist()})"
        )


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
