"""The interactive viewer: a tree in wind in a window, dragged with the mouse, tuned from an
imgui panel.

:class:`Viewer` owns the simulation, the renderer, the camera and the panel of one window: a
GLFW window (:class:`~treeanim.app.window.Window`) or a headless one on EGL
(:class:`~treeanim.app.headless.HeadlessWindow`), anything of the
:class:`~treeanim.app.protocol.AppWindow` protocol. Everything it does is a plain method: its
input handlers (``on_mouse_button``, ``on_cursor_pos``, ``on_scroll``, ``on_key``, ``on_char``,
``on_resize``, ``on_focus``: :mod:`~treeanim.app.input`), which a GLFW window's callbacks call
and tests call directly; its actions (open, save, the model, the settings, the light, the
overlays, screenshots: :mod:`~treeanim.app.actions`), which the panel, the keys and scripts
call; and :meth:`Viewer.frame`, which advances the simulation by the elapsed time and draws one
frame. Beside them: the tuning tool (:mod:`~treeanim.app.tuning`), the grab's strength and
pins (:mod:`~treeanim.app.hold`), the timeline (:mod:`~treeanim.app.timeline`) and the plots'
signals (:mod:`~treeanim.app.plots`). :func:`run` is the main loop. The controls are the table
in :mod:`treeanim.app.keys`.
"""

from __future__ import annotations

import dataclasses
import time
from pathlib import Path

import numpy as np

from ..driver import MAX_FRAME_DT, FrameDriver
from ..model.scene import object_trees
from ..model.tree import Tree
from ..physics.lod import choose_detail, tree_extents
from ..physics.pull import SpringPull, TreeDrag
from ..physics.pull import grab as grab_object
from ..physics.simulation import Simulation
from ..physics.wind import WindField
from ..physics.wind import wind_preset as wind_preset_kwargs
from ..render.camera import TREE_ELEVATION, OrbitCamera, frame_tree
from ..render.overlays import LocalFrames, Markers, PullTrace, WindArrow, WindSlices
from ..render.picking import Picker
from ..render.renderer import Renderer
from ..render.scene import Scene
from .actions import ViewerActions
from .gui import Gui
from .hold import ViewerHold
from .input import ViewerInput
from .plots import Signals
from .protocol import AppWindow
from .timeline import Timeline, ViewerTimeline
from .tuning import DRAFT_SCALE, ViewerTuning
from .winddir import wind_direction

__all__ = ["Viewer", "run", "MAX_FRAME_DT"]


def _clone_wind(w: WindField | None, **changes) -> WindField:
    """A new WindField with ``w``'s settings (its bounds and automatic canopy height left to
    the next Simulation to fit)."""
    kw = {} if w is None else w.settings()
    if w is not None and not np.any(kw["direction"]):
        kw["direction"] = (1.0, 0.0, 0.0)
    kw.update(changes)
    return WindField(**kw)


class _Ema:
    """Exponential moving average (for the statistics)."""

    def __init__(self, weight: float = 0.1) -> None:
        self.w = weight
        self.value: float | None = None

    def add(self, x: float) -> None:
        self.value = x if self.value is None else self.value + self.w * (x - self.value)


class Viewer(ViewerInput, ViewerActions, ViewerTuning, ViewerHold, ViewerTimeline):
    """A tree in wind in a window: simulation, renderer, camera, mouse and keys, panel.

    Parameters
    ----------
    window : AppWindow
        An open window (its GL context current): :class:`~treeanim.app.window.Window` (GLFW) or
        :class:`~treeanim.app.headless.HeadlessWindow` (EGL, no display).
    tree : Tree
    season : float
        0 summer … 1 winter.
    wind_speed : float
        m/s at the tree top (0: calm).
    wind_angle_deg : float
        Wind direction, degrees about +y from +x.
    seed : int
        Seed of the simulation's random numbers and of the wind.
    model : {'tree', 'paper'}
        The simulation's model (kept when the tree changes; the panel switches it).
    show_panel : bool
        Show the imgui panel.
    clock : callable or None
        Seconds (monotonic); None: ``time.perf_counter``.

    Attributes
    ----------
    sim : Simulation
    renderer : Renderer
    camera : OrbitCamera
    paused : bool
    time_scale : float
        Simulated seconds per real second (0.05 … 2).
    gl_renderer : str
        The OpenGL renderer's name.
    show_trace, show_frames, show_wind : bool
        Overlays: the grabbed point's trace, the local frames, the wind slices and arrow.
    preset_path : str
        The file Save and Open use (Ctrl+S, Ctrl+O, the panel's buttons and text field); it
        follows the tree shown (``NAME-custom.toml``) until another name is set.
    messages : list of str
        The status line's last lines (newest last).
    grab : TreeDrag or SpringPull or None
        The grab in progress (:mod:`treeanim.physics.pull`): a drag solved inside the tree
        model's step, or the paper model's spring pull.
    traced : (int, float) or None
        (object, s) of the point the trace follows: the grabbed point (tree model) or the
        object's tip (s = 1; the paper's model).
    timeline : Timeline
        The last seconds of states, to scrub back through (:mod:`~treeanim.app.timeline`).
    signals : Signals
        What the panel's plots draw (:mod:`~treeanim.app.plots`).
    pins : list of TreeDrag
        The pinned drags (:mod:`~treeanim.app.hold`).
    last_sim_s, last_draw_s : float
        Wall time of the last frame's simulation sub-steps and of its drawing (pose upload,
        draw calls, panel), seconds; ``sim_ms`` and ``render_ms`` are their moving averages.
    """

    def __init__(self, window: AppWindow, tree: Tree, *, season: float = 0.0, wind_speed: float | None = None,
                 wind_angle_deg: float = 0.0, seed: int = 0, show_panel: bool = True, clock=None,
                 wind_preset: str | None = None, model: str = "tree") -> None:
        self.window = window
        self.ctx = window.ctx
        self.gl_renderer = str(window.ctx.info.get("GL_RENDERER", "unknown renderer"))
        self.seed = int(seed)
        self._clock = clock or time.perf_counter
        self.paused = False
        self.show_panel = bool(show_panel)
        self.show_trace = True
        self.show_frames = False
        self.show_wind = False
        self.grab: TreeDrag | SpringPull | None = None
        self.traced: tuple[int, float] | None = None  # (object, s) of the point the trace follows
        # the last 6 s of steps: after a release, the swing's last seconds, shrinking to a point
        # as it dies away (with 40 s the last pull's path stayed on screen until R)
        self.trace = PullTrace(capacity=360)
        self.camera = OrbitCamera(azimuth=20.0, elevation=TREE_ELEVATION)
        self.messages: list[str] = []  # lines for the panel's status line (newest last)
        self.preset_path = self._default_path = ""
        self.screenshots: list[Path] = []
        self.sim_ms, self.render_ms, self.frame_s = _Ema(), _Ema(), _Ema(0.05)
        self.real_time = _Ema(0.05)  # simulated seconds per real second (the time scale, if kept up)
        self.last_sim_s = self.last_draw_s = 0.0  # the last frame's advance() and draw(), s
        self.driver = FrameDriver()  # the clock and the step policy (docs/design.md §10)
        self._last_time: float | None = None
        self._screenshot_pending: list[Path | None] = []
        self._uploaded = None
        self._stats_key = None
        self._stats: dict = {}
        self._win = tuple(window.size)
        self._fb = tuple(window.framebuffer_size)
        self._integrator = "exact"
        self._coupling = True
        self._model = model
        self.sim: Simulation | None = None
        self.renderer: Renderer | None = None
        self.scene = Scene()  # sun, shadows and leaves' translucency, kept across trees
        self._init_tuning()  # undo history, defaults, camera bookmarks, draft mode (tuning.py)
        self._init_hold()  # the grab's strength, pins (hold.py)
        self.timeline = Timeline()
        self._draft_target = None
        named = wind_preset_kwargs(wind_preset) if wind_preset else {}
        if wind_speed is not None:
            named["speed"] = float(wind_speed)
        named.setdefault("speed", 5.0)
        self._wind = _clone_wind(None, direction=wind_direction(wind_angle_deg), seed=self.seed, **named)
        self._season = float(season)
        self.gui = Gui(window, scale=window.content_scale)
        try:
            from .panel import Panel

            self.panel = Panel(self)
            self.load_tree(tree)
        except BaseException:  # e.g. a ValueError from the Simulation: free the Gui (and any renderer)
            self.release()
            raise

    # ------------------------------------------------------------------ the tree
    @property
    def tree(self) -> Tree:
        return self.sim.tree

    @property
    def wind(self) -> WindField:
        """The wind field (also when calm: speed 0)."""
        return self.sim.wind

    def load_tree(self, tree: Tree) -> None:
        """Show ``tree``: a new simulation (same wind, season and model, and the paper model's
        integrator and coupling), renderer and picker; the camera frames it."""
        if self.sim is not None:
            self._season = self.sim.season
            self._model = self.sim.model
            if self._model == "paper":
                self._integrator = self.sim.integrator
                self._coupling = self.sim.coupling
            self._wind = self.sim.wind
        self._end_drag()
        sim = Simulation(tree, wind=_clone_wind(self._wind), season=self._season, seed=self.seed, model=self._model,
                         integrator=self._integrator, coupling=self._coupling)
        self.window.make_current()
        renderer = Renderer(self.ctx, tree, scene=self.scene)
        if self.renderer is not None:
            self.renderer.release()
        self.sim, self.renderer = sim, renderer
        self.picker = Picker(tree)
        self._extents = tree_extents(tree) if getattr(tree, "n_trees", 1) > 1 else None  # a scene's (lod)
        self.signals = Signals(tree)
        self._restarted()
        lo, hi = renderer.bounds()
        self.local_frames = LocalFrames(scale=0.25)
        size = float(np.max(hi - lo))
        self.wind_slices = WindSlices(self._wind_at, (lo, hi), resolution=9, reference_speed=None)
        self.wind_arrow = WindArrow(length=0.35 * size, reference_speed=10.0)
        self.pin_markers = Markers(size=0.04 * size)
        self._wind_arrow_anchor = (0.5 * (lo + hi), 0.65 * size)
        self._follow_file_name()
        self.frame_camera()
        self.note_defaults(fresh=True)
        self.panel.tree_changed()

    def _wind_at(self, points: np.ndarray) -> np.ndarray:
        return self.sim.wind.sample(points, self.sim.time)

    # ------------------------------------------------------------------ sizes
    @property
    def window_size(self) -> tuple[int, int]:
        """The window's size in screen units as the viewer last heard of it (its handlers:
        ``on_window_size``, ``on_resize``)."""
        return self._win

    @property
    def framebuffer_size(self) -> tuple[int, int]:
        """The framebuffer's size in pixels as the viewer last heard of it (0 × 0: minimised;
        at most the GL's largest size)."""
        return self._fb

    # ------------------------------------------------------------------ camera
    def frame_camera(self) -> None:
        """Frame the tree beside the panel (:func:`~treeanim.render.camera.frame_tree`, the
        offline commands' framing): the orbit then pivots on the tree's centre."""
        w, h = self._win
        if w <= 0 or h <= 0:
            w, h = 16, 9
        left = self.panel.right if self.show_panel else 0.0
        frame_tree(self.camera, self.tree, w, h, present=self.sim.shown, left=min(left, 0.6 * w))

    # ------------------------------------------------------------------ time
    @property
    def time_scale(self) -> float:
        """Simulated seconds per real second (the frame driver's)."""
        return self.driver.time_scale

    @time_scale.setter
    def time_scale(self, value: float) -> None:
        self.driver.time_scale = float(value)

    @property
    def substep(self) -> float:
        """The simulation's fixed step (s): the frame driver's, 1/60 × the time scale, at most
        1/60 (one step a frame at 60 frames a second at any slow-motion scale)."""
        return self.driver.step

    def advance(self, real_dt: float) -> int:
        """Advance the simulation by ``real_dt`` seconds of real time (the frame driver's
        :meth:`~treeanim.driver.FrameDriver.advance`, the grab acting before every step and
        the trace following the grabbed point). Returns the steps taken."""
        if self.paused:
            return 0
        self.choose_detail()
        n = self.driver.advance(self.sim, real_dt, self.grab, self._after_step)
        if n:
            self.sim.positions, self.sim.rotations  # the pose is built lazily: count it as simulation
        return n

    def choose_detail(self) -> None:
        """A scene's trees at the detail their height on the screen asks for
        (:func:`~treeanim.physics.lod.choose_detail`), the trees grabbed, traced or pinned at
        full detail (the tree model; a tree holding a drag is whole anyway)."""
        if self._extents is None or self.sim.model != "tree":
            return
        held = [p.object for p in self.pins] + ([self.grab.object] if self.grab is not None else [])
        held += [self.traced[0]] if self.traced is not None else []
        focal = max(self._fb[1], 1) / (2.0 * np.tan(np.radians(self.camera.fov_y) / 2.0))
        hero = object_trees(self.tree)[np.asarray(held, np.int64)]
        self.sim.set_detail(choose_detail(self.camera.eye, *self._extents, focal, hero, self.sim.detail))

    def _steps(self, n: int) -> None:
        """Take ``n`` steps now (paused or not), as :meth:`advance` takes them."""
        for j in range(n):
            if self.grab is not None:
                self.grab.step(self.sim, self.substep, exact=j == 0)
            self.sim.step(self.substep)
            self._after_step()

    def _after_step(self) -> None:
        """After every step: the trace follows the grabbed point, the timeline and the plots'
        signals record."""
        at = None
        if self.traced is not None:
            at = self.traced_point()
            self.trace.push(at)
        self.timeline.record(self.sim)
        self.signals.record(self.sim, self.traced, at)

    def _restarted(self) -> None:
        """The simulation starts again (a new tree or model, a reset): no trace, pins,
        timeline or signals; nothing due."""
        self.trace.clear()
        self.traced = None
        self.pins = []
        self.timeline.clear()
        self.signals.clear()
        self.driver.reset()

    # ------------------------------------------------------------------ frames
    def frame(self, dt: float | None = None) -> bool:
        """Advance and draw one frame (not swapped). ``dt``: real seconds since the last frame
        (None: measured). Returns False when nothing was drawn (a minimised window)."""
        now = self._clock()
        if dt is None:
            dt = 0.0 if self._last_time is None else now - self._last_time
        self._last_time = now
        w, h = self._fb
        if w <= 0 or h <= 0 or self.window.framebuffer is None:  # minimised (the window knows first)
            return False
        self.window.make_current()
        t0 = time.perf_counter()
        before = self.sim.time
        self.advance(dt)
        t1 = time.perf_counter()
        if dt > 0 and not self.paused:
            self.real_time.add((self.sim.time - before) / dt)
        self.draw(dt)
        t2 = time.perf_counter()
        self.last_sim_s, self.last_draw_s = t1 - t0, t2 - t1
        self.sim_ms.add(1e3 * (t1 - t0))
        self.render_ms.add(1e3 * (t2 - t1))
        if dt > 0:
            self.frame_s.add(dt)
        while self._screenshot_pending:
            self.screenshot(self._screenshot_pending.pop(0))
        return True

    def draw(self, dt: float = 1 / 60) -> None:
        """Upload the pose and draw the scene and the panel into the window's back buffer."""
        fw, fh = self._fb
        if fw <= 0 or fh <= 0:
            return
        sim, r = self.sim, self.renderer
        highlight = self.grab.object if self.grab is not None else None
        pos = sim.positions
        key = (id(r), id(pos), sim.time, id(sim.shown), highlight)
        if key != self._uploaded:  # the pose is unchanged while paused or between steps
            r.update(pos, sim.rotations, present=sim.shown, highlight=highlight, wind=sim.wind, time=sim.time)
            self._uploaded = key
        target = self.window.framebuffer
        if target is None:  # minimised since the viewer last heard of the size
            return
        if self.draft:  # no shadows, a smaller picture without MSAA, scaled up (tuning.py)
            from .draft import DraftTarget

            r.scene = dataclasses.replace(self.scene, shadow=False)
            self._draft_target = self._draft_target or DraftTarget(self.ctx)
            self._draft_target.draw(r, self.camera, fw, fh, DRAFT_SCALE, target, season=sim.season,
                                    overlays=self.overlays())
        else:
            r.scene = self.scene
            target.use()
            r.draw(self.camera, fw, fh, season=sim.season, overlays=self.overlays())
        if self.show_panel:
            ww, wh = self._win
            self.gui.new_frame(ww, wh, fw, fh, dt if dt > 0 else 1 / 60)
            self.panel.draw()
            self.gui.render()

    def overlays(self) -> list:
        """The overlays switched on."""
        out = []
        if self.show_trace and len(self.trace) > 1:
            out.append(self.trace)
        if self.pins:
            self.pin_markers.points = self.pinned_points()
            out.append(self.pin_markers)
        if self.show_frames:
            out.append(self.local_frames)
        if self.show_wind and not self.sim.wind.calm:
            w = self.sim.wind
            a = self.wind_arrow
            a.direction = w.direction
            a.speed = w.speed
            centre, dist = self._wind_arrow_anchor
            d = w.direction / max(np.linalg.norm(w.direction), 1e-12)
            a.origin = centre - dist * d
            out += [self.wind_slices, a]
        return out

    def stats(self) -> dict:
        """The tree's counts at the current season (cached)."""
        key = self._stats_key
        if key is None or key[0] is not self.sim.tree or key[1] != self.sim.season:
            # (the key holds the tree itself: a freed tree's id() may come back as a new tree's)
            self._stats = self.sim.tree.stats(self.sim.season)
            self._stats_key = (self.sim.tree, self.sim.season)
        return self._stats

    # ------------------------------------------------------------------ pixels
    def read_pixels(self) -> np.ndarray:
        """The frame as drawn so far, (height, width, 3) uint8, row 0 at the top
        (:meth:`AppWindow.read_pixels <treeanim.app.protocol.AppWindow.read_pixels>`)."""
        return self.window.read_pixels(*self._fb)

    # ------------------------------------------------------------------ picking and grabbing
    def _ray(self, x: float, y: float):
        w, h = self._win
        return self.camera.ray(x, y, max(w, 1), max(h, 1))

    def pick(self, x: float, y: float):
        """The object under window point (x, y) (screen units, y down), or None."""
        o, d = self._ray(x, y)
        h = max(self._win[1], 1)
        thin = self.scene.thin_pixels * h / (self._fb[1] or h)  # framebuffer pixels, in screen units
        return self.picker.pick(self.sim.positions, self.sim.rotations, o, d, present=self.sim.present,
                                pixel_angle=self.camera.pixel_angle(h), min_pixels=4.0, thin_pixels=thin)

    def start_pull(self, x: float, y: float) -> bool:
        """Grab the object under (x, y), if any: on the tree model a drag of the point of the
        object nearest the picked one (:class:`~treeanim.physics.pull.TreeDrag`, through
        :meth:`Simulation.drag`), on the paper's a spring pull
        (:class:`~treeanim.physics.pull.SpringPull`). Returns whether something was grabbed."""
        hit = self.pick(x, y)
        if hit is None:
            return False
        self._take_pin(hit.object)
        self.grab = grab_object(self.sim, hit.object, hit.point, self.camera.forward, self.grab_strength)
        self.trace.clear()
        self.traced = (hit.object, self.grab.s if isinstance(self.grab, TreeDrag) else 1.0)
        self.trace.push(self.traced_point())
        return True

    def traced_point(self) -> np.ndarray:
        """The point the trace follows (world): on the tree model the grabbed point of the
        object (:meth:`Simulation.point_position`, no whole pose), on the paper's its tip."""
        obj, s = self.traced
        if self.sim.model == "tree":
            return self.sim.point_position(obj, s)
        return self.sim.tip_position(obj)

    def anchor_point(self) -> np.ndarray | None:
        """Where the grabbed point is now (world), or None."""
        return None if self.grab is None else self.grab.anchor(self.sim)

    def _grabbed_point(self, exact: bool) -> np.ndarray:
        """The grabbed point: a drag's from the tree model's bodies; a spring pull's exact on a
        frame's first sub-step (whose pose the last frame drew, so it is built already), else
        followed through the tip (:meth:`SpringPull.grabbed_point`)."""
        return self.grab.grabbed_point(self.sim, exact)

    def end_pull(self) -> None:
        """Let go of the grabbed object (it swings freely; the trace goes on)."""
        if self.grab is not None:
            self.grab.release(self.sim)
            self.grab = None

    # ------------------------------------------------------------------ actions (the rest: actions.py)
    def reset(self) -> None:
        """Back to rest: the simulation at time 0, no grab, pins, trace or timeline."""
        self._end_drag()
        self.sim.reset()
        self._restarted()

    def release(self) -> None:
        """Free the GL resources (the window stays open)."""
        self.window.make_current()
        self.window.release_readback()
        if self.renderer is not None:
            self.renderer.release()
            self.renderer = None
        if self._draft_target is not None:
            self._draft_target.release()
            self._draft_target = None
        self.gui.release()


def run(viewer: Viewer, max_frames: int | None = None) -> int:
    """The main loop: poll input, advance and draw, swap; until the window closes (or
    ``max_frames`` frames have been drawn). Returns the number of frames drawn."""
    win = viewer.window
    win.connect(viewer)
    drawn = 0
    while not win.should_close:
        w, h = viewer._fb
        if w <= 0 or h <= 0:  # minimised: sleep until something happens
            win.wait(0.1)
            viewer._last_time = None
            viewer.on_resize(*win.framebuffer_size)
            continue
        win.poll()
        if viewer.frame():
            win.swap()
            drawn += 1
        if max_frames is not None and drawn >= max_frames:
            break
    return drawn
