"""The viewer's imgui panel: preset, season, wind, modal ranges, stiffness, time, overlays,
statistics, and saving or loading the settings as a preset.

Every change goes through :meth:`Panel.apply`, which sets the simulation's checked properties
(``sim.season``, ``sim.physics = dataclasses.replace(...)``, the wind's setters ...) and shows
any refusal in the panel's status line instead of raising.
"""

from __future__ import annotations

import dataclasses
import time
from pathlib import Path

import numpy as np
from imgui_bundle import imgui

from ..model.params import ModeRange
from ..model.tree import KINDS
from ..physics.simulation import INTEGRATORS
from ..physics.wind import WIND_PRESETS
from ..render.renderer import sun_angles, sun_direction
from .settings import save_preset
from .winddir import wind_angle

#: Width of the panel in screen units at UI scale 1.
PANEL_WIDTH = 330

#: Slider ranges: (min, max, format, logarithmic).
RANGES = {
    "season": (0.0, 1.0, "%.2f", False),
    "wind_speed": (0.0, 30.0, "%.1f m/s", False),
    "wind_angle": (0.0, 360.0, "%.0f°", False),
    "turbulence": (0.0, 1.0, "%.2f", False),  # physical: intensity at the canopy top
    "turbulence_paper": (1.0, 2.0, "%.2f", False),  # paper: λ of Eq. 17
    "gust_strength": (0.0, 2.0, "%.2f", False),
    "gust_rate": (0.0, 30.0, "%.1f /min", False),
    "length_scale": (0.5, 100.0, "%.1f m", True),
    "beta_u": (0.5, 3.0, "%.2f", False),
    "beta_vw": (0.5, 3.0, "%.2f", False),
    "c3": (0.0, 2.0, "%.2f", False),
    "c4": (0.0, 2.0, "%.2f", False),
    "ei_max": (0.0, 0.0, "%.3g N·m²", True),  # set per tree: the preset's value ÷ or × EI_SPAN
    "time_scale": (0.05, 2.0, "%.2f×", True),
    "sun_azimuth": (0.0, 360.0, "%.0f°", False),
    "sun_elevation": (5.0, 90.0, "%.0f°", False),
    "translucency": (0.0, 1.0, "%.2f", False),
}
#: The EI_max slider spans the preset's value divided or multiplied by this.
EI_SPAN = 30.0
_PLURAL = {"branch": "branches", "leaf": "leaves", "blade": "blades"}
_WINDOW_FLAGS = imgui.WindowFlags_.no_move | imgui.WindowFlags_.no_resize | imgui.WindowFlags_.no_saved_settings


class Panel:
    """The settings panel of a :class:`~treeanim.app.viewer.Viewer`.

    Attributes
    ----------
    path : str
        The file the Save and Open buttons use (Open also reads TreeQSM models).
    edit_season : {'summer', 'winter'}
        Which season's f and ζ ranges the range widgets edit.
    record_rects : bool
        Fill :attr:`item_rects` while drawing (off by default: it costs a few imgui calls a
        widget).
    item_rects : dict
        Label → (x0, y0, x1, y1) in screen units of each widget as last drawn, for tests and
        scripts that click on them.
    rect : tuple or None
        (x0, y0, x1, y1) of the panel window as last drawn.
    """

    def __init__(self, viewer) -> None:
        self.viewer = viewer
        self.path = ""
        self._default_path = ""
        self.edit_season = "summer"
        self.item_rects: dict[str, tuple[float, float, float, float]] = {}
        self.rect: tuple[float, float, float, float] | None = None
        self._presets: list[str] | None = None
        self._kinds: list[str] = []
        self._ranges: dict[str, tuple] = {}
        self._pending: dict[str, float] = {}  # slider values applied when the slider is let go
        self.record_rects = False
        self.busy = False  # a widget is active or a popup is open (it owns the mouse)
        self._text_key = None
        self._text: tuple[str, str] = ("", "")
        self._timing_at = -1.0
        self._timing = ""

    # ------------------------------------------------------------------ geometry
    @property
    def width(self) -> float:
        """Width in screen units."""
        return PANEL_WIDTH * self.viewer.gui.scale

    def contains(self, x: float, y: float) -> bool:
        """Whether screen point (x, y) lies on the panel as last drawn."""
        r = self.rect
        return r is not None and r[0] <= x < r[2] and r[1] <= y < r[3]

    def owns_mouse(self, x: float, y: float) -> bool:
        """Whether a click at (x, y) belongs to the panel: on it, or anywhere while one of its
        widgets is active or a popup (a combo's list) is open."""
        return self.busy or self.contains(x, y)

    def presets(self) -> list[str]:
        if self._presets is None:
            from ..model.presets import list_presets

            self._presets = list_presets()
        return self._presets

    def tree_changed(self) -> None:
        """The viewer shows a new tree: default file name and season table."""
        v = self.viewer
        if not self.path or self.path == self._default_path:  # a name the user typed is kept
            self.path = f"{v.sim.tree.name}-custom.toml"
        self._default_path = f"{v.sim.tree.name}-custom.toml"
        self.edit_season = "summer" if v.sim.season < 0.5 else "winter"
        self._kinds = [k for k in KINDS if np.any(v.sim.tree.kind == k)]
        ei = float(v.sim.tree.physics.ei_max)
        self._ranges = {"ei_max": (ei / EI_SPAN, ei * EI_SPAN, *RANGES["ei_max"][2:])}
        self._pending.clear()

    # ------------------------------------------------------------------ changes
    def apply(self, name: str, value) -> bool:
        """Apply one setting; returns whether it was accepted (a refusal is shown in the panel).

        Names: ``preset`` (a shipped preset's name), ``season``, ``wind_speed``, ``wind_angle``
        (degrees about +y), ``wind_preset`` (calm, breeze, windy, gale, storm), ``turbulence``,
        ``gust_strength``, ``gust_rate``, ``length_scale``, ``beta_u``, ``beta_vw``, ``c3``, ``c4``, ``ei_max``,
        ``f:KIND`` and ``zeta:KIND`` ((min, max) of the edited season's table), ``time_scale``,
        ``integrator``, ``coupling``, ``load_path``, ``physical_modes``, ``paused``, ``show_trace``, ``show_frames``, ``show_wind``,
        ``sun_azimuth`` and ``sun_elevation`` (degrees), ``shadows``, ``translucency``.
        """
        v = self.viewer
        sim = v.sim
        try:
            if name == "preset":
                from ..model.presets import load_preset

                v.load_tree(load_preset(value))
                v.say(f"loaded preset {value}")
            elif name == "season":
                sim.season = float(value)
            elif name == "wind_speed":
                v.set_wind(speed=float(value))
            elif name == "wind_angle":
                v.set_wind(angle=float(value))
            elif name == "turbulence_paper":
                v.set_wind(turbulence=float(value))
            elif name in ("turbulence", "beta_u", "beta_vw", "c3", "c4", "gust_strength", "gust_rate",
                          "length_scale"):
                v.set_wind(**{name: float(value)})
            elif name == "wind_preset":
                v.set_wind(preset=str(value))
                v.say(f"wind: {value}")
            elif name == "ei_max":
                sim.physics = dataclasses.replace(sim.physics, ei_max=float(value))
            elif name.startswith(("f:", "zeta:")):
                what, kind = name.split(":")
                p = sim.physics
                table = getattr(p, self.edit_season)
                cur = table.of(kind) or p.modes(kind, sim.season)
                lo, hi = sorted(float(x) for x in value)
                new = ModeRange((lo, hi), cur.zeta) if what == "f" else ModeRange(cur.f, (lo, hi))
                table = dataclasses.replace(table, **{kind: new})
                sim.physics = dataclasses.replace(p, **{self.edit_season: table})
            elif name == "time_scale":
                lo, hi = RANGES["time_scale"][:2]
                v.time_scale = min(max(float(value), lo), hi)
            elif name == "integrator":
                sim.integrator = value
            elif name == "coupling":
                sim.coupling = bool(value)
            elif name == "load_path":
                sim.load_path = bool(value)
            elif name == "physical_modes":  # beam theory, or the preset's ranges (Eqs. 20–22)
                sim.modal = v.tree.modes = "physical" if value else "paper"
            elif name in ("paused", "show_trace", "show_frames", "show_wind"):
                setattr(v, name, bool(value))
            elif name in ("sun_azimuth", "sun_elevation"):
                az, el = sun_angles(v.scene.sun_direction)
                az, el = (float(value), el) if name == "sun_azimuth" else (az, float(value))
                lo, hi = RANGES["sun_elevation"][:2]
                v.scene.sun_direction = sun_direction(az % 360.0, min(max(el, lo), hi))
            elif name == "shadows":
                v.scene.shadow = bool(value)
            elif name == "translucency":
                v.scene.translucency = min(max(float(value), 0.0), 1.0)
            else:
                raise ValueError(f"unknown setting {name!r}")
        except (ValueError, OSError) as e:
            v.say(f"error: {' '.join(str(e).split())}")
            return False
        return True

    def save(self, path: str | None = None) -> Path | None:
        """Save the current physics (and the tree's seed) as a preset at ``path`` (default
        :attr:`path`). Returns the file, or None after showing why not."""
        v = self.viewer
        target = path or self.path
        try:
            out = save_preset(target, v.sim.tree, v.sim.physics)
        except (ValueError, OSError) as e:
            v.say(f"error: {' '.join(str(e).split())}")
            return None
        v.say(f"saved {out}")
        print(f"treeanim: saved preset {out}", flush=True)
        return out

    def load(self, path: str | None = None) -> bool:
        """Open a preset or TreeQSM model file (default :attr:`path`; .toml, .txt, .csv or .mat)
        and show its tree (a model's counts in Statistics).

        Returns
        -------
        bool
            Whether the tree is shown. A file that cannot be read or parsed (PresetError), or a
            tree the simulation refuses (ValueError, e.g. no f/ζ range for a kind the tree
            has), is reported in the panel's status line; the current tree stays.
        """
        import treeanim as ta

        from ..model.qsm import QSM_SUFFIXES

        v = self.viewer
        target = path or self.path
        try:
            v.load_tree(ta.load_qsm(target) if str(target).lower().endswith(QSM_SUFFIXES) else ta.load_tree(target))
        except (ValueError, OSError) as e:  # PresetError is a ValueError
            v.say(f"error: {' '.join(str(e).split())}")
            return False
        v.say(f"loaded {target}")
        return True

    # ------------------------------------------------------------------ drawing
    def _rect(self, label: str, frame_only: bool = False) -> None:
        if not self.record_rects:
            return
        a, b = imgui.get_item_rect_min(), imgui.get_item_rect_max()
        x1 = a.x + imgui.calc_item_width() if frame_only else b.x  # the widget without its label
        self.item_rects[label] = (a.x, a.y, x1, b.y)

    def _header(self, label: str, open_: bool = False) -> bool:
        shown = imgui.collapsing_header(label, imgui.TreeNodeFlags_.default_open if open_ else 0)
        self._rect(label)
        return shown

    def _slider(self, label: str, name: str, value: float, deferred: bool = False) -> None:
        lo, hi, fmt, log = self._ranges.get(name) or RANGES[name]
        flags = imgui.SliderFlags_.logarithmic if log else 0
        shown = self._pending.get(name, value)
        changed, new = imgui.slider_float(label, shown, lo, hi, fmt, flags)
        self._rect(label, frame_only=True)
        if deferred:  # rebuilding noise grids on every drag step would stall the frame
            if changed:
                self._pending[name] = new
            if name in self._pending and not imgui.is_item_active():
                self.apply(name, self._pending.pop(name))
        elif changed:
            self.apply(name, new)

    def _check(self, label: str, name: str, value: bool) -> None:
        changed, new = imgui.checkbox(label, value)
        self._rect(label)
        if changed:
            self.apply(name, new)

    def draw(self) -> None:
        """Build the panel for this frame (between ``imgui.new_frame`` and ``imgui.render``)."""
        v = self.viewer
        sim = v.sim
        wind = sim.wind
        s = v.gui.scale
        ww, wh = v._win
        self.item_rects = {}
        imgui.set_next_window_pos(imgui.ImVec2(8 * s, 8 * s), imgui.Cond_.always)
        imgui.set_next_window_size_constraints(imgui.ImVec2(self.width, 0),
                                               imgui.ImVec2(self.width, max(wh - 16 * s, 60)))
        imgui.set_next_window_size(imgui.ImVec2(self.width, 0), imgui.Cond_.always)
        expanded, _ = imgui.begin("treeanim", None, _WINDOW_FLAGS)
        pos, size = imgui.get_window_pos(), imgui.get_window_size()
        self.rect = (pos.x, pos.y, pos.x + size.x, pos.y + size.y)
        if not expanded:
            imgui.end()
            self.busy = False
            return
        imgui.push_item_width(-110 * s)

        # --- statistics
        key = (id(sim.tree), sim.season)
        if key != self._text_key:  # the counts change only with the tree and the season
            st = v.stats()
            kinds = [k for k in KINDS if st[_PLURAL[k]]]
            self._text = ("  ".join(f"{st[_PLURAL[k]]:,} {_PLURAL[k]}" for k in kinds),
                          f"{st['objects']:,} objects  {st['nodes']:,} nodes  {st['triangles']:,} tris")
            self._text_key = key
        imgui.text(self._text[0])
        imgui.text(self._text[1])
        now = time.perf_counter()
        if now - self._timing_at > 0.25:  # readable, and cheaper than formatting every frame
            fps = 1.0 / v.frame_s.value if v.frame_s.value else 0.0
            rt = f"  {v.real_time.value:.2f}× real time" if v.real_time.value is not None else ""
            self._timing = f"sim {v.sim_ms.value or 0:.1f} ms  render {v.render_ms.value or 0:.1f} ms  {fps:.0f} FPS{rt}"
            self._timing_at = now
        imgui.text(self._timing)
        gl = v.gl_renderer.split(" (")[0][:24]
        msaa = f"MSAA {v.window.samples}×" if v.window.samples else "no MSAA"
        state = f"{'paused' if v.paused else f't = {sim.time:.1f} s'}   {gl}, {msaa}"
        if v.grab is not None:
            state += f"  pulling #{v.grab.object} ({sim.tree.kind[v.grab.object]})"
        imgui.text_disabled(state)
        imgui.separator()

        # --- tree
        presets = self.presets()
        name = sim.tree.name
        items = presets if name in presets else presets + [f"{name} (file)"]
        current = items.index(name) if name in items else len(items) - 1
        changed, idx = imgui.combo("preset", current, items)
        self._rect("preset")
        if changed and idx != current and idx < len(presets):
            self.apply("preset", presets[idx])
            sim, wind = v.sim, v.sim.wind
        self._slider("season", "season", sim.season)

        # --- wind
        if self._header("Wind", open_=True):
            physical = wind.model == "physical"
            if physical:
                names = list(WIND_PRESETS)
                changed, idx = imgui.combo("named wind", -1, [f"{n} (Bf {WIND_PRESETS[n]['beaufort']})" for n in names])
                self._rect("named wind", frame_only=True)
                if changed and 0 <= idx < len(names):
                    self.apply("wind_preset", names[idx])
            self._slider("speed", "wind_speed", wind.speed)
            self._slider("direction", "wind_angle", wind_angle(wind.direction))
            if physical:
                self._slider("turbulence", "turbulence", wind.turbulence)
                self._slider("gust strength", "gust_strength", wind.gust_strength)
                self._slider("gust rate", "gust_rate", wind.gust_rate)
                self._slider("length scale", "length_scale", wind.length_scale)
            else:
                self._slider("turbulence λ", "turbulence_paper", wind.turbulence)
            self._slider("β_u", "beta_u", wind.beta_u, deferred=True)
            self._slider("β_vw", "beta_vw", wind.beta_vw, deferred=True)
            if not physical:
                self._slider("c3 (vertical)", "c3", wind.c3)
                self._slider("c4 (lateral)", "c4", wind.c4)

        # --- physics
        if self._header("Physics", open_=True):
            p = sim.physics
            imgui.text("ranges of")
            imgui.same_line()
            if imgui.radio_button("summer", self.edit_season == "summer"):
                self.edit_season = "summer"
            imgui.same_line()
            if imgui.radio_button("winter", self.edit_season == "winter"):
                self.edit_season = "winter"
            imgui.same_line()
            self._check("physical", "physical_modes", sim.modal == "physical")  # branches: beam theory
            table = getattr(p, self.edit_season)
            for kind in self._kinds:
                r = table.of(kind) or p.modes(kind, sim.season)
                if r is None:
                    continue
                changed, lo, hi = imgui.drag_float_range2(f"f {kind} (Hz)", r.f[0], r.f[1], 0.01, 0.05, 20.0,
                                                          "%.2f", "%.2f", imgui.SliderFlags_.always_clamp)
                self._rect(f"f {kind}")
                if changed:
                    self.apply(f"f:{kind}", (max(lo, 0.05), max(hi, 0.05)))
                changed, lo, hi = imgui.drag_float_range2(f"ζ {kind}", r.zeta[0], r.zeta[1], 0.002, 0.0, 2.0,
                                                          "%.3f", "%.3f", imgui.SliderFlags_.always_clamp)
                self._rect(f"zeta {kind}")
                if changed:
                    self.apply(f"zeta:{kind}", (max(lo, 0.0), max(hi, 0.0)))
            self._slider("EI_max", "ei_max", p.ei_max)

        # --- time
        if self._header("Simulation", open_=True):
            self._slider("time scale", "time_scale", v.time_scale)
            current = INTEGRATORS.index(sim.integrator)
            changed, idx = imgui.combo("integrator", current, list(INTEGRATORS))
            self._rect("integrator")
            if changed:
                self.apply("integrator", INTEGRATORS[idx])
            self._check("coupling", "coupling", sim.coupling)
            imgui.same_line()
            self._check("load path", "load_path", sim.load_path)
            imgui.same_line()
            if imgui.button("Resume" if v.paused else "Pause"):
                self.apply("paused", not v.paused)
            self._rect("pause")
            imgui.same_line()
            if imgui.button("Reset"):
                v.reset()
            self._rect("reset")
            imgui.same_line()
            if imgui.button("Frame"):
                v.frame_camera()

        # --- overlays
        if self._header("Overlays", open_=True):
            self._check("pull trace", "show_trace", v.show_trace)
            imgui.same_line()
            self._check("local frames", "show_frames", v.show_frames)
            self._check("wind slices + arrow", "show_wind", v.show_wind)

        # --- light
        if self._header("Light"):
            az, el = sun_angles(v.scene.sun_direction)
            self._slider("sun azimuth", "sun_azimuth", az)
            self._slider("sun elevation", "sun_elevation", el)
            self._slider("translucency", "translucency", v.scene.translucency)
            self._check("shadows", "shadows", v.scene.shadow)

        # --- preset file
        if self._header("Preset file"):
            changed, text = imgui.input_text("##path", self.path)
            self._rect("path")
            if changed:
                self.path = text
            if imgui.button("Save"):
                self.save()
            self._rect("save")
            imgui.same_line()
            if imgui.button("Open"):  # a preset .toml or a TreeQSM model (.txt, .csv, .mat)
                self.load()
            self._rect("load")
            imgui.same_line()
            imgui.text_disabled("Ctrl+S / Ctrl+O")

        for line in v.messages[-2:]:
            if line.startswith("error"):
                imgui.push_style_color(imgui.Col_.text, imgui.ImVec4(1.0, 0.45, 0.4, 1.0))
                imgui.text_wrapped(line)
                imgui.pop_style_color()
            else:
                imgui.text_wrapped(line)
        if self._header("Controls"):
            for line in ("left-drag a branch or leaf: pull, let go: swing", "left-drag the sky: orbit",
                         "right/middle-drag: pan   wheel: zoom", "F frame  Space pause  R reset  H panel",
                         "S/F12 screenshot  F11 full screen  Esc/Q quit"):
                imgui.push_style_color(imgui.Col_.text, imgui.get_style_color_vec4(imgui.Col_.text_disabled))
                imgui.text_wrapped(line)  # the panel is narrow: lines wrap rather than run off its edge
                imgui.pop_style_color()
        imgui.pop_item_width()
        imgui.end()
        # What the next clicks belong to (io.want_capture_mouse lags a frame behind the cursor).
        self.busy = imgui.is_any_item_active() or imgui.is_popup_open("", imgui.PopupFlags_.any_popup)

