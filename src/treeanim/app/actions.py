"""What the panel, the keys and scripts do to the viewer, each a plain method: open a preset or a
file, save, switch the model, set the season, the wind, the physics, the time scale, the light
and the overlays, take a screenshot, say a line in the status line.

Mixed into :class:`treeanim.app.viewer.Viewer`, whose simulation, scene and window they change.
The setters go through the simulation's checked properties and raise ValueError on a refusal
(the panel shows it in its status line: :meth:`Panel.apply <treeanim.app.panel.Panel.apply>`);
the file actions, which keys also call, report in the status line themselves and return what
they did. The panel's table of widgets (:data:`treeanim.app.settings.SETTINGS`) names these
methods; the key table (:data:`treeanim.app.keys.BINDINGS`) names the ones without arguments.
"""

from __future__ import annotations

import dataclasses
import math
from datetime import datetime
from pathlib import Path

import numpy as np

from ..model.params import ModeRange
from ..physics.simulation import MODELS
from ..physics.wind import wind_preset as wind_preset_kwargs
from ..render.scene import sun_angles, sun_direction
from .save import save_preset
from .winddir import wind_angle, wind_direction

__all__ = ["ViewerActions", "TIME_SCALES", "SUN_ELEVATIONS", "OVERLAYS"]

#: The time scale's range: simulated seconds per real second.
TIME_SCALES = (0.05, 2.0)
#: The sun's elevation's range, degrees (below 5° the ground's shadows run off to the horizon).
SUN_ELEVATIONS = (5.0, 90.0)
#: The overlays :meth:`ViewerActions.set_overlay` switches, and the viewer's flag of each.
OVERLAYS = {"trace": "show_trace", "frames": "show_frames", "wind": "show_wind"}


def _one_line(e: BaseException) -> str:
    return " ".join(str(e).split())


class ViewerActions:
    """Actions of a :class:`~treeanim.app.viewer.Viewer` (its panel's, its keys', a script's)."""

    # ------------------------------------------------------------------ the status line
    def say(self, line: str) -> None:
        """Show one line in the panel's status line."""
        self.messages.append(line)
        del self.messages[:-4]

    # ------------------------------------------------------------------ trees and files
    def open_preset(self, name: str) -> None:
        """Show the shipped preset ``name`` (PresetError, a ValueError, for an unknown one)."""
        from ..model.presets import load_preset

        self.load_tree(load_preset(name))
        self.say(f"loaded preset {name}")

    def _follow_file_name(self) -> None:
        """The preset file name follows the tree shown, unless one was typed."""
        default = f"{self.sim.tree.name}-custom.toml"
        if not self.preset_path or self.preset_path == self._default_path:
            self.preset_path = default
        self._default_path = default

    def open_file(self, path=None) -> bool:
        """Open a tree file (default :attr:`preset_path`): a preset or scene .toml, or a TreeQSM
        model (.txt, .csv or .mat), read by ``treeanim.load_tree``, and show its tree or scene.

        Returns
        -------
        bool
            Whether the tree is shown. A file that cannot be read or parsed (PresetError), or a
            tree the simulation refuses (ValueError, e.g. no f/ζ range for a kind the tree
            has), is reported in the status line; the current tree stays.
        """
        import treeanim as ta

        target = path or self.preset_path
        try:
            self.load_tree(ta.load_tree(target))
        except (ValueError, OSError) as e:  # PresetError is a ValueError
            self.say(f"error: {_one_line(e)}")
            return False
        self.say(f"loaded {target}")
        return True

    def save_preset(self, path=None) -> Path | None:
        """Save the current physics (and the tree's seed) as a preset at ``path`` (default
        :attr:`preset_path`; :func:`treeanim.app.save.save_preset`). Returns the file, or None
        after showing why not in the status line."""
        target = path or self.preset_path
        try:
            out = save_preset(target, self.sim.tree, self.sim.physics)
        except (ValueError, OSError) as e:
            self.say(f"error: {_one_line(e)}")
            return None
        self.say(f"saved {out}")
        print(f"treeanim: saved preset {out}", flush=True)
        return out

    # ------------------------------------------------------------------ the model
    def set_model(self, name: str) -> None:
        """Switch the simulation to model ``name`` ('tree' or 'paper'; ValueError otherwise):
        any grab is let go and the trace cleared; the tree restarts from rest (time, wind,
        season and physics are kept)."""
        if name == self.sim.model:
            return
        if name not in MODELS:
            raise ValueError(f"model must be one of {tuple(MODELS)}, got {name!r}")
        if self.sim.model == "paper":
            self._integrator, self._coupling = self.sim.integrator, self.sim.coupling
        self._end_drag()
        self.sim.model = name
        self._model = self.sim.model
        self._restarted()
        self._uploaded = None
        self.note_defaults()  # the paper model's settings, the first time it runs on this tree

    def set_paper_model(self, on: bool) -> None:
        """The paper's model (True) or the tree model (False): :meth:`set_model`."""
        self.set_model("paper" if on else "tree")

    def set_integrator(self, name: str) -> None:
        """The paper model's oscillator integrator ('exact' or 'euler'; AttributeError on the
        tree model, which has none)."""
        self.sim.integrator = name

    def set_coupling(self, on: bool) -> None:
        """Whether the paper's model couples each object to its parent's motion (AttributeError
        on the tree model)."""
        self.sim.coupling = bool(on)

    def set_physical_modes(self, on: bool) -> None:
        """The paper model's branch modes from beam theory (True) or the preset's ranges (Eqs.
        20–22); the tree keeps the choice for the next simulation (AttributeError on the tree
        model)."""
        self.sim.modal = self.tree.modes = "physical" if on else "paper"

    # ------------------------------------------------------------------ settings
    def set_season(self, season: float) -> None:
        """0 summer … 1 winter (ValueError outside)."""
        self.sim.season = float(season)

    @property
    def wind_angle(self) -> float:
        """The wind's direction, degrees about +y from +x, in [0, 360)."""
        return wind_angle(self.sim.wind.direction)

    def set_wind(self, **changes) -> None:
        """Change wind settings: ``speed``, ``angle`` (degrees), ``turbulence``, ``beta_u``,
        ``beta_vw``, ``c3``, ``c4``, ``gust_strength``, ``gust_rate``, ``length_scale``
        (each through the WindField's checked setters), or ``preset`` (a named wind of
        :data:`treeanim.physics.wind.WIND_PRESETS`: its speed, turbulence and gusts)."""
        w = self.sim.wind
        if "preset" in changes:
            changes = {**wind_preset_kwargs(changes.pop("preset"), w.model), **changes}
            del changes["model"]
        for k, v in changes.items():
            if k == "angle":
                w.direction = wind_direction(v)
            else:
                setattr(w, k, v)

    def set_wind_preset(self, name: str) -> None:
        """A named wind (:meth:`set_wind` ``preset=``), said in the status line."""
        self.set_wind(preset=str(name))
        self.say(f"wind: {name}")

    def set_physics(self, **changes) -> None:
        """Change physics settings by name (``ei_max=5000.0`` …), checked by their declarations
        (:class:`~treeanim.model.params.PhysicsParams`; a refusal is a ValueError)."""
        self.sim.physics = dataclasses.replace(self.sim.physics, **changes)

    def mode_range(self, kind: str, what: str, season: str = "summer") -> tuple[float, float] | None:
        """The (min, max) f (``what='f'``) or ζ (``'zeta'``) of ``kind`` in the ``season``
        ('summer' or 'winter') table, or, where that table has none, the range at the current
        season; None if the tree's physics has none for ``kind``."""
        p = self.sim.physics
        r = getattr(p, season).of(kind) or p.modes(kind, self.sim.season)
        return None if r is None else getattr(r, what)

    def set_mode_range(self, kind: str, what: str, value, season: str = "summer") -> None:
        """Set the (min, max) f or ζ of ``kind`` in the ``season`` table (given in either order;
        the ranges are the preset's, saved with it, on either model: only the paper's uses
        them)."""
        p = self.sim.physics
        table = getattr(p, season)
        cur = table.of(kind) or p.modes(kind, self.sim.season)
        lo, hi = sorted(float(x) for x in value)
        new = ModeRange((lo, hi), cur.zeta) if what == "f" else ModeRange(cur.f, (lo, hi))
        self.sim.physics = dataclasses.replace(p, **{season: dataclasses.replace(table, **{kind: new})})

    def set_time_scale(self, scale: float) -> None:
        """Simulated seconds per real second, clamped to :data:`TIME_SCALES` (ValueError: not a
        number)."""
        scale = float(scale)
        if math.isnan(scale):
            raise ValueError("time scale: expected a number, got nan")
        self.time_scale = min(max(scale, TIME_SCALES[0]), TIME_SCALES[1])

    # ------------------------------------------------------------------ the look
    @property
    def sun_angles(self) -> tuple[float, float]:
        """(azimuth, elevation) of the sun, degrees."""
        return sun_angles(self.scene.sun_direction)

    def set_sun(self, azimuth: float | None = None, elevation: float | None = None) -> None:
        """Move the sun (degrees; None keeps an angle); the elevation is clamped to
        :data:`SUN_ELEVATIONS`."""
        az, el = self.sun_angles
        az = az if azimuth is None else float(azimuth)
        el = el if elevation is None else float(elevation)
        if not (np.isfinite(az) and np.isfinite(el)):
            raise ValueError(f"sun: expected finite angles, got {az}, {el}")
        self.scene.sun_direction = sun_direction(az % 360.0, min(max(el, SUN_ELEVATIONS[0]), SUN_ELEVATIONS[1]))

    def set_translucency(self, amount: float) -> None:
        """Sunlight through the leaves, 0 (opaque) … 1, clamped."""
        self.scene.translucency = min(max(float(amount), 0.0), 1.0)

    def set_shadows(self, on: bool) -> None:
        """The sun's shadows on or off."""
        self.scene.shadow = bool(on)

    def set_overlay(self, name: str, on: bool) -> None:
        """Show (True) or hide overlay ``name``: 'trace' (the grabbed point's path), 'frames'
        (the objects' local frames) or 'wind' (the wind's slices and arrow)."""
        if name not in OVERLAYS:
            raise ValueError(f"overlay must be one of {tuple(OVERLAYS)}, got {name!r}")
        setattr(self, OVERLAYS[name], bool(on))

    def toggle_panel(self) -> None:
        """Hide or show the panel."""
        self.show_panel = not self.show_panel
        if self.show_panel:
            self.gui.mouse_pos(*self._cursor)

    def toggle_fullscreen(self) -> None:
        """Full screen on the window's monitor, or back (nothing headless)."""
        self.window.toggle_fullscreen()

    # ------------------------------------------------------------------ screenshots
    def request_screenshot(self, path=None) -> None:
        """Write a screenshot after the next frame is drawn (see :meth:`screenshot`)."""
        self._screenshot_pending.append(None if path is None else Path(path))

    def screenshot(self, path=None) -> Path:
        """Write the frame as drawn so far as a PNG and print its path.

        Parameters
        ----------
        path : path-like or None
            None: ``treeanim-YYYYmmdd-HHMMSS.png`` in the current folder (``-2``, ``-3`` … if
            taken within the same second).
        """
        import imageio.v3 as iio

        if path is None:
            stem = "treeanim-" + datetime.now().strftime("%Y%m%d-%H%M%S")
            path = Path(stem + ".png")
            k = 2
            while path.exists():
                path = Path(f"{stem}-{k}.png")
                k += 1
        path = Path(path)
        iio.imwrite(path, self.read_pixels())
        self.screenshots.append(path)
        self.say(f"screenshot: {path}")
        print(f"treeanim: screenshot {path.resolve()}", flush=True)
        return path

    # ------------------------------------------------------------------ the window
    def quit(self) -> None:
        """Close the window (the main loop ends)."""
        self.window.request_close()
