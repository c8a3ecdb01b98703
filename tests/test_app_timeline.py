"""The timeline and the live plots, headless (issue 31): scrubbing back puts an earlier state
back exactly (the slider, ← and →), resuming continues from it as the first run did and forgets
what came after; the plots' data (the spectra of the trunk top's sway and of the wind) peak where
the motion does, and the panel draws them with ImPlot."""

from __future__ import annotations

import glfw
import numpy as np
import pytest

from app_helpers import DT, branch_on_screen, centre, click, drag_and_let_go, press, reveal
from treeanim.app.plots import spectrum
from treeanim.app.timeline import Timeline

pytestmark = pytest.mark.usefixtures("no_display")  # the app fixtures: tests/conftest.py


def swing(v, steps):
    """Drag a branch across and let go; then ``steps`` steps: the poses after each, by time."""
    drag_and_let_go(v, 30, 10, 30)
    poses = {}
    for _ in range(steps):
        v.advance(DT)
        poses[v.sim.time] = v.sim.positions.copy()
    return poses


def test_scrubbing_back_restores_a_state_exactly_and_resuming_continues_from_it(viewer):
    v = viewer
    v.set_wind(speed=6.0)  # the wind is a function of time: a run from a state repeats
    poses = swing(v, 60)
    times = sorted(poses)
    assert len(v.timeline) >= 90 and v.timeline.interval < DT  # every step kept
    # the panel's slider: moved back, it pauses and shows the state kept then
    v.show_panel = True
    v.frame(DT)
    reveal(v, "timeline")
    click(v, *centre(v.panel.item_rects["timeline"]))  # the middle of the slider: half way back
    assert v.paused and v.timeline.cursor is not None
    t = v.sim.time
    assert t in poses and t < times[-1] - 0.2
    np.testing.assert_array_equal(v.sim.positions, poses[t])
    # ← and →: a kept state back and forth, exactly
    v.show_panel = False
    v.on_key(glfw.KEY_LEFT, 0, glfw.PRESS, 0)
    earlier = times[times.index(t) - 1]
    assert v.sim.time == earlier
    np.testing.assert_array_equal(v.sim.positions, poses[earlier])
    v.on_key(glfw.KEY_RIGHT, 0, glfw.PRESS, 0)
    assert v.sim.time == t
    # resume: the states after it are forgotten, and the run goes on as it went the first time
    v.on_key(glfw.KEY_SPACE, 0, glfw.PRESS, 0)
    assert not v.paused and v.timeline.times[-1] == t and len(v.signals) and v.signals.window()[0][-1] == t
    for _ in range(12):
        v.advance(DT)
    assert v.sim.time == pytest.approx(times[times.index(t) + 12], abs=1e-9)
    np.testing.assert_allclose(v.sim.positions, poses[times[times.index(t) + 12]], atol=1e-9)
    # → at the newest takes a step; a reset forgets the timeline
    n = len(v.timeline)
    assert v.step_forward() and v.paused and len(v.timeline) == n + 1
    v.reset()
    assert len(v.timeline) == 0 and not v.step_back()


def test_the_timeline_keeps_its_seconds_within_its_budget(viewer):
    v = viewer
    one = v.timeline.memory // max(len(v.timeline), 1)
    assert one > 0
    tl = Timeline(seconds=1.0, budget=10 * one)  # room for 10 states over 1 s: one each 0.1 s
    for _ in range(90):
        v.advance(DT)
        tl.record(v.sim)
    assert tl.interval == pytest.approx(0.1)
    assert len(tl) <= 11 and tl.memory <= 11 * one
    assert tl.times[-1] - tl.times[0] <= 1.0 + 1e-9 and 0 <= v.sim.time - tl.times[-1] < 0.1


def test_spectrum_of_a_sine_peaks_at_its_frequency_with_its_power():
    t = np.arange(0.0, 20.0, 1 / 60)
    x = 0.3 * np.sin(2 * np.pi * 1.3 * t) + 0.1
    f, p = spectrum(t, x)
    assert abs(f[np.argmax(p)] - 1.3) <= f[1] - f[0]
    df = f[1] - f[0]
    assert p.sum() * df == pytest.approx(0.3**2 / 2, rel=0.05)  # the variance, as a power density


def test_the_sway_spectrum_peaks_at_the_trunks_motion_and_the_panel_plots_it(viewer):
    v = viewer
    top = v.sim.point_position(0, 1.0)
    hz = 0.8  # the trunk top led round a 3 cm circle, 0.8 turns a second (a known motion)
    for _ in range(1200):
        w = 2 * np.pi * hz * v.sim.time
        v.sim.drag(0, top + 0.03 * np.array([np.cos(w), 0.0, np.sin(w)]))
        v.advance(DT)
    sp = v.signals.spectra()
    f, p = sp["sway"]
    assert len(f) > 100 and f[np.argmax(p)] == pytest.approx(hz, abs=f[1] - f[0])
    assert np.all(sp["wind"][1] == 0) and not len(sp["grabbed"][0])  # still air, nothing grabbed
    # a branch grabbed and shaken by the mouse, 1.2 times a second: its spectrum peaks there
    v.sim.release()
    obj, x, y = branch_on_screen(v)
    press(v, x, y)
    t0 = v.sim.time
    for _ in range(600):
        v.on_cursor_pos(x + 8 * np.sin(2 * np.pi * 1.2 * (v.sim.time - t0)), y)
        v.advance(DT)
    f, p = v.signals.spectra(now=1e9)["grabbed"]
    assert f[np.argmax(p)] == pytest.approx(1.2, abs=f[1] - f[0])
    # the panel draws the plots (open their section): the trace and the spectra
    v.set_wind(speed=8.0)
    for _ in range(120):
        v.advance(DT)
    wind_f, wind_p = v.signals.spectra(now=2e9)["wind"]  # (a second later: worked out again)
    assert wind_p.max() > 0 and np.all(np.isfinite(wind_p))
    v.show_panel = True
    v.frame(DT)
    before = v.read_pixels()
    click(v, *reveal(v, "Plots"))
    for _ in range(3):
        v.frame(DT)
    assert v.ctx.error == "GL_NO_ERROR"
    x0, y0, x1, y1 = (int(c) for c in v.panel.rect)
    drawn = np.abs(v.read_pixels().astype(int) - before.astype(int)).max(axis=2) > 24
    assert drawn[y0:y1, x0:x1].mean() > 0.05
