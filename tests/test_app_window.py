"""The viewer in a real GLFW window (under Xvfb through pytest-xvfb): what only a window system
shows. A window draws the tree and the panel; the X server's resizes, full screen and a window
wider than the GL can draw reach the viewer through GLFW's callbacks; real X input through
xdotool; the ``view`` command; and the one-line failures without a display, without OpenGL 3.3
or with a tree the simulation refuses. Everything else about the app runs headless, with no
display: tests/test_app.py."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import time

import glfw
import pytest

import treeanim as ta
from app_helpers import DT, H, W, check_tree_and_panel, open_viewer, unsimulable
from treeanim.app import window as window_module
from treeanim.app.viewer import Viewer, run
from treeanim.app.window import Window


@pytest.fixture()
def viewer():
    """A viewer of its own for each test (a window and a viewer open in a fraction of a second):
    the small cherry at rest, calm, the tree model, panel hidden, 480 × 360, framed, one frame
    drawn."""
    win = Window.open(W, H, "treeanim test", samples=4)  # 4x MSAA: screenshots resolve it
    yield from open_viewer(win, ta.load_preset("small_cherry"), ready=lambda v: _settle(v, (W, H)))


def _settle(v, size):
    """Poll until the X server's resize reached the viewer through the GLFW callbacks (waiting
    on the X server, another process: at most 200 polls of 5 ms)."""
    for _ in range(200):
        glfw.poll_events()
        if v.framebuffer_size == size and v.window_size == size:
            return
        glfw.wait_events_timeout(0.005)
    raise AssertionError(f"the window never became {size}: framebuffer {v.framebuffer_size}, window {v.window_size}")


# ---------------------------------------------------------------------------- drawing
def test_window_draws_the_tree_and_the_panel(viewer):
    check_tree_and_panel(viewer, (0, 4))  # pytest-xvfb's 16-bit screen has no multisampled visual


# ---------------------------------------------------------------------------- window states
def test_a_window_wider_than_the_gl_can_draw_is_brought_back(viewer, tmp_path):
    v = viewer
    most = v.window.max_pixels
    assert 1024 <= most <= 32768
    glfw.set_window_size(v.window.handle, most + 700, 200)  # no window manager under Xvfb to stop it
    for _ in range(200):  # waiting on the X server, as _settle does
        glfw.poll_events()
        if v.window.size[0] <= most and v.framebuffer_size[0] <= most and v.framebuffer_size[1] == 200:
            break
        glfw.wait_events_timeout(0.005)
    assert v.framebuffer_size[0] <= most and v.window.size[0] <= most, (v.framebuffer_size, v.window.size)
    assert v.frame(DT)
    shot = v.screenshot(tmp_path / "wide.png")
    assert iio_shape(shot)[1] <= most
    assert v.ctx.error == "GL_NO_ERROR"


def iio_shape(path):
    import imageio.v3 as iio

    return iio.imread(path).shape


def test_resize_to_odd_sizes_and_minimise(viewer):
    v = viewer
    for w, h in ((333, 211), (1, 1), (97, 401), (W, H)):
        glfw.set_window_size(v.window.handle, w, h)
        _settle(v, (w, h))
        fw, fh = v.window.framebuffer_size
        assert v.framebuffer_size == (fw, fh), "the framebuffer-size callback reached the viewer"
        v.show_panel = (w, h) != (1, 1)
        assert v.frame(DT)
        assert v.read_pixels().shape == (fh, fw, 3)
        assert v.ctx.error == "GL_NO_ERROR"
    v.on_key(glfw.KEY_F11, 0, glfw.PRESS, 0)  # full screen: the whole (virtual) monitor
    mode = glfw.get_video_mode(glfw.get_primary_monitor())
    _settle(v, (mode.size.width, mode.size.height))
    assert v.window.fullscreen and v.frame(DT)
    v.on_key(glfw.KEY_F11, 0, glfw.PRESS, 0)
    _settle(v, (W, H))
    assert not v.window.fullscreen and v.frame(DT)
    v.on_resize(0, 0)  # minimised
    assert not v.frame(DT)
    assert v.read_pixels().shape == (0, 0, 3)
    v.on_key(glfw.KEY_S, 0, glfw.PRESS, 0)  # a screenshot waits for a drawn frame
    assert not v.frame(DT)
    v._screenshot_pending.clear()
    v.on_resize(*v.window.framebuffer_size)
    assert v.frame(DT)
    assert v.ctx.error == "GL_NO_ERROR"


def test_view_refuses_a_tree_the_simulation_refuses_in_one_line():
    from treeanim.app.main import view

    open_before = len(window_module._open_windows)
    with pytest.raises(ValueError) as err:
        view(unsimulable(), size=(160, 120), frames=1)
    msg = str(err.value)
    assert "\n" not in msg and msg.startswith("cannot show beam:") and "no f/zeta range" in msg
    with pytest.raises(ValueError, match="speed"):
        view(ta.load_preset("beam"), size=(160, 120), frames=1, wind_speed=1e9)
    assert len(window_module._open_windows) == open_before, "the window was closed again"


# ---------------------------------------------------------------------------- real X input
def _xdotool(*args) -> str:
    exe = shutil.which("xdotool")
    if exe is None:
        pytest.fail("xdotool is not installed: run scripts/test, which installs it (Debian package xdotool)")
    res = subprocess.run([exe, *map(str, args)], capture_output=True, text=True, timeout=30)
    assert res.returncode == 0, f"xdotool {' '.join(map(str, args))} failed: {res.stderr.strip()}"
    return res.stdout


def _pump_until(v, done, what, timeout=10.0):
    """Run the viewer's own main loop (GLFW polling, the callbacks of Window.connect) a frame
    at a time until ``done()``: the X server delivers xdotool's events asynchronously. A poll
    with a timeout, as it waits on other processes (xdotool, the X server); the timeout is
    only how long to wait before failing, never something measured."""
    end = time.monotonic() + timeout
    while True:
        assert run(v, max_frames=1) == 1
        if done():
            return
        if time.monotonic() > end:
            raise AssertionError(f"{what}: the X event never reached the viewer")
        glfw.wait_events_timeout(0.02)


def test_real_x_input_orbits_zooms_and_presses_keys(viewer, tmp_path, monkeypatch):
    """The window driven through the X server (xdotool's XTEST input), not by calling the
    handlers: the pointer moves onto it, a left-drag on the sky orbits, the wheel zooms, 'h'
    shows the panel and 's' writes a screenshot, all through GLFW and Window.connect."""
    monkeypatch.chdir(tmp_path)
    v = viewer
    title = f"treeanim xdotool {os.getpid()}"
    glfw.set_window_title(v.window.handle, title)
    _pump_until(v, lambda: True, "a first frame")
    ids = _xdotool("search", "--sync", "--onlyvisible", "--name", f"^{re.escape(title)}$").split()
    assert len(ids) == 1, f"windows named {title!r}: {ids}"
    wid = ids[0]
    _xdotool("windowraise", wid)
    _xdotool("windowfocus", "--sync", wid)
    geometry = _xdotool("getwindowgeometry", "--shell", wid)
    g = dict(line.split("=", 1) for line in geometry.split())
    assert (int(g["WIDTH"]), int(g["HEIGHT"])) == (W, H), geometry
    x, y = W - 10, 10  # empty sky, away from the tree
    assert v.pick(x, y) is None
    _xdotool("mousemove", "--window", wid, "--sync", x, y)
    _pump_until(v, lambda: v._cursor == (x, y), "pointer motion")
    az, el, d = v.camera.azimuth, v.camera.elevation, v.camera.distance
    _xdotool("mousedown", 1)
    _pump_until(v, lambda: v._mode == "orbit", "left button press")
    assert v.grab is None
    _xdotool("mousemove", "--window", wid, "--sync", x - 40, y + 20)
    _pump_until(v, lambda: v._cursor == (x - 40, y + 20), "drag")
    _xdotool("mouseup", 1)
    _pump_until(v, lambda: v._mode is None, "left button release")
    assert (v.camera.azimuth - az) % 360 == pytest.approx(14.0)
    assert v.camera.elevation == pytest.approx(el + 7.0)
    _xdotool("click", 4)  # wheel up: zoom in one notch
    _pump_until(v, lambda: v.camera.distance != d, "wheel")
    assert v.camera.distance == pytest.approx(d * 0.88)
    assert not v.show_panel
    _xdotool("key", "h")
    _pump_until(v, lambda: v.show_panel, "key h")
    _xdotool("key", "s")
    _pump_until(v, lambda: list(tmp_path.glob("treeanim-*.png")), "key s")
    assert v.screenshots and v.screenshots[-1].name.startswith("treeanim-")
    assert not v.window.should_close and v.ctx.error == "GL_NO_ERROR"


# ---------------------------------------------------------------------------- the command line
def test_view_command_runs_frames(tmp_path, monkeypatch):
    from treeanim.app.main import view
    from treeanim.cli import main

    monkeypatch.chdir(tmp_path)
    shots = []
    frame = Viewer.frame

    def spy(self, dt=None):
        drawn = frame(self, dt)
        if drawn:
            shots.append(self.read_pixels())
        return drawn

    monkeypatch.setattr(Viewer, "frame", spy)
    assert main(["view", "beam", "--size", "320x200", "--season", "0.5", "--wind", "3", "--frames", "3"]) == 0
    assert len(shots) == 3, "the command drew exactly --frames frames"
    for img in shots:
        assert img.shape[2] == 3 and img.shape[:2] == (200, 320)
        assert img.std() > 10, "a frame with nothing drawn in it"
    assert view(ta.load_preset("beam"), size=(320, 200), frames=2) == 2
    assert len(shots) == 5


def _one_line_failure(env, *args):
    res = subprocess.run([sys.executable, "-m", "treeanim", *args], env=env, capture_output=True, text=True,
                         timeout=60)
    lines = res.stderr.strip().splitlines()
    assert res.returncode == 2, res.stderr
    assert len(lines) == 1, res.stderr
    assert "Traceback" not in res.stderr and res.stdout == ""
    return lines[0]


def test_no_display_is_one_clear_line():
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    line = _one_line_failure(env)  # plain `treeanim` opens the viewer
    assert "no display" in line and "treeanim render" in line and "treeanim export" in line


def test_no_opengl_33_is_one_clear_line():
    env = dict(os.environ, MESA_GL_VERSION_OVERRIDE="3.0", MESA_GLSL_VERSION_OVERRIDE="130")
    line = _one_line_failure(env, "view", "beam")
    assert "OpenGL 3.3" in line and "treeanim render" in line


def test_bad_view_options_are_one_line():
    line = _one_line_failure(dict(os.environ), "view", "beam", "--size", "12by7")
    assert "--size" in line
