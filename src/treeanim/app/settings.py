"""The panel's settings in one table: :data:`SETTINGS` (name → :class:`Setting`: its widget's
label and range, how to read it from the viewer and how to apply it), which drives both the
panel's drawing (:meth:`Panel.widget <treeanim.app.panel.Panel.widget>`) and
:meth:`Panel.apply <treeanim.app.panel.Panel.apply>`. A new setting is one entry here.

Every setter goes through a checked property (``sim.season``, ``sim.physics =
dataclasses.replace(...)``, the wind's setters ...) and raises ValueError on a refusal, which
the panel shows in its status line. Settings of the paper's model alone (its integrator,
coupling and modal ranges) are shown only while it runs, and refused (ValueError) on the tree
model.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any, Callable

from ..model.params import MODE_PARAMS, PARAMS, ModeRange
from ..model.tree import KINDS
from ..physics.oscillator import INTEGRATORS
from ..render.scene import sun_angles, sun_direction
from .winddir import wind_angle

__all__ = ["Setting", "SETTINGS", "EI_SPAN"]

#: The EI_max slider spans the preset's value divided or multiplied by this.
EI_SPAN = 30.0


@dataclass(frozen=True)
class Setting:
    """One setting of the panel.

    Attributes
    ----------
    label : str
        The widget's label.
    get : callable
        ``get(viewer)``: the current value.
    set : callable
        ``set(viewer, value)``: apply a value (ValueError: refused).
    kind : {'slider', 'check', 'choice', 'custom'}
        The widget: a float slider, a checkbox, a combo of :attr:`choices`, or drawn by the
        panel's own code (a preset list, a range pair).
    lo, hi : float
        A slider's range (a value beyond it is clamped where :attr:`clamp`).
    fmt : str
        A slider's display format.
    log : bool
        A logarithmic slider.
    deferred : bool
        Applied when the slider is let go (rebuilding noise grids on every drag step would
        stall the frame).
    clamp : bool
        Clamp the value to [lo, hi] before applying it.
    shown : callable or None
        ``shown(viewer)``: whether the widget is drawn (None: always).
    choices : tuple of str
        A combo's items.
    """

    label: str
    get: Callable[[Any], Any]
    set: Callable[[Any, Any], None]
    kind: str = "slider"
    lo: float = 0.0
    hi: float = 1.0
    fmt: str = "%.2f"
    log: bool = False
    deferred: bool = False
    clamp: bool = False
    shown: Callable[[Any], bool] | None = None
    choices: tuple[str, ...] = ()

    def apply(self, viewer, value) -> None:
        """Apply ``value`` (clamped to the range where :attr:`clamp`)."""
        if self.clamp:
            value = min(max(float(value), self.lo), self.hi)
        self.set(viewer, value)


def _physical(v) -> bool:
    return v.sim.wind.model == "physical"


def _paper(v) -> bool:
    return v.sim.wind.model == "paper"


def _paper_model(v) -> bool:
    return v.sim.model == "paper"


def _paper_only(setting: Setting) -> Setting:
    """``setting``, shown with the paper's model only and refused (ValueError, the façade's
    reason) on the tree model, where its attribute does not exist."""

    def put(v, x):
        try:
            setting.set(v, x)
        except AttributeError as e:
            raise ValueError(f"{setting.label}: {e}") from None

    return dataclasses.replace(setting, set=put, shown=_paper_model)


def _wind(name: str, label: str, lo: float, hi: float, fmt: str = "%.2f", **kw) -> Setting:
    """A wind field setting, through the WindField's checked setter of ``name``; shown (by
    default) for the wind models that have it."""
    kw.setdefault("shown", lambda v: name in v.sim.wind.parameters())
    return Setting(label, lambda v: getattr(v.sim.wind, name), lambda v, x: v.set_wind(**{name: float(x)}),
                   lo=lo, hi=hi, fmt=fmt, **kw)


def _flag(owner: Callable[[Any], Any], name: str, label: str) -> Setting:
    """A checkbox for boolean attribute ``name`` of ``owner(viewer)``."""
    return Setting(label, lambda v: getattr(owner(v), name), lambda v, x: setattr(owner(v), name, bool(x)),
                   kind="check")


def _set_modal(v, physical) -> None:
    v.sim.modal = v.tree.modes = "physical" if physical else "paper"


def _load_preset(v, name) -> None:
    from ..model.presets import load_preset

    v.load_tree(load_preset(name))
    v.say(f"loaded preset {name}")


def _wind_preset(v, name) -> None:
    v.set_wind(preset=str(name))
    v.say(f"wind: {name}")


def _physics(name: str) -> Setting:
    """A slider of the physics setting ``name``: label, unit, format and scale from its
    declaration (:data:`~treeanim.model.params.PARAMS`), set through ``dataclasses.replace``
    (which checks it)."""
    p = PARAMS[name]
    return Setting(p.label or name, lambda v: getattr(v.sim.physics, name),
                   lambda v, x: setattr(v.sim, "physics", dataclasses.replace(v.sim.physics, **{name: float(x)})),
                   lo=p.lo, hi=p.hi, fmt=p.widget_format, log=p.log)


def _set_sun(v, azimuth=None, elevation=None) -> None:
    az, el = sun_angles(v.scene.sun_direction)
    az = az if azimuth is None else float(azimuth)
    el = el if elevation is None else float(elevation)
    lo, hi = SETTINGS["sun_elevation"].lo, SETTINGS["sun_elevation"].hi
    v.scene.sun_direction = sun_direction(az % 360.0, min(max(el, lo), hi))


def _modes(what: str, kind: str) -> Setting:
    """The (min, max) f or ζ range of ``kind`` in the season table the panel edits."""

    def table(v):
        return getattr(v.sim.physics, v.panel.edit_season)

    def get(v):
        r = table(v).of(kind) or v.sim.physics.modes(kind, v.sim.season)
        return None if r is None else getattr(r, what)

    def put(v, value):
        p = v.sim.physics
        cur = table(v).of(kind) or p.modes(kind, v.sim.season)
        lo, hi = sorted(float(x) for x in value)
        new = ModeRange((lo, hi), cur.zeta) if what == "f" else ModeRange(cur.f, (lo, hi))
        v.sim.physics = dataclasses.replace(p, **{v.panel.edit_season: dataclasses.replace(table(v), **{kind: new})})

    # the ranges are the preset's (saved with it) on either model; only the paper's uses them
    p = MODE_PARAMS[what]
    return Setting(f"{p.label} {kind}" + (f" ({p.unit})" if p.unit else ""), get, put, kind="custom",
                   lo=p.lo, hi=p.hi, fmt=p.fmt, shown=_paper_model)


#: Every setting the panel shows or :meth:`Panel.apply` takes, by name.
SETTINGS: dict[str, Setting] = {
    "preset": Setting("preset", lambda v: v.sim.tree.name, _load_preset, kind="custom"),
    "season": Setting("season", lambda v: v.sim.season, lambda v, x: setattr(v.sim, "season", float(x))),
    # wind
    "wind_preset": Setting("named wind", lambda v: None, _wind_preset, kind="custom", shown=_physical),
    "wind_speed": _wind("speed", "speed", 0.0, 30.0, "%.1f m/s"),
    "wind_angle": Setting("direction", lambda v: wind_angle(v.sim.wind.direction),
                          lambda v, x: v.set_wind(angle=float(x)), lo=0.0, hi=360.0, fmt="%.0f°"),
    "turbulence": _wind("turbulence", "turbulence", 0.0, 1.0, shown=_physical),  # intensity at the canopy top
    "turbulence_paper": _wind("turbulence", "turbulence λ", 1.0, 2.0, shown=_paper),  # λ of Eq. 17
    "gust_strength": _wind("gust_strength", "gust strength", 0.0, 2.0),
    "gust_rate": _wind("gust_rate", "gust rate", 0.0, 30.0, "%.1f /min"),
    "length_scale": _wind("length_scale", "length scale", 0.5, 100.0, "%.1f m", log=True),
    "beta_u": _wind("beta_u", "β_u", 0.5, 3.0, deferred=True),
    "beta_vw": _wind("beta_vw", "β_vw", 0.5, 3.0, deferred=True),
    "c3": _wind("c3", "c3 (vertical)", 0.0, 2.0),
    "c4": _wind("c4", "c4 (lateral)", 0.0, 2.0),
    # physics: the range is the preset's value ÷ or × EI_SPAN (Panel.tree_changed)
    "ei_max": _physics("ei_max"),
    **{f"{what}:{kind}": _modes(what, kind) for kind in KINDS for what in ("f", "zeta")},
    # simulation
    "time_scale": Setting("time scale", lambda v: v.time_scale, lambda v, x: setattr(v, "time_scale", float(x)),
                          lo=0.05, hi=2.0, fmt="%.2f×", log=True, clamp=True),
    # the model: the whole tree as one structure (default), or the paper's independent objects
    "paper_model": Setting("paper's model (Hu et al. 2012)", _paper_model,
                           lambda v, x: v.set_model("paper" if x else "tree"), kind="check"),
    "integrator": _paper_only(Setting("integrator", lambda v: v.sim.integrator,
                                      lambda v, x: setattr(v.sim, "integrator", x), kind="choice",
                                      choices=tuple(INTEGRATORS))),
    "coupling": _paper_only(_flag(lambda v: v.sim, "coupling", "coupling")),
    # the paper's branch modes: beam theory, or the preset's ranges (Eqs. 20–22)
    "physical_modes": _paper_only(Setting("physical modes (beam theory)", lambda v: v.sim.modal == "physical",
                                          _set_modal, kind="check")),
    "paused": _flag(lambda v: v, "paused", "paused"),
    # overlays
    "show_trace": _flag(lambda v: v, "show_trace", "grab trace"),
    "show_frames": _flag(lambda v: v, "show_frames", "local frames"),
    "show_wind": _flag(lambda v: v, "show_wind", "wind slices + arrow"),
    # light
    "sun_azimuth": Setting("sun azimuth", lambda v: sun_angles(v.scene.sun_direction)[0],
                           lambda v, x: _set_sun(v, azimuth=x), lo=0.0, hi=360.0, fmt="%.0f°"),
    "sun_elevation": Setting("sun elevation", lambda v: sun_angles(v.scene.sun_direction)[1],
                             lambda v, x: _set_sun(v, elevation=x), lo=5.0, hi=90.0, fmt="%.0f°"),
    "translucency": Setting("translucency", lambda v: v.scene.translucency,
                            lambda v, x: setattr(v.scene, "translucency", float(x)), clamp=True),
    "shadows": _flag(lambda v: v.scene, "shadow", "shadows"),
}
