"""The same Renderer on a GLFW window's context (under Xvfb in CI, via pytest-xvfb)."""

from __future__ import annotations

import glfw
import moderngl
import numpy as np
import pytest

from conftest import small_tree
from treeanim.render.camera import OrbitCamera
from treeanim.render.overlays import LocalFrames
from treeanim.render.renderer import Renderer


@pytest.fixture()
def window():
    assert glfw.init(), "GLFW could not initialise (no X display? run under xvfb)"
    glfw.window_hint(glfw.CONTEXT_VERSION_MAJOR, 3)
    glfw.window_hint(glfw.CONTEXT_VERSION_MINOR, 3)
    glfw.window_hint(glfw.OPENGL_PROFILE, glfw.OPENGL_CORE_PROFILE)
    glfw.window_hint(glfw.OPENGL_FORWARD_COMPAT, True)
    glfw.window_hint(glfw.VISIBLE, False)
    win = glfw.create_window(200, 150, "treeanim test", None, None)
    assert win, "GLFW could not open a GL 3.3 core window"
    glfw.make_context_current(win)
    yield win
    glfw.destroy_window(win)
    glfw.terminate()


def test_renderer_draws_into_a_window(window):
    ctx = moderngl.create_context(require=330)
    tree = small_tree()
    r = Renderer(ctx, tree)
    cam = OrbitCamera(elevation=5.0)
    cam.frame(r.bounds(), aspect=200 / 150)
    w, h = glfw.get_framebuffer_size(window)
    rest = tree.rest_positions, np.broadcast_to(np.eye(3), (tree.n_nodes, 3, 3))
    # Into the window itself, then shown.
    ctx.screen.use()
    r.update(*rest)
    r.draw(cam, w, h, overlays=[LocalFrames()])
    r.draw(cam, 0, 0)  # a minimised window: nothing happens
    glfw.swap_buffers(window)
    assert ctx.error == "GL_NO_ERROR"
    # Into a framebuffer of the window's context, read back: the tree is there.
    fbo = ctx.simple_framebuffer((w, h))
    r.draw(cam, w, h, framebuffer=fbo)
    img = np.frombuffer(fbo.read(components=3, alignment=1), np.uint8).reshape(h, w, 3)
    r.update(*rest, present=np.zeros(tree.n_objects, bool))
    r.draw(cam, w, h, framebuffer=fbo)
    bg = np.frombuffer(fbo.read(components=3, alignment=1), np.uint8).reshape(h, w, 3)
    tree_px = np.abs(img.astype(int) - bg.astype(int)).max(axis=2) > 24
    assert tree_px.mean() > 0.015
    ys, xs = np.nonzero(tree_px)
    assert abs(xs.mean() - w / 2) < 0.2 * w
    assert ctx.error == "GL_NO_ERROR"
    fbo.release()
    r.release()
