"""Wind over trees: the physical field (default) and the paper's (Hu, Chiba & He 2012).

``WindField(model="physical")`` (docs/design.md §12, issue 11) is weather-like wind:

* **Turbulence in metres.** Three independent Gaussian fields (along-wind u, vertical v,
  lateral w) on one periodic tile of 96 × 48 × 96 cells covering 8 L × 4 L × 8 L (along,
  up, across the wind), L the along-wind integral length scale (``length_scale``, by
  default the canopy height). The tile is independent of any tree's box, so several trees
  share one field. The 3-D spectrum is (k² + k0²)^−(β+2)/2 with k0 = 1/(1.339 L_c), so the
  spectrum along any line is the von Kármán form (k1² + k0²)^−β/2: f^−β in the inertial
  range, flat below the energy-containing eddies (L_u = L, L_v = L_w = L/3, as in canopy
  flows). Its Fourier amplitudes are pre-compensated for trilinear interpolation (exactly
  along the wind, on average across it), so the spectrum at a fixed point keeps its slope
  up to about half the grid's Nyquist frequency U·12/(2L).
* **Taylor's frozen turbulence.** The tile is carried downwind at the mean speed at the
  canopy top, so a gust reaches a point d metres downwind d/U seconds later and gusts come
  faster in stronger wind.
* **Evolution, no loop.** Two layers of the tile, weighted sin(πs) and |cos(πs)| (their
  squares sum to one, so the variance is steady), evolve with the travelled distance:
  s grows by one every 4 L of travel, and each layer jumps to a new random place in the
  tile (a hash of the seed and the cycle) when its weight is zero. Eddies so live for
  about 4 L / U seconds and nothing repeats: the point's autocorrelation is ~0 beyond a few
  L / U.
* **Canopy profile.** Mean speed ``speed``·ln((y − d)/z0)/ln((h − d)/z0) above the canopy
  height h (d = 0.7 h, z0 = 0.1 h) and ``speed``·exp(a(y/h − 1)) inside it (a ≈ 3.03, so
  the two meet smoothly). Standard deviations σ_u : σ_w(lateral) : σ_v(vertical) =
  1 : 0.75 : 0.5 with σ_u = ``turbulence``·``speed`` at and above h, decaying as
  exp(y/h − 1) inside the canopy (the intensity rises towards the ground).
* **Gusts.** ``gust_rate`` gusts a minute, each a plane front across the wind with a sharp
  rise (0.5 L) and a slower decay (1.5 L) of peak ``gust_strength``·U·A (A uniform in
  [0.5, 1.5]), carried at the wind speed; their mean is subtracted, so they are gusts and
  lulls about the set mean.
* **Mean direction.** Every fluctuation across the wind has zero mean by construction
  (symmetric Gaussian noise, no rescaling), so the long-run mean wind points along
  ``direction``.

``WindField(model="paper")`` keeps the three-dimensional 1/f^β field of §4.3 (Eqs. 13–18)
exactly. Three independent periodic noise grids (``fbm_noise``) give the along-wind (u),
vertical (v) and lateral (w) turbulence. ``WindField`` samples them by periodic trilinear
interpolation, shapes them with the logarithmic mean profile (Eq. 16) and the normalisation
of Eq. 17, and turns the result into a world velocity along the user's wind direction
(Eq. 18). Choices made there (docs/design.md §7 leaves them open):

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

Named winds by Beaufort number (:data:`WIND_PRESETS`, :func:`wind_preset`,
``WindField.from_preset``): calm, breeze, windy, gale, storm.
"""

from __future__ import annotations

import math
import operator
import threading
from functools import lru_cache

import numpy as np
import scipy.fft

from .checks import finite_float, finite_vector3

__all__ = ["fbm_noise", "WindField", "WIND_PRESETS", "wind_preset", "MODELS"]

#: The wind models: weather-like (default) and Hu, Chiba & He's Eqs. 13–18.
MODELS = ("physical", "paper")
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
#: Largest gust strength (fraction of the mean speed) and gust rate (per minute) accepted.
MAX_GUST_STRENGTH = 2.0
MAX_GUST_RATE = 30.0
#: Smallest automatic length scale (m): below it (grass) the eddies are still metres across.
MIN_AUTO_LENGTH = 1.0
#: Travel (in length scales) over which the turbulence evolves through one cycle.
EVOLUTION_LENGTH = 4.0
#: Bounds must lie within ±_MAX_COORD m and be at least _MIN_EXTENT m thick on each axis.
_MAX_COORD = 1e9
_MIN_EXTENT = 1e-9
#: Length scale and canopy height limits (m).
_MIN_LENGTH = 0.01
_MAX_LENGTH = 1e4
#: The physical clocks run for at most this many seconds from their last change.
_TIME_CLIP = 1e12
#: Points per vectorised pass of sample() (bounds the scratch memory).
_CHUNK = 16384
#: A direction whose horizontal part is at most this fraction of its length is "vertical".
_VERTICAL_TOL = 1e-6
#: Noise look-ups clip world coordinates to ±this (m); float64 still resolves a cell there.
_COORD_CLIP = 1e12
#: ... and grid coordinates to ±2^40 cells, where q mod N is still exact.
_GRID_CLIP = 2.0**40

#: Named winds by Beaufort number: speed (m/s at the canopy top, the middle of the
#: Beaufort band), turbulence intensity, gust strength and gusts per minute.
WIND_PRESETS: dict[str, dict] = {
    "calm": dict(beaufort=1, speed=1.0, turbulence=0.2, gust_strength=0.1, gust_rate=1.0),
    "breeze": dict(beaufort=3, speed=4.5, turbulence=0.25, gust_strength=0.25, gust_rate=3.0),
    "windy": dict(beaufort=5, speed=9.5, turbulence=0.3, gust_strength=0.35, gust_rate=4.0),
    "gale": dict(beaufort=8, speed=19.0, turbulence=0.3, gust_strength=0.4, gust_rate=5.0),
    "storm": dict(beaufort=10, speed=26.5, turbulence=0.35, gust_strength=0.5, gust_rate=6.0),
}


def wind_preset(name: str) -> dict:
    """WindField keyword arguments for a named wind (physical model).

    Parameters
    ----------
    name : str
        ``calm`` (Beaufort 1, light air, 1 m/s), ``breeze`` (3, gentle breeze, 4.5 m/s),
        ``windy`` (5, fresh breeze, 9.5 m/s), ``gale`` (8, 19 m/s) or ``storm`` (10,
        26.5 m/s).

    Returns
    -------
    dict
        ``speed``, ``turbulence``, ``gust_strength``, ``gust_rate`` and ``model``.

    Raises
    ------
    ValueError
        If the name is not one of :data:`WIND_PRESETS`.
    """
    if name not in WIND_PRESETS:
        raise ValueError(f"wind preset must be one of {', '.join(WIND_PRESETS)}, got {name!r}")
    kw = {k: v for k, v in WIND_PRESETS[name].items() if k != "beaufort"}
    return dict(kw, model="physical")


# ----------------------------------------------------------------------------- validation


def _optional_length(name: str, value) -> float | None:
    if value is None:
        return None
    return _in_range(name, value, _MIN_LENGTH, _MAX_LENGTH, " m")


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
    """Wind over trees, sampled at any points and time: the physical model or the paper's.

    ``model="physical"`` (the default, docs/design.md §12) is turbulence in metres carried downwind
    at the wind speed (Taylor), evolving along its way so that it never repeats, with a
    von Kármán f^−β spectrum, a canopy profile and gusts; see the module docstring.
    ``model="paper"`` is Hu, Chiba & He (2012) Eqs. 13–18 exactly as before issue 11 (same
    samples, bit for bit, for the same parameters).

    Parameters
    ----------
    direction : array_like of 3 floats, default (1, 0, 0)
        Wind direction in world coordinates (y up); only its direction is used. It must have
        a horizontal part; a zero vector means calm (``sample`` returns zeros).
    speed : float, default 5.0
        Mean wind speed in m/s at the canopy top (physical) or the tree top (paper), in
        [0, 1000]. 0 means calm.
    grid : int, default 32
        Paper: edge N of the three N³ noise grids, in [4, 256]. Unused by the physical model.
    beta_u, beta_vw : float or None
        Spectral exponents of the along-wind and of the vertical and lateral turbulence, in
        [−10, 10]. None: 5/3 and 5/3 (physical, Kolmogorov), 1.67 and 1.33 (paper, Eq. 15).
    turbulence : float or None
        Physical: the along-wind turbulence intensity σ_u/U at the canopy top, in [0, 1];
        None: 0.3. Paper: λ of Eq. 17, in [1, 2]; None: 1.5.
    c1, c2, c3, c4, c5, c6 : float
        Paper only (Eqs. 16–17): c1 in [0, 1000] or None (1 / ln(c2·H)), c2 in [1e-12, 1e12]
        1/m or None (50 / H), c3 and c4 the vertical and lateral scales in [0, 1000] (0.5
        and 1.0), c5 and c6 the downwind and lateral drift in grid cells per second (4 and
        0.5). Kept, and validated, by the physical model, which does not use them.
    seed : int, default 0
        Seed of the noise (both models) and of the gusts.
    bounds : ((x0, y0, z0), (x1, y1, z1)) or None
        Paper: box in metres that maps onto the grid; None means ((−5, 0, −5), (5, 10, 5))
        until a Simulation calls ``fit`` with its tree's rest bounding box. Every extent must
        be positive (at least 1e-9 m) and the box within ±1e9 m; its top y1 is H. Physical:
        only its top y1 is used, as the canopy height when ``canopy_height`` is None.
    model : {"physical", "paper"}, default "physical"
        Which field; fixed at construction (keyword only).
    length_scale : float or None
        Physical: the along-wind integral length scale L of the turbulence in metres, in
        [0.01, 10000]; the vertical and lateral ones are L/3. None: the canopy height (at
        least 1 m). Keyword only.
    canopy_height : float or None
        Physical: the canopy height h in metres, in [0.01, 10000], the height of ``speed``
        and of the canopy profile. None: the top of ``bounds`` (10 m until a Simulation fits
        the field to its tree). Keyword only.
    gust_strength : float, default 0.3
        Physical: mean peak speed of a gust above the mean, as a fraction of the mean
        speed, in [0, 2]. Keyword only.
    gust_rate : float, default 4.0
        Physical: gusts per minute passing a point, in [0, 30]. Keyword only.

    Notes
    -----
    Every setter validates its value and raises a one-line ``ValueError`` naming the
    argument; the old value is kept. ``direction``, ``speed``, ``turbulence``,
    ``length_scale``, ``canopy_height``, ``gust_strength``, ``gust_rate`` and c1 … c6 change
    at no cost; ``beta_u``, ``beta_vw``, ``seed`` (and, for the paper, ``grid``) rebuild
    the noise (cached). Changing the speed, the length scale or the gust rate keeps the
    field continuous in time: the downwind travel, the evolution and the gust clock are
    integrated piecewise from the last sampled time, so ``sample`` is a pure function of
    ``t`` between changes. Turning the wind rotates the field about the world origin.
    ``sample`` is thread-safe.

    Paper model: Eq. 17 makes the speed of each sample W·(1 + λ(s2/s1 − 0.5)); the mean of
    that factor over one seed's grids is near 1 (about 0.85–1.0). The grids are
    standardised to exactly [−0.5, 0.5], which leaves each a small residual mean, so one
    seed's mean wind can be a few degrees off ``direction``. Interpolation runs in float32.

    Examples
    --------
    >>> wind = WindField(direction=(1, 0, 1), speed=8.0)
    >>> wind.sample([[0.0, 5.0, 0.0], [1.0, 9.0, 2.0]], t=0.5).shape
    (2, 3)
    >>> WindField.from_preset("gale").speed
    19.0
    >>> WindField(model="paper").turbulence  # λ of Eq. 17
    1.5
    """

    def __init__(
        self,
        direction=(1, 0, 0),
        speed: float = 5.0,
        grid: int = 32,
        beta_u: float | None = None,
        beta_vw: float | None = None,
        turbulence: float | None = None,
        c1: float | None = None,
        c2: float | None = None,
        c3: float = 0.5,
        c4: float = 1.0,
        c5: float = 4.0,
        c6: float = 0.5,
        seed: int = 0,
        bounds=None,
        *,
        model: str = "physical",
        length_scale: float | None = None,
        canopy_height: float | None = None,
        gust_strength: float = 0.3,
        gust_rate: float = 4.0,
    ):
        if model not in MODELS:
            raise ValueError(f"model must be one of {', '.join(map(repr, MODELS))}, got {model!r}")
        self._model = model
        paper = model == "paper"
        self._grid = _integer("grid", grid, 4, MAX_GRID)
        if beta_u is None:
            beta_u = 1.67 if paper else 5.0 / 3.0
        if beta_vw is None:
            beta_vw = 1.33 if paper else 5.0 / 3.0
        self._beta_u = _in_range("beta_u", beta_u, -MAX_BETA, MAX_BETA)
        self._beta_vw = _in_range("beta_vw", beta_vw, -MAX_BETA, MAX_BETA)
        self._seed = _integer("seed", seed, 0)
        self._c1 = None if c1 is None else _in_range("c1", c1, 0.0, MAX_COEFF)
        self._c2 = None if c2 is None else self._check_c2(c2)
        b = _bounds(DEFAULT_BOUNDS if bounds is None else bounds)
        _check_extent(b)
        if paper:
            self._constants(b, self._c1, self._c2)
        self._bounds = b
        self._length_scale = _optional_length("length_scale", length_scale)
        self._canopy_height = _optional_length("canopy_height", canopy_height)
        self._gust_strength = _in_range("gust_strength", gust_strength, 0.0, MAX_GUST_STRENGTH)
        self._gust_rate = _in_range("gust_rate", gust_rate, 0.0, MAX_GUST_RATE, " per minute")
        self.direction = direction
        self._speed = _in_range("speed", speed, 0.0, MAX_SPEED, " m/s")
        self.turbulence = (1.5 if paper else 0.3) if turbulence is None else turbulence
        self.c3 = c3
        self.c4 = c4
        self.c5 = c5
        self.c6 = c6
        self._tables = None  # padded, raveled float32 grids, built on first use
        self._local = threading.local()  # per-thread scratch buffers for sample()
        # Physical clocks: (t0, travel a0 in m, evolution s0 in cycles, gusts g0) at t0;
        # each advances linearly from t0 at its current rate (see _rebase).
        self._clock = (0.0, 0.0, 0.0, 0.0)
        self._t_last = 0.0

    @classmethod
    def from_preset(cls, name: str, **overrides) -> "WindField":
        """A physical field from a named wind (:data:`WIND_PRESETS`, by Beaufort number).

        Parameters
        ----------
        name : str
            One of ``calm``, ``breeze``, ``windy``, ``gale``, ``storm``.
        **overrides
            Any other constructor argument (``direction``, ``seed``, ...) or a preset value
            to replace.

        Returns
        -------
        WindField
        """
        return cls(**{**wind_preset(name), **overrides})

    def settings(self) -> dict:
        """The constructor arguments that rebuild this field for another tree.

        Explicit values only: ``bounds`` and an automatic ``canopy_height`` or
        ``length_scale`` are left out, so the next Simulation fits them to its tree.

        Returns
        -------
        dict
            Keyword arguments for :class:`WindField`.
        """
        kw = dict(direction=self.direction, speed=self._speed, grid=self._grid,
                  beta_u=self._beta_u, beta_vw=self._beta_vw, turbulence=self._turbulence,
                  c1=self._c1, c2=self._c2, c3=self._c3, c4=self._c4, c5=self._c5, c6=self._c6,
                  seed=self._seed, model=self._model, length_scale=self._length_scale,
                  canopy_height=self._canopy_height, gust_strength=self._gust_strength,
                  gust_rate=self._gust_rate)
        return kw

    @property
    def model(self) -> str:
        """``"physical"`` or ``"paper"`` (read-only)."""
        return self._model

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
        """Mean wind speed at the canopy top (paper: the tree top), m/s, in [0, 1000]."""
        return self._speed

    @speed.setter
    def speed(self, value) -> None:
        x = _in_range("speed", value, 0.0, MAX_SPEED, " m/s")
        self._rebase()
        self._speed = x

    @property
    def calm(self) -> bool:
        """True when the speed is 0 or the direction is a zero vector."""
        return self._speed == 0.0 or not self._frame.any()

    @property
    def turbulence(self) -> float:
        """Physical: turbulence intensity σ_u/U at the canopy top, in [0, 1].
        Paper: λ of Eq. 17, in [1, 2]."""
        return self._turbulence

    @turbulence.setter
    def turbulence(self, value) -> None:
        if self._model == "paper":
            self._turbulence = _in_range("turbulence", value, 1.0, 2.0)
        else:
            self._turbulence = _in_range("turbulence", value, 0.0, 1.0, " (intensity)")

    @property
    def length_scale(self) -> float:
        """Along-wind integral length scale L of the turbulence, m (physical).

        Set None for automatic: the canopy height, at least 1 m."""
        if self._length_scale is not None:
            return self._length_scale
        return max(self.canopy_height, MIN_AUTO_LENGTH)

    @length_scale.setter
    def length_scale(self, value) -> None:
        x = _optional_length("length_scale", value)
        self._rebase()
        self._length_scale = x

    @property
    def canopy_height(self) -> float:
        """Canopy height h, m (physical): the height of ``speed`` and of the profile's
        displacement (0.7 h) and roughness (0.1 h). Set None for the top of ``bounds``."""
        if self._canopy_height is not None:
            return self._canopy_height
        return min(max(float(self._bounds[1, 1]), _MIN_LENGTH), _MAX_LENGTH)

    @canopy_height.setter
    def canopy_height(self, value) -> None:
        x = _optional_length("canopy_height", value)
        self._rebase()
        self._canopy_height = x

    @property
    def gust_strength(self) -> float:
        """Mean peak gust above the mean speed, as a fraction of it, in [0, 2] (physical)."""
        return self._gust_strength

    @gust_strength.setter
    def gust_strength(self, value) -> None:
        self._gust_strength = _in_range("gust_strength", value, 0.0, MAX_GUST_STRENGTH)

    @property
    def gust_rate(self) -> float:
        """Gusts per minute passing a point, in [0, 30] (physical)."""
        return self._gust_rate

    @gust_rate.setter
    def gust_rate(self, value) -> None:
        x = _in_range("gust_rate", value, 0.0, MAX_GUST_RATE, " per minute")
        self._rebase()
        self._gust_rate = x

    @property
    def c1(self) -> float:
        """Effective c1 of Eq. 16 (set None for 1 / ln(c2·H))."""
        return self._profile_constants()[0]

    @c1.setter
    def c1(self, value) -> None:
        c1 = None if value is None else _in_range("c1", value, 0.0, MAX_COEFF)
        if self._model == "paper":
            self._constants(self._bounds, c1, self._c2)
        self._c1 = c1

    @property
    def c2(self) -> float:
        """Effective c2 of Eq. 16 in 1/m (set None for 50 / H)."""
        return self._profile_constants()[1]

    @c2.setter
    def c2(self, value) -> None:
        c2 = None if value is None else self._check_c2(value)
        if self._model == "paper":
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
        if self._model == "paper":
            self._constants(b, self._c1, self._c2)
        self._rebase()
        self._bounds = b

    def fit(self, bounds) -> None:
        """Fit the field to a tree's rest bounding box (what a Simulation calls).

        Paper: the box maps onto the noise grid. Physical: only the box top is used, as the
        canopy height (and so the default length scale) when ``canopy_height`` is None; the
        turbulence stays in metres, whatever the box. Like setting ``bounds``, except that an axis of (near) zero extent — a straight
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
        """Mean wind profile: the mean speed at height h over ``speed``.

        Physical: the canopy profile, ln((h − d)/z0) / ln((h_c − d)/z0) above the canopy
        height h_c (d = 0.7 h_c, z0 = 0.1 h_c) and exp(a(h/h_c − 1)) inside it, with
        a = 1/(0.3 ln 3) ≈ 3.03 so the two meet smoothly; 1 at h_c. Paper: W(h) = c1·ln(c2·h)
        of Eq. 16, 0 below h = 1/c2, 1 at the top of the bounds by default.

        Parameters
        ----------
        h : array_like
            Heights above the ground in metres (world y).

        Returns
        -------
        numpy.ndarray
            The profile, dimensionless, same shape as h.
        """
        h = np.asarray(h, dtype=np.float64)
        if not np.all(np.isfinite(h)):
            raise ValueError("h must be finite")
        if self._model != "paper":
            return _canopy_mean(h, self.canopy_height)
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

    # -- physical clocks ------------------------------------------------------------------------

    def _rates(self) -> tuple[float, float, float]:
        """(downwind travel m/s, evolution cycles/s, gusts/s) at the current settings."""
        u = self._speed
        return u, u / (EVOLUTION_LENGTH * self.length_scale), self._gust_rate / 60.0

    def _clocks(self, t: float) -> tuple[float, float, float]:
        """(travel a in m, evolution s in cycles, gust count g) at time t."""
        t0, a0, s0, g0 = self._clock
        dt = min(max(t - t0, -_TIME_CLIP), _TIME_CLIP)
        ra, rs, rg = self._rates()
        return a0 + ra * dt, s0 + rs * dt, g0 + rg * dt

    def _rebase(self) -> None:
        """Start the clocks afresh at the last sampled time, before a rate changes."""
        if getattr(self, "_model", "paper") == "paper" or not hasattr(self, "_clock"):
            return
        t = self._t_last
        self._clock = (t, *self._clocks(t))

    # -- sampling ------------------------------------------------------------------------------

    def sample(self, points, t: float) -> np.ndarray:
        """World wind velocity at ``points`` and time ``t``.

        Parameters
        ----------
        points : array_like, shape (K, 3) or (3,)
            World positions in metres (y up, ground at y = 0). Any finite values. Paper:
            outside the bounds the field repeats periodically. Physical: the turbulence
            repeats every 8 L along and across the wind and 4 L up, in space only (in time
            it never repeats); the mean profile keeps growing with height.
        t : float
            Time in seconds (moves the turbulence downwind).

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
        if self._model != "paper":
            self._t_last = t
        if self.calm or k == 0:
            return out
        if self._model != "paper":
            _sample_physical(self, p, t, out)
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
        if self._model != "paper":
            return (
                f"WindField(model='physical', direction=({d}), speed={self._speed:g}, "
                f"turbulence={self._turbulence:g}, length_scale={self.length_scale:g}, "
                f"canopy_height={self.canopy_height:g}, gust_strength={self._gust_strength:g}, "
                f"gust_rate={self._gust_rate:g}, beta_u={self._beta_u:g}, "
                f"beta_vw={self._beta_vw:g}, seed={self._seed})"
            )
        return (
            f"WindField(model='paper', direction=({d}), speed={self._speed:g}, grid={self._grid}, "
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


# ----------------------------------------------------------------------------- physical model

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
