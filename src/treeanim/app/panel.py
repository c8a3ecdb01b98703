"""The viewer's imgui panel: preset, season, wind, the model (the tree model or the paper's, with
its modal ranges, integrator and coupling), stiffness, time, overlays, statistics, and saving
or loading the settings as a preset.

The settings are the table :data:`treeanim.app.settings.SETTINGS`: :meth:`Panel.widget` draws
one from it, and every change goes through :meth:`Panel.apply`, which calls the viewer's method
for it (:class:`~treeanim.app.actions.ViewerActions`) and shows any refusal in the panel's status
line instead of raising. The buttons call the viewer's methods too (``reset``, ``frame_camera``,
``save_preset``, ``open_file``); the panel reads the viewer's public state and keeps only its
own (which season's ranges it edits, the widgets' places, a slider's value until it is let go).
"""

from __future__ import annotations

import time

import numpy as np
from imgui_bundle import imgui

from ..model.tree import KINDS, PLURAL
from ..physics.wind import WIND_PRESETS, named_wind
from .keys import help_lines
from .plots import draw_plots
from .settings import EI_SPAN, SETTINGS

#: Width of the panel in screen units at UI scale 1.
PANEL_WIDTH = 330
#: Gap between the panel and the window's top and left edges (and the scene), at UI scale 1.
PANEL_GAP = 8

#: The wind's sliders, in the panel's order (each shown only for its wind model).
WIND_SLIDERS = ("wind_speed", "wind_angle", "turbulence", "turbulence_paper", "gust_strength", "gust_rate",
                "length_scale", "beta_u", "beta_vw", "c3", "c4")
#: The Light section.
LIGHT = ("sun_azimuth", "sun_elevation", "translucency", "shadows")
_WINDOW_FLAGS = imgui.WindowFlags_.no_move | imgui.WindowFlags_.no_resize | imgui.WindowFlags_.no_saved_settings


class Panel:
    """The settings panel of a :class:`~treeanim.app.viewer.Viewer`.

    Attributes
    ----------
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
        self.edit_season = "summer"
        self.item_rects: dict[str, tuple[float, float, float, float]] = {}
        self.rect: tuple[float, float, float, float] | None = None
        self._presets: list[str] | None = None
        self._kinds: list[str] = []
        self._ranges: dict[str, tuple[float, float]] = {}  # per tree: EI_max's
        self._pending: dict[str, float] = {}  # slider values applied when the slider is let go
        self.record_rects = False
        self.busy = False  # a widget is active or a popup is open (it owns the mouse)
        self._text_key = None
        self._text: tuple[str, str] = ("", "")
        self._timing_at = -1.0
        self._timing = ""
        self._holding: str | None = None  # the setting whose widget is held since it changed

    # ------------------------------------------------------------------ geometry
    @property
    def width(self) -> float:
        """Width in screen units."""
        return PANEL_WIDTH * self.viewer.gui.scale

    @property
    def right(self) -> float:
        """Screen units from the window's left edge to the scene beside the panel."""
        return (PANEL_WIDTH + 2 * PANEL_GAP) * self.viewer.gui.scale

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
        """The viewer shows a new tree: the season table edited, the kinds, EI_max's range."""
        v = self.viewer
        self.edit_season = "summer" if v.sim.season < 0.5 else "winter"
        self._kinds = [k for k in KINDS if np.any(v.sim.tree.kind == k)]
        ei, st = float(v.sim.tree.physics.ei_max), SETTINGS["ei_max"]
        self._ranges = {"ei_max": (max(ei / EI_SPAN, st.lo), min(ei * EI_SPAN, st.hi))}
        self._pending.clear()

    # ------------------------------------------------------------------ changes
    def apply(self, name: str, value, merge: bool = False) -> bool:
        """Apply setting ``name`` (a key of :data:`~treeanim.app.settings.SETTINGS`: ``preset``,
        ``season``, the wind's, ``ei_max``, ``f:KIND`` and ``zeta:KIND`` ((min, max) of the
        edited season's table), ``time_scale``, ``paper_model``, the paper model's
        ``integrator``, ``coupling`` and ``physical_modes``, the switches, the light's, ``draft``)
        through the viewer's method for it, recorded to undo
        (:meth:`Viewer.change_setting <treeanim.app.tuning.ViewerTuning.change_setting>`;
        ``merge``: part of the last step, a slider still held); returns whether it was accepted
        (a refusal is shown in the panel)."""
        return self.viewer.change_setting(name, value, season=self.edit_season, merge=merge)

    def _held(self, name: str, changed: bool) -> bool:
        """After a widget of setting ``name``: whether a change continues the step of the same
        held widget (a drag is one step to undo); a right-click sets it back to its default."""
        merge = self._holding == name
        if imgui.is_item_active():
            if changed:
                self._holding = name
        elif self._holding == name:
            self._holding = None
        if imgui.is_item_clicked(imgui.MouseButton_.right):
            self.viewer.reset_setting(name, self.edit_season)
        elif imgui.is_item_hovered() and not self.viewer.is_default(name, self.edit_season):
            imgui.set_tooltip("right-click: back to its default")
        return merge

    def state_line(self) -> str:
        """The status line under the timings: time or paused, the GL renderer and its
        multisampling (or draft mode), what is grabbed."""
        v, sim = self.viewer, self.viewer.sim
        gl = v.gl_renderer.split(" (")[0][:24]
        msaa = f"MSAA {v.window.samples}×" if v.window.samples else "no MSAA"
        if v.draft:
            msaa = "DRAFT: ½ res, no MSAA, no shadows"
        state = f"{'paused' if v.paused else f't = {sim.time:.1f} s'}   {gl}, {msaa}"
        if v.grab is not None:
            verb = "dragging" if sim.model == "tree" else "pulling"
            state += f"  {verb} #{v.grab.object} ({sim.tree.kind[v.grab.object]})"
        return state

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

    def widget(self, name: str) -> None:
        """Draw setting ``name``'s slider, checkbox or combo (as :data:`SETTINGS` describes it,
        if it is shown for this wind and model) and apply a change."""
        st = SETTINGS[name]
        v = self.viewer
        if st.shown is not None and not st.shown(v):
            return
        value = st.value(v)
        if st.kind == "check":
            changed, new = imgui.checkbox(st.label, value)
            self._rect(st.label)
        elif st.kind == "choice":
            current = st.choices.index(value)
            changed, idx = imgui.combo(st.label, current, list(st.choices))
            self._rect(st.label)
            new = st.choices[idx]
        else:
            lo, hi = self._ranges.get(name, (st.lo, st.hi))
            flags = imgui.SliderFlags_.logarithmic if st.log else 0
            changed, new = imgui.slider_float(st.label, self._pending.get(name, value), lo, hi, st.fmt, flags)
            self._rect(st.label, frame_only=True)
            if st.deferred:
                if changed:
                    self._pending[name] = new
                if name in self._pending and not imgui.is_item_active():
                    self.apply(name, self._pending.pop(name))
                if imgui.is_item_clicked(imgui.MouseButton_.right):
                    self.viewer.reset_setting(name)
                return
        merge = self._held(name, changed)
        if changed:
            self.apply(name, new, merge=merge)

    def _range_pair(self, name: str, speed: float) -> None:
        """Setting ``name``'s (min, max) pair as two linked drag fields (f or ζ of a kind), in its
        declared range and format."""
        st = SETTINGS[name]
        if st.shown is not None and not st.shown(self.viewer):
            return
        r = self.viewer.mode_range(*st.args, season=self.edit_season)
        if r is None:
            return
        changed, lo, hi = imgui.drag_float_range2(st.label, r[0], r[1], speed, st.lo, st.hi, st.fmt, st.fmt,
                                                  imgui.SliderFlags_.always_clamp)
        self._rect(name.replace(":", " "))
        merge = self._held(name, changed)
        if changed:
            self.apply(name, (max(lo, st.lo), max(hi, st.lo)), merge=merge)

    def _button(self, label: str, enabled: bool, rect: str) -> bool:
        imgui.begin_disabled(not enabled)
        pressed = imgui.button(label)
        imgui.end_disabled()
        self._rect(rect)
        return pressed

    def _timeline(self) -> None:
        """The timeline in one row: ← and → a kept state, a slider over the kept states' times
        (moving it pauses there); what it keeps in its tooltip."""
        v = self.viewer
        tl = v.timeline
        times = tl.times
        if imgui.arrow_button("##back", imgui.Dir.left):
            v.step_back()
        imgui.same_line()
        if imgui.arrow_button("##forward", imgui.Dir.right):
            v.step_forward()
        imgui.same_line()
        imgui.push_item_width(imgui.calc_item_width() - imgui.get_cursor_pos_x() + imgui.get_style().window_padding.x)
        now = times[-1 if tl.cursor is None else tl.cursor] if len(times) else v.sim.time
        lo, hi = (float(times[0]), float(times[-1])) if len(times) > 1 else (now, now + 1e-6)
        changed, t = imgui.slider_float("timeline", float(now), lo, hi, "%.2f s")
        self._rect("timeline", frame_only=True)  # (the slider's own width, pushed)
        imgui.pop_item_width()
        if changed and len(times):
            v.scrub(int(np.argmin(np.abs(times - t))))
        if imgui.is_item_hovered():
            imgui.set_tooltip(f"the last {hi - lo:.1f} s: {len(times)} states, {tl.memory / 2**20:.0f} MB "
                              f"(at most {tl.seconds:.0f} s, {tl.budget / 2**20:.0f} MB)\n"
                              "drag back to pause there; Space resumes from it, forgetting what came after")

    def _hold(self) -> None:
        """The grab's strength (with what it holds) and the pins, each with its × to let go."""
        v = self.viewer
        self.widget("grab_strength")
        spring = f", now {v.grab.spring(v.sim):.3g} N/m" if v.grab is not None else ""
        imgui.text_disabled(f"covers up to {100 * v.held_share():.1f} % of a small drag{spring}")
        for j, p in enumerate(v.pins):
            if imgui.small_button(f"x##pin{j}"):
                v.unpin(j)
                break
            self._rect(f"unpin {j}")
            imgui.same_line()
            imgui.text(f"pin #{p.object} ({v.sim.tree.kind[p.object]}) s = {p.s:.2f}, {p.spring(v.sim):.3g} N/m")
        if v.pins:
            if imgui.small_button("unpin all"):
                v.unpin()
        else:
            imgui.text_disabled("P or Shift + let go: pin the branch dragged")

    def _tuning_row(self) -> None:
        """Undo, Redo and Reset all (right-click a setting: that one back to its default)."""
        v = self.viewer
        if self._button("Undo", v.history.can_undo, "undo"):
            v.undo()
        imgui.same_line()
        if self._button("Redo", v.history.can_redo, "redo"):
            v.redo()
        imgui.same_line()
        if self._button("Reset all", True, "reset all"):
            v.reset_all()

    def draw(self) -> None:
        """Build the panel for this frame (between ``imgui.new_frame`` and ``imgui.render``)."""
        v = self.viewer
        sim = v.sim
        s = v.gui.scale
        ww, wh = v.window_size
        self.item_rects = {}
        imgui.set_next_window_pos(imgui.ImVec2(PANEL_GAP * s, PANEL_GAP * s), imgui.Cond_.always)
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
        key = self._text_key  # the counts change only with the tree (itself, not its id) and the season
        if key is None or key[0] is not sim.tree or key[1] != sim.season:
            st = v.stats()
            kinds = [k for k in KINDS if st[PLURAL[k]]]
            self._text = ("  ".join(f"{st[PLURAL[k]]:,} {PLURAL[k]}" for k in kinds),
                          f"{st['objects']:,} objects  {st['nodes']:,} nodes  {st['triangles']:,} tris")
            self._text_key = (sim.tree, sim.season)
        imgui.text(self._text[0])
        imgui.text(self._text[1])
        now = time.perf_counter()
        if now - self._timing_at > 0.25:  # readable, and cheaper than formatting every frame
            fps = 1.0 / v.frame_s.value if v.frame_s.value else 0.0
            rt = f"  {v.real_time.value:.2f}× real time" if v.real_time.value is not None else ""
            self._timing = f"sim {v.sim_ms.value or 0:.1f} ms  render {v.render_ms.value or 0:.1f} ms  {fps:.0f} FPS{rt}"
            self._timing_at = now
        imgui.text(self._timing)
        imgui.text_disabled(self.state_line())
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
        self.widget("season")

        # --- wind
        if self._header("Wind", open_=True):
            if SETTINGS["wind_preset"].shown(v):
                names = list(WIND_PRESETS)
                now = named_wind(v.sim.wind)  # the one the wind is now (blank: a wind of its own)
                current = names.index(now) if now is not None else -1
                changed, idx = imgui.combo("named wind", current,
                                           [f"{n} (Bf {WIND_PRESETS[n]['beaufort']})" for n in names])
                self._rect("named wind", frame_only=True)
                if changed and idx != current and 0 <= idx < len(names):
                    self.apply("wind_preset", names[idx])
            for name in WIND_SLIDERS:
                self.widget(name)

        # --- physics
        if self._header("Physics", open_=True):
            self.widget("paper_model")
            if sim.model == "paper":  # its modal ranges (the tree model's come from beam theory)
                imgui.text("ranges of")
                imgui.same_line()
                if imgui.radio_button("summer", self.edit_season == "summer"):
                    self.edit_season = "summer"
                imgui.same_line()
                if imgui.radio_button("winter", self.edit_season == "winter"):
                    self.edit_season = "winter"
                for kind in self._kinds:
                    self._range_pair(f"f:{kind}", 0.01)
                    self._range_pair(f"zeta:{kind}", 0.002)
            self.widget("ei_max")
            self.widget("physical_modes")

        # --- time
        if self._header("Simulation", open_=True):
            self.widget("time_scale")
            if sim.model == "paper":
                self.widget("integrator")
                self.widget("coupling")
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
            self._timeline()

        # --- overlays
        if self._header("Overlays", open_=True):
            self.widget("show_trace")
            imgui.same_line()
            self.widget("show_frames")
            self.widget("show_wind")

        # --- grab strength, pins
        if self._header("Grab and pins", open_=True):
            self._hold()

        # --- live plots
        if self._header("Plots"):
            w = imgui.get_content_region_avail().x
            draw_plots(v.signals, w, 0.65 * w, shown=v.sim.time if v.timeline.cursor is not None else None)

        # --- light
        if self._header("Light"):
            for name in LIGHT:
                self.widget(name)
            self.widget("draft")

        # --- preset file
        if self._header("Preset file"):
            changed, text = imgui.input_text("##path", v.preset_path)
            self._rect("path")
            if changed:
                v.preset_path = text
            if imgui.button("Save"):
                v.save_preset()
            self._rect("save")
            imgui.same_line()
            if imgui.button("Open"):  # a preset .toml or a TreeQSM model (.txt, .csv, .mat)
                v.open_file()
            self._rect("load")
            imgui.same_line()
            imgui.text_disabled("Ctrl+S / Ctrl+O")

        self._tuning_row()
        for line in v.messages[-2:]:
            if line.startswith("error"):
                imgui.push_style_color(imgui.Col_.text, imgui.ImVec4(1.0, 0.45, 0.4, 1.0))
                imgui.text_wrapped(line)
                imgui.pop_style_color()
            else:
                imgui.text_wrapped(line)
        if self._header("Controls"):
            for line in help_lines():
                imgui.push_style_color(imgui.Col_.text, imgui.get_style_color_vec4(imgui.Col_.text_disabled))
                imgui.text_wrapped(line)  # the panel is narrow: lines wrap rather than run off its edge
                imgui.pop_style_color()
        imgui.pop_item_width()
        imgui.end()
        # What the next clicks belong to (io.want_capture_mouse lags a frame behind the cursor).
        self.busy = imgui.is_any_item_active() or imgui.is_popup_open("", imgui.PopupFlags_.any_popup)

