"""The viewer as a tuning tool, headless (issue 31): a setting back to its default (an action,
a right-click in the panel, Reset all), undo and redo of setting changes (the panel's apply,
a slider's drag as one step, Ctrl+Z / Ctrl+Y / Ctrl+Shift+Z, refusals as the actions refuse),
camera bookmarks (Ctrl+1–4 store, 1–4 recall, kept across trees) and draft mode (D, the panel:
half resolution, no MSAA, no shadows, said in the status line)."""

from __future__ import annotations

import glfw
import numpy as np
import pytest

from app_helpers import DT, H, W, centre, click, reveal

CTRL, SHIFT = glfw.MOD_CONTROL, glfw.MOD_SHIFT


pytestmark = pytest.mark.usefixtures("no_display")  # the app fixtures: tests/conftest.py


def key(v, k, mods=0):
    v.on_key(k, 0, glfw.PRESS, mods)
    v.on_key(k, 0, glfw.RELEASE, mods)


# ---------------------------------------------------------------------------- defaults
def test_reset_setting_returns_to_what_the_tree_loaded_with(viewer):
    v = viewer
    ei = float(v.sim.tree.physics.ei_max)
    assert v.panel.apply("ei_max", 2 * ei) and v.panel.apply("wind_speed", 7.0) and v.panel.apply("season", 0.4)
    assert not v.is_default("ei_max")
    assert v.reset_setting("ei_max")
    assert v.sim.physics.ei_max == pytest.approx(ei) and v.is_default("ei_max")
    assert v.sim.wind.speed == 7.0  # the others stay
    assert v.reset_all() == 2
    assert (v.sim.wind.speed, v.sim.season) == (0.0, 0.0)
    assert not v.reset_setting("nonsense") and v.messages[-1].startswith("error")
    # a new tree: its values are the defaults now
    v.panel.apply("wind_speed", 3.0)
    v.open_preset("small_cherry")
    v.panel.apply("wind_speed", 9.0)
    v.reset_setting("wind_speed")
    assert v.sim.wind.speed == 3.0


def test_reset_all_is_one_step_and_covers_the_papers_ranges(viewer):
    v = viewer
    assert v.panel.apply("paper_model", True)
    f = v.mode_range("branch", "f")
    assert v.panel.apply("f:branch", (f[0] * 1.5, f[1] * 1.5)) and v.panel.apply("integrator", "euler")
    assert v.panel.apply("sun_elevation", 20.0)
    steps = len(v.history.done)
    v.reset_all()
    assert len(v.history.done) == steps + 1
    assert v.sim.model == "tree" and v.mode_range("branch", "f") == pytest.approx(f)
    assert v.sun_angles[1] == pytest.approx(v.default_of("sun_elevation"))
    assert v.undo()  # all of it comes back at once
    assert v.sim.model == "paper" and v.sim.integrator == "euler" and v.sun_angles[1] == pytest.approx(20.0)
    assert v.mode_range("branch", "f") == pytest.approx((f[0] * 1.5, f[1] * 1.5))


def test_right_click_on_a_slider_resets_it(viewer):
    v = viewer
    v.show_panel = True
    v.panel.apply("wind_speed", 12.0)
    v.frame(DT)
    v.frame(DT)
    click(v, *centre(v.panel.item_rects["speed"]), glfw.MOUSE_BUTTON_RIGHT)
    assert v.sim.wind.speed == 0.0
    assert v._mode is None


# ---------------------------------------------------------------------------- undo and redo
def test_undo_and_redo_go_through_the_actions(viewer):
    v = viewer
    v.panel.apply("season", 0.3)
    v.panel.apply("season", 0.6)
    v.panel.apply("shadows", False)
    key(v, glfw.KEY_Z, CTRL)
    assert v.scene.shadow
    key(v, glfw.KEY_Z, CTRL)
    assert v.sim.season == pytest.approx(0.3)
    key(v, glfw.KEY_Z, CTRL | SHIFT)
    assert v.sim.season == pytest.approx(0.6)
    key(v, glfw.KEY_Y, CTRL)
    assert not v.scene.shadow
    assert not v.redo() and v.messages[-1] == "nothing to redo"
    v.undo()
    v.panel.apply("wind_speed", 4.0)  # a new change forgets what was undone
    assert not v.history.can_redo
    assert v.undo() and v.undo() and v.undo()
    assert v.sim.season == 0.0 and v.sim.wind.speed == 0.0
    assert not v.undo() and v.messages[-1] == "nothing to undo"
    # a refused value (nothing changed), an unknown setting: nothing recorded
    assert not v.panel.apply("season", 2.0) and not v.panel.apply("nonsense", 1)
    assert not v.history.can_undo


def test_an_undo_refused_now_is_said_and_kept(viewer):
    v = viewer
    v.panel.apply("paper_model", True)
    v.panel.apply("integrator", "euler")
    v.set_model("tree")  # not through a setting: not recorded
    assert not v.undo()
    assert v.messages[-1].startswith("error: integrator")
    assert len(v.history.done) == 2 and not v.history.can_redo
    v.set_model("paper")
    assert v.undo() and v.sim.integrator == "exact"


def test_a_slider_drag_is_one_step(viewer):
    v = viewer
    v.show_panel = True
    v.frame(DT)
    v.frame(DT)
    x0, y0, x1, y1 = v.panel.item_rects["season"]
    y = 0.5 * (y0 + y1)
    v.on_cursor_pos(x0 + 0.1 * (x1 - x0), y)
    v.frame(DT)
    v.on_mouse_button(glfw.MOUSE_BUTTON_LEFT, glfw.PRESS, 0)
    v.frame(DT)
    seen = set()
    for f in (0.3, 0.5, 0.7, 0.9):
        v.on_cursor_pos(x0 + f * (x1 - x0), y)
        v.frame(DT)
        seen.add(round(v.sim.season, 3))
    v.on_mouse_button(glfw.MOUSE_BUTTON_LEFT, glfw.RELEASE, 0)
    v.frame(DT)
    assert len(seen) >= 3  # the season followed the drag, frame by frame
    assert len(v.history.done) == 1
    (change,) = v.history.done[0]
    assert change.name == "season" and change.old == 0.0 and change.new == v.sim.season > 0.5
    assert v.undo() and v.sim.season == 0.0
    # a second drag of the same slider is a step of its own
    v.on_cursor_pos(x0 + 0.2 * (x1 - x0), y)
    v.frame(DT)
    v.on_mouse_button(glfw.MOUSE_BUTTON_LEFT, glfw.PRESS, 0)
    v.frame(DT)
    v.on_mouse_button(glfw.MOUSE_BUTTON_LEFT, glfw.RELEASE, 0)
    v.frame(DT)
    v.panel.apply("season", 0.9)
    assert len(v.history.done) == 2


def test_the_panels_undo_button(viewer):
    v = viewer
    v.show_panel = True
    v.panel.apply("wind_speed", 6.0)
    v.frame(DT)
    click(v, *reveal(v, "undo"))  # (at the panel's foot, by the status line)
    assert v.sim.wind.speed == 0.0 and v.history.can_redo
    click(v, *reveal(v, "redo"))
    assert v.sim.wind.speed == 6.0


# ---------------------------------------------------------------------------- bookmarks
def test_camera_bookmarks_store_recall_and_outlive_the_tree(viewer):
    v = viewer
    c = v.camera
    key(v, glfw.KEY_2, CTRL)
    saved = (c.azimuth, c.elevation, c.distance, c.target.copy())
    c.orbit(40.0, 15.0)
    c.zoom(0.5)
    c.pan(30.0, 10.0, H)
    v.open_preset("small_cherry")  # a new tree reframes the camera; the bookmark stays
    key(v, glfw.KEY_2)
    assert (c.azimuth, c.elevation, c.distance) == pytest.approx(saved[:3])
    assert np.allclose(c.target, saved[3])
    assert not v.recall_bookmark(3) and "Ctrl+3" in v.messages[-1]
    with pytest.raises(ValueError):
        v.store_bookmark(5)
    c.orbit(10.0, 0.0)
    key(v, glfw.KEY_2)
    assert c.azimuth == pytest.approx(saved[0])
    v.frame(DT)
    assert v.ctx.error == "GL_NO_ERROR"


# ---------------------------------------------------------------------------- draft mode
def test_draft_mode_draws_smaller_without_shadows_and_says_so(viewer):
    v = viewer
    assert "DRAFT" not in v.panel.state_line()
    full = v.read_pixels().astype(float)
    key(v, glfw.KEY_D)
    assert v.draft and "DRAFT" in v.panel.state_line()
    v.frame(DT)
    assert v.ctx.error == "GL_NO_ERROR"
    assert v._draft_target.size == (W // 2, H // 2)
    assert not v.renderer.scene.shadow and v.scene.shadow  # the setting is kept
    draft = v.read_pixels().astype(float)
    assert draft.shape == full.shape
    assert 0 < np.abs(draft - full).mean() < 40  # the same view, coarser and without shadows
    assert v.panel.apply("draft", False) and not v.draft
    assert not v.history.can_undo  # draft mode is not a setting to undo
    v.frame(DT)
    assert v.renderer.scene is v.scene
    assert np.abs(v.read_pixels().astype(float) - full).mean() < 1.0
