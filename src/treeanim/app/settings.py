"""The panel's settings in one table: :data:`SETTINGS` (name → :class:`Setting`: its widget's
label and range, where the viewer keeps its value and which viewer method applies it), which
drives both the panel's drawing (:meth:`Panel.widget <treeanim.app.panel.Panel.widget>`) and
:meth:`Panel.apply <treeanim.app.panel.Panel.apply>`. A new setting is one entry here (and, for
something new to set, one method of :class:`~treeanim.app.actions.ViewerActions`).

Every action goes through a checked property (``sim.season``, ``sim.physics =
dataclasses.replace(...)``, the wind's setters ...) and raises ValueError on a refusal, which
the panel shows in its status line. Settings of the paper's model alone (its integrator,
coupling and modal ranges) are shown only while it runs, and refused (ValueError) on the tree
model.
"""

from __future__ import annotations

import operator
from dataclasses import dataclass
from typing import Any, Callable

from ..model.params import MODE_PARAMS, PARAMS
from ..model.tree import KINDS
from ..physics.oscillator import INTEGRATORS
from .actions import SUN_ELEVATIONS, TIME_SCALES
from .hold import GRAB_STRENGTHS

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
    get : str or callable or None
        Where the value is: a path of attributes from the viewer (``'sim.wind.speed'``), or
        ``get(viewer)``; None: no value to show (a list of named winds).
    action : str
        The :class:`~treeanim.app.viewer.Viewer` method that applies a value
        (:class:`~treeanim.app.actions.ViewerActions`; ValueError: refused).
    keyword : str or None
        The action takes the value as this keyword (``set_wind(speed=value)``); None: as its
        last positional argument.
    args : tuple
        Arguments the action takes before the value (``set_overlay('trace', value)``).
    kind : {'slider', 'check', 'choice', 'custom'}
        The widget: a float slider, a checkbox, a combo of :attr:`choices`, or drawn by the
        panel's own code (a preset list, a range pair). A slider's value is applied as a float,
        a checkbox's as a bool.
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
    seasonal : bool
        The action also takes ``season=``: the season table the panel edits.
    paper_only : bool
        Shown with the paper's model only; on the tree model, where the simulation has no such
        attribute, refused with a ValueError naming the setting.
    """

    label: str
    get: str | Callable[[Any], Any] | None
    action: str
    keyword: str | None = None
    args: tuple = ()
    kind: str = "slider"
    lo: float = 0.0
    hi: float = 1.0
    fmt: str = "%.2f"
    log: bool = False
    deferred: bool = False
    clamp: bool = False
    shown: Callable[[Any], bool] | None = None
    choices: tuple[str, ...] = ()
    seasonal: bool = False
    paper_only: bool = False

    def value(self, viewer):
        """The current value (None where :attr:`get` is None)."""
        if self.get is None:
            return None
        if isinstance(self.get, str):
            return operator.attrgetter(self.get)(viewer)
        return self.get(viewer)

    def apply(self, viewer, value, **extra) -> None:
        """Apply ``value`` through the viewer's :attr:`action` (a slider's as a float clamped to
        the range where :attr:`clamp`, a checkbox's as a bool); ``extra``: more keywords for the
        action (``season=`` of a :attr:`seasonal` one)."""
        if self.kind == "slider":
            value = float(value)
            if self.clamp:
                value = min(max(value, self.lo), self.hi)
        elif self.kind == "check":
            value = bool(value)
        act = getattr(viewer, self.action)
        try:
            if self.keyword is None:
                act(*self.args, value, **extra)
            else:
                act(*self.args, **{self.keyword: value}, **extra)
        except AttributeError as e:
            if not self.paper_only:
                raise
            raise ValueError(f"{self.label}: {e}") from None


def _physical(v) -> bool:
    return v.sim.wind.model == "physical"


def _paper(v) -> bool:
    return v.sim.wind.model == "paper"


def _paper_model(v) -> bool:
    return v.sim.model == "paper"


def _physical_modes(v) -> bool:
    return v.sim.modal == "physical"


def _sun_azimuth(v) -> float:
    return v.sun_angles[0]


def _sun_elevation(v) -> float:
    return v.sun_angles[1]


def _wind(name: str, label: str, lo: float, hi: float, fmt: str = "%.2f", **kw) -> Setting:
    """A wind field setting: ``set_wind(name=value)``, through the wind model's checked
    setter; shown (by default) for the wind models that have it."""
    kw.setdefault("shown", lambda v: name in v.sim.wind.parameters())
    return Setting(label, f"sim.wind.{name}", "set_wind", keyword=name, lo=lo, hi=hi, fmt=fmt, **kw)


def _check(label: str, get, action: str, **kw) -> Setting:
    """A checkbox."""
    return Setting(label, get, action, kind="check", **kw)


def _physics(name: str) -> Setting:
    """A slider of the physics setting ``name``: label, unit, format and scale from its
    declaration (:data:`~treeanim.model.params.PARAMS`), set through ``set_physics`` (which
    checks it)."""
    p = PARAMS[name]
    return Setting(p.label or name, f"sim.physics.{name}", "set_physics", keyword=name,
                   lo=p.lo, hi=p.hi, fmt=p.widget_format, log=p.log)


def _modes(what: str, kind: str) -> Setting:
    """The (min, max) f or ζ range of ``kind`` in the season table the panel edits
    (``Viewer.mode_range``, ``Viewer.set_mode_range``; drawn by the panel's own code)."""
    p = MODE_PARAMS[what]
    return Setting(f"{p.label} {kind}" + (f" ({p.unit})" if p.unit else ""), None, "set_mode_range",
                   args=(kind, what), kind="custom", lo=p.lo, hi=p.hi, fmt=p.fmt, shown=_paper_model, seasonal=True)


#: Every setting the panel shows or :meth:`Panel.apply` takes, by name.
SETTINGS: dict[str, Setting] = {
    "preset": Setting("preset", "sim.tree.name", "open_preset", kind="custom"),
    "season": Setting("season", "sim.season", "set_season"),
    # wind
    "wind_preset": Setting("named wind", None, "set_wind_preset", kind="custom", shown=_physical),
    "wind_speed": _wind("speed", "speed", 0.0, 30.0, "%.1f m/s"),
    "wind_angle": Setting("direction", "wind_angle", "set_wind", keyword="angle", lo=0.0, hi=360.0, fmt="%.0f°"),
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
    "time_scale": Setting("time scale", "time_scale", "set_time_scale", lo=TIME_SCALES[0], hi=TIME_SCALES[1],
                          fmt="%.2f×", log=True, clamp=True),
    # the model: the whole tree as one structure (default), or the paper's independent objects
    "paper_model": _check("paper's model (Hu et al. 2012)", _paper_model, "set_paper_model"),
    "integrator": Setting("integrator", "sim.integrator", "set_integrator", kind="choice",
                          choices=tuple(INTEGRATORS), shown=_paper_model, paper_only=True),
    "coupling": _check("coupling", "sim.coupling", "set_coupling", shown=_paper_model, paper_only=True),
    # the paper's branch modes: beam theory, or the preset's ranges (Eqs. 20–22)
    "physical_modes": _check("physical modes (beam theory)", _physical_modes, "set_physical_modes",
                             shown=_paper_model, paper_only=True),
    "paused": _check("paused", "paused", "set_paused"),
    # the mouse's spring × its default (hold.py)
    "grab_strength": Setting("grab strength", "grab_strength", "set_grab_strength", lo=GRAB_STRENGTHS[0],
                             hi=GRAB_STRENGTHS[1], fmt="%.3g×", log=True, clamp=True),
    # draft mode for slow renderers: half resolution, no MSAA, no shadows (not undone or reset)
    "draft": _check("draft", "draft", "set_draft"),
    # overlays
    "show_trace": _check("grab trace", "show_trace", "set_overlay", args=("trace",)),
    "show_frames": _check("local frames", "show_frames", "set_overlay", args=("frames",)),
    "show_wind": _check("wind slices + arrow", "show_wind", "set_overlay", args=("wind",)),
    # light
    "sun_azimuth": Setting("sun azimuth", _sun_azimuth, "set_sun", keyword="azimuth", lo=0.0, hi=360.0, fmt="%.0f°"),
    "sun_elevation": Setting("sun elevation", _sun_elevation, "set_sun", keyword="elevation",
                             lo=SUN_ELEVATIONS[0], hi=SUN_ELEVATIONS[1], fmt="%.0f°"),
    "translucency": Setting("translucency", "scene.translucency", "set_translucency", clamp=True),
    "shadows": _check("shadows", "scene.shadow", "set_shadows"),
}
