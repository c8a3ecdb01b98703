"""``WindField``: the base of every wind model, the registry of models and the façade that
builds one by name (docs/design.md, "Adding a wind model").

A wind model is a subclass of :class:`WindField` registered under a name
(:func:`register_wind_model`, :data:`WIND_MODELS`) whose ``Params`` declares its own settings
(a :class:`WindParams` subclass, declared as the physics settings are: ``model/declare.py``)
and whose ``_sample`` fills the wind at some points. The base holds what every model has: the
direction (and its frame), the speed, the box it is fitted to (``bounds``, ``fit``), the checks
of ``sample``'s input, the settings' properties, ``settings()`` and ``repr``.
``WindField(model=NAME, ...)`` builds the model registered as NAME (default ``"physical"``).
"""

from __future__ import annotations

import dataclasses
import math
from abc import ABC, abstractmethod
from typing import Annotated, ClassVar

import numpy as np

from ...model.declare import Param, default_of, params_of, settings
from ...validate import finite_float, finite_vector3
from .settings import _VERTICAL_TOL, DEFAULT_BOUNDS, MAX_SPEED, _bounds, _check_extent, wind_preset

__all__ = ["WindField", "WindParams", "WIND_MODELS", "DEFAULT_MODEL", "register_wind_model", "wind_model"]

#: The wind models by name, in the order they were registered (:func:`register_wind_model`).
WIND_MODELS: dict[str, type[WindField]] = {}
#: The model ``WindField(...)`` builds when none is named.
DEFAULT_MODEL = "physical"
_UNSET = object()


@settings("")
class WindParams:
    """The settings every wind model has. A model's own ``Params`` subclasses this, decorated
    with ``@settings("")`` (:func:`treeanim.model.declare.settings`), one annotated field a
    setting."""

    speed: Annotated[float, Param(0.0, MAX_SPEED, unit="m/s", fmt="%.1f",
                                  help="Mean wind speed at the model's reference height (the canopy top "
                                  "or the tree top); 0 is calm.")] = 5.0


def register_wind_model(name: str):
    """Class decorator: register a :class:`WindField` subclass as the wind model ``name``.

    ``WindField(model=name, ...)``, ``--wind-model name`` and :data:`WIND_MODELS` then know it.

    Parameters
    ----------
    name : str
        The model's name (its ``model`` attribute).

    Raises
    ------
    TypeError
        If the class is not a WindField, or its ``Params`` is not a ``@settings`` class
        subclassing :class:`WindParams`.
    ValueError
        If another class is registered under ``name``.
    """

    def wrap(cls):
        if not (isinstance(cls, type) and issubclass(cls, WindField)):
            raise TypeError(f"a wind model must subclass WindField, got {cls!r}")
        _check_params(cls)
        if WIND_MODELS.get(name, cls) is not cls:
            raise ValueError(f"wind model {name!r} is already registered ({WIND_MODELS[name].__name__})")
        cls.model = name
        WIND_MODELS[name] = cls
        return cls

    return wrap


def wind_model(name) -> type[WindField]:
    """The class registered as wind model ``name``, or a one-line ValueError."""
    try:
        return WIND_MODELS[name]
    except (KeyError, TypeError):
        raise ValueError(f"model must be one of {', '.join(map(repr, WIND_MODELS))}, got {name!r}") from None


def _check_params(cls) -> None:
    params = cls.Params
    if not (isinstance(params, type) and issubclass(params, WindParams)):
        raise TypeError(f"{cls.__name__}.Params must subclass WindParams, got {params!r}")
    if params is not WindParams and "__pydantic_fields__" not in vars(params):
        raise TypeError(f"{cls.__name__}.Params must be decorated with @settings('') (treeanim.model.declare)")
    taken = [name for name in params_of(params) if name in vars(WindField)]
    if taken:
        raise TypeError(f"{cls.__name__}.Params: {', '.join(taken)} would hide WindField's own")


def _refusal(cls, name: str) -> str:
    """One line: ``name`` is not a setting of the wind model ``cls`` (and whose it is)."""
    own = ", ".join(["direction", "bounds", *cls.parameters()])
    mine = cls.model or cls.__name__
    owners = [m for m, c in WIND_MODELS.items() if name in c.parameters()]
    if owners:
        whose = " and ".join(owners) + " wind model" + ("s" if len(owners) > 1 else "")
        return f"{name}: a setting of the {whose}, not of the {mine} one (its settings: {own})"
    return f"{name}: not a setting of the {mine} wind model (its settings: {own})"


def _setting(name: str, param: Param) -> property:
    """The property of setting ``name``: reads it, and sets it through ``_set`` (checked)."""

    def get(self):
        return getattr(self._params, name)

    def put(self, value):
        self._set(**{name: value})

    unit = f", {param.unit}" if param.unit else ""
    return property(get, put, doc=f"{param.help} In {param.interval}{unit}.")


class WindField(ABC):
    """Wind over trees, sampled at any points and time; the base of every wind model.

    ``WindField(model=NAME, ...)`` builds the wind model registered as NAME
    (:data:`WIND_MODELS`): ``"physical"`` (the default, :class:`~.physical.PhysicalWind`,
    docs/design.md §12) or ``"paper"`` (:class:`~.paper.PaperWind`, Hu, Chiba & He 2012 Eqs.
    13–18). Each takes only its own settings (``WindField.parameters()`` of its class); another
    model's setting is refused in one line.

    Parameters
    ----------
    direction : array_like of 3 floats, default (1, 0, 0)
        Wind direction in world coordinates (y up); only its direction is used. It must have
        a horizontal part; a zero vector means calm (``sample`` returns zeros).
    speed : float, default 5.0
        Mean wind speed in m/s at the model's reference height, in [0, 1000]. 0 means calm.
    model : str, default "physical"
        The registered model to build (keyword only).
    bounds : ((x0, y0, z0), (x1, y1, z1)) or None
        The box in metres the field is fitted to; None means ((−5, 0, −5), (5, 10, 5)) until
        a Simulation calls ``fit`` with its tree's rest bounding box. Every extent must be
        positive (at least 1e-9 m) and the box within ±1e9 m. Keyword only.
    **settings
        The model's own settings (keyword only); None gives a setting's default.

    Notes
    -----
    Every setting is a property whose setter checks the value (its declaration, then the
    model's own checks) and raises a one-line ``ValueError`` naming it; the old value is kept.
    ``sample`` is thread-safe.

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

    #: The registered name (set by :func:`register_wind_model`).
    model: ClassVar[str] = ""
    #: The model's settings: a ``@settings("")`` subclass of :class:`WindParams`.
    Params: ClassVar[type] = WindParams

    def __new__(cls, *args, model=_UNSET, **kwargs):
        if cls is WindField:
            cls = wind_model(DEFAULT_MODEL if model is _UNSET else model)
        return super().__new__(cls)

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        _check_params(cls)
        for name, param in cls.parameters().items():
            if not hasattr(cls, name):  # a model may define a setting's property itself
                setattr(cls, name, _setting(name, param))

    def __init__(self, direction=(1.0, 0.0, 0.0), speed: float | None = None, *, model=_UNSET, bounds=None,
                 **settings):
        if model is not _UNSET and model != self.model:
            wind_model(model)  # an unknown name is refused as such
            raise ValueError(f"model: {type(self).__name__} is the {self.model!r} wind model, got {model!r}")
        if speed is not None:
            settings["speed"] = speed
        for name in settings:
            if name not in self.parameters():
                raise ValueError(_refusal(type(self), name))
        settings = {k: v for k, v in settings.items() if v is not None or default_of(self.Params, k) is None}
        params = self.Params(**settings)
        b = _bounds(DEFAULT_BOUNDS if bounds is None else bounds)
        _check_extent(b)
        self._check(params, b)
        self._params, self._bounds = params, b
        self.direction = direction

    @classmethod
    def from_preset(cls, name: str, **overrides) -> WindField:
        """A physical field from a named wind (:data:`~.settings.WIND_PRESETS`, by Beaufort number).

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

    @classmethod
    def parameters(cls) -> dict[str, Param]:
        """The model's own settings (its ``Params``' declarations), by name, in order.

        Returns
        -------
        dict of str to :class:`~treeanim.model.declare.Param`
        """
        return params_of(cls.Params)

    def settings(self) -> dict:
        """The constructor arguments that rebuild this field for another tree.

        Explicit values only: ``bounds`` and any automatic setting (None) are left to the
        next Simulation to fit.

        Returns
        -------
        dict
            Keyword arguments for :class:`WindField`: ``model``, ``direction`` and the
            model's settings.
        """
        return dict(model=self.model, direction=self.direction, **dataclasses.asdict(self._params))

    def _set(self, **changes) -> None:
        """Change settings: checked by their declarations and :meth:`_check`, then
        :meth:`_changing` sees them before they replace the current ones."""
        for name in changes:
            if name not in self.parameters():
                raise ValueError(_refusal(type(self), name))
        params = dataclasses.replace(self._params, **changes)
        self._check(params, self._bounds)
        self._changing(params, self._bounds)
        self._params = params

    def __setattr__(self, name: str, value) -> None:
        if not name.startswith("_") and not isinstance(getattr(type(self), name, None), property):
            if hasattr(type(self), name):
                raise AttributeError(f"{name} is read-only")
            raise ValueError(_refusal(type(self), name))
        object.__setattr__(self, name, value)

    # -- what a model may add ------------------------------------------------------------------

    def _check(self, params, bounds: np.ndarray) -> None:
        """Refuse (ValueError) settings ``params`` that cannot go with the box ``bounds``
        (each already within its declared range). Nothing by default."""

    def _changing(self, params, bounds: np.ndarray) -> None:
        """Called with the new settings and box, checked, just before they replace the current
        ones (``self._params``, ``self._bounds``): for caches and clocks. Nothing by default."""

    def _profile(self, h: np.ndarray) -> np.ndarray:
        """The mean profile at the finite heights ``h`` (see :meth:`profile`)."""
        raise NotImplementedError(f"the {self.model} wind model has no mean profile")

    @abstractmethod
    def _sample(self, p: np.ndarray, t: float, out: np.ndarray) -> None:
        """Write the wind (m/s, world) at the points ``p`` (K, 3), K ≥ 1, finite, at the finite
        time ``t`` (s) into ``out`` (K, 3, zeros); never called when calm."""

    # -- direction and speed ----------------------------------------------------------------------

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
        return self._params.speed == 0.0 or not self._frame.any()

    # -- the box -------------------------------------------------------------------------------------

    @property
    def bounds(self) -> np.ndarray:
        """(2, 3) box ((x0, y0, z0), (x1, y1, z1)) in metres the field is fitted to; its top
        y1 is the tree's height where a model needs one."""
        return self._bounds.copy()

    @bounds.setter
    def bounds(self, value) -> None:
        b = _bounds(value)
        _check_extent(b)
        self._check(self._params, b)
        self._changing(self._params, b)
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
            If the box is not finite, is inverted on some axis, is a single point, or the
            model refuses it (the paper's default profile: a top not above the ground).
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

    # -- sampling ------------------------------------------------------------------------------------

    def profile(self, h) -> np.ndarray:
        """The mean wind profile: the mean speed at height ``h`` over ``speed`` (the model's
        own law, 1 at its reference height).

        Parameters
        ----------
        h : array_like
            Heights above the ground in metres (world y), finite.

        Returns
        -------
        numpy.ndarray
            The profile, dimensionless, same shape as h.
        """
        h = np.asarray(h, dtype=np.float64)
        if not np.all(np.isfinite(h)):
            raise ValueError("h must be finite")
        return self._profile(h)

    def sample(self, points, t: float) -> np.ndarray:
        """World wind velocity at ``points`` and time ``t``.

        Parameters
        ----------
        points : array_like, shape (K, 3) or (3,)
            World positions in metres (y up, ground at y = 0). Any finite values.
        t : float
            Time in seconds.

        Returns
        -------
        numpy.ndarray
            (K, 3) float64 wind velocities in m/s ((1, 3) for a single point); zeros when calm.

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
        out = np.zeros((p.shape[0], 3))
        if not self.calm and p.shape[0]:
            self._sample(p, t, out)
        return out

    def __repr__(self) -> str:
        d = ", ".join(f"{x:g}" for x in self._direction)
        values = ", ".join(f"{k}={getattr(self, k)!r}" for k in self.parameters())
        return f"WindField(model={self.model!r}, direction=({d}), {values}, bounds={self._bounds.tolist()})"
