"""``WindField``: the wind over trees, its settings and its sampling (physical or the paper's)."""

from __future__ import annotations

import math
import threading

import numpy as np

from ...validate import finite_float, finite_vector3, float_within
from .paper import _cached_grid, _sample_paper, _Workspace, check_c2, lookup_tables, profile_constants
from .physical import _canopy_mean, _sample_physical
from .settings import (
    _MAX_LENGTH,
    _MIN_LENGTH,
    _TIME_CLIP,
    _VERTICAL_TOL,
    DEFAULT_BOUNDS,
    EVOLUTION_LENGTH,
    MAX_BETA,
    MAX_COEFF,
    MAX_GRID,
    MAX_GUST_RATE,
    MAX_GUST_STRENGTH,
    MAX_SPEED,
    MIN_AUTO_LENGTH,
    MODELS,
    Setting,
    _bounds,
    _check_extent,
    _integer,
    _optional_length,
    wind_preset,
)


def _within(lo: float, hi: float, unit: str = ""):
    """A :class:`Setting` check: a finite number in [lo, hi]."""
    return lambda name, value: float_within(name, value, lo, hi, unit)


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

    # Checked settings (the others are properties below).
    speed = Setting("Mean wind speed at the canopy top (paper: the tree top), m/s, in [0, 1000].",
                    _within(0.0, MAX_SPEED, " m/s"), rebase=True)
    gust_strength = Setting("Mean peak gust above the mean speed, as a fraction of it, in [0, 2] (physical).",
                            _within(0.0, MAX_GUST_STRENGTH))
    gust_rate = Setting("Gusts per minute passing a point, in [0, 30] (physical).",
                        _within(0.0, MAX_GUST_RATE, " per minute"), rebase=True)
    c3 = Setting("Vertical turbulence scale of Eq. 17.", _within(0.0, MAX_COEFF))
    c4 = Setting("Lateral turbulence scale of Eq. 17.", _within(0.0, MAX_COEFF))
    c5 = Setting("Downwind speed of the frozen turbulence, grid cells per second.", finite_float)
    c6 = Setting("Lateral drift of the frozen turbulence, grid cells per second.", finite_float)
    grid = Setting("Grid edge N (rebuilds the grids when changed).", lambda n, v: _integer(n, v, 4, MAX_GRID),
                   regrid=True)
    beta_u = Setting("Spectral exponent of the along-wind noise (rebuilds the grids when changed).",
                     _within(-MAX_BETA, MAX_BETA), regrid=True)
    beta_vw = Setting("Spectral exponent of the vertical and lateral noise (rebuilds the grids).",
                      _within(-MAX_BETA, MAX_BETA), regrid=True)
    seed = Setting("Noise seed (rebuilds the grids when changed).", lambda n, v: _integer(n, v, 0), regrid=True)

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
        self.grid = grid
        if beta_u is None:
            beta_u = 1.67 if paper else 5.0 / 3.0
        if beta_vw is None:
            beta_vw = 1.33 if paper else 5.0 / 3.0
        self.beta_u = beta_u
        self.beta_vw = beta_vw
        self.seed = seed
        self._c1 = None if c1 is None else float_within("c1", c1, 0.0, MAX_COEFF)
        self._c2 = None if c2 is None else check_c2(c2)
        b = _bounds(DEFAULT_BOUNDS if bounds is None else bounds)
        _check_extent(b)
        if paper:
            profile_constants(b, self._c1, self._c2)
        self._bounds = b
        self._length_scale = _optional_length("length_scale", length_scale)
        self._canopy_height = _optional_length("canopy_height", canopy_height)
        self.gust_strength = gust_strength
        self.gust_rate = gust_rate
        self.direction = direction
        self.speed = speed
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
            self._turbulence = float_within("turbulence", value, 1.0, 2.0)
        else:
            self._turbulence = float_within("turbulence", value, 0.0, 1.0, " (intensity)")

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
    def c1(self) -> float:
        """Effective c1 of Eq. 16 (set None for 1 / ln(c2·H))."""
        return self._profile_constants()[0]

    @c1.setter
    def c1(self, value) -> None:
        c1 = None if value is None else float_within("c1", value, 0.0, MAX_COEFF)
        if self._model == "paper":
            profile_constants(self._bounds, c1, self._c2)
        self._c1 = c1

    @property
    def c2(self) -> float:
        """Effective c2 of Eq. 16 in 1/m (set None for 50 / H)."""
        return self._profile_constants()[1]

    @c2.setter
    def c2(self, value) -> None:
        c2 = None if value is None else check_c2(value)
        if self._model == "paper":
            profile_constants(self._bounds, self._c1, c2)
        self._c2 = c2

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
            profile_constants(b, self._c1, self._c2)
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

    def _profile_constants(self) -> tuple[float, float]:
        return profile_constants(self._bounds, self._c1, self._c2)

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
            self._tables = lookup_tables(self.grids)
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
            repeats every 8 L along the wind, 6 L across and 3 L up, in space only (in time
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

        _sample_paper(self, p, t, out)
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
