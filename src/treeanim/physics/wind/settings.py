"""The wind's limits, defaults and named winds (Beaufort), and the checks of its box."""

from __future__ import annotations

import operator

import numpy as np

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
#: Points per vectorised pass of the paper's sample() (bounds the scratch memory; the
#: physical model is one compiled pass with no per-point scratch).
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


def named_wind(wind) -> str | None:
    """The named wind (:data:`WIND_PRESETS`) whose settings ``wind`` has now, or None: a
    physical wind whose speed, turbulence and gusts are one's, to within rounding."""
    if getattr(wind, "model", None) != "physical":
        return None
    for name, preset in WIND_PRESETS.items():
        if all(abs(float(getattr(wind, k)) - v) <= 1e-9 * max(1.0, abs(v)) for k, v in preset.items() if k != "beaufort"):
            return name
    return None


def wind_preset(name: str, model: str | None = None) -> dict:
    """WindField keyword arguments for a named wind (physical model).

    Parameters
    ----------
    name : str
        ``calm`` (Beaufort 1, light air, 1 m/s), ``breeze`` (3, gentle breeze, 4.5 m/s),
        ``windy`` (5, fresh breeze, 9.5 m/s), ``gale`` (8, 19 m/s) or ``storm`` (10,
        26.5 m/s).
    model : str or None
        The wind model it is for, if one is chosen: the named winds are the physical model's
        (any other is refused).

    Returns
    -------
    dict
        ``speed``, ``turbulence``, ``gust_strength``, ``gust_rate`` and ``model``.

    Raises
    ------
    ValueError
        If the name is not one of :data:`WIND_PRESETS`, or ``model`` is another model.
    """
    if name not in WIND_PRESETS:
        raise ValueError(f"wind preset must be one of {', '.join(WIND_PRESETS)}, got {name!r}")
    if model not in (None, "physical"):
        raise ValueError(f"the named winds are for the physical wind model, not the {model} one")
    kw = {k: v for k, v in WIND_PRESETS[name].items() if k != "beaufort"}
    return dict(kw, model="physical")


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
