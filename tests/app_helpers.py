"""Driving a viewer from a test, on either window (test_app: headless on EGL; test_app_window:
GLFW under Xvfb): the mouse and the panel through the viewer's own handlers, a branch to grab,
the pixels the tree covers."""

from __future__ import annotations

import dataclasses

import glfw
import numpy as np

import treeanim as ta
from treeanim.app.viewer import Viewer

#: The apps' size in screen units, and a 60 Hz frame.
W, H = 480, 360
DT = 1.0 / 60.0


def press(v, x, y, button=glfw.MOUSE_BUTTON_LEFT):
    """Move the cursor to (x, y) and press ``button`` there."""
    v.on_cursor_pos(x, y)
    v.on_mouse_button(button, glfw.PRESS, 0)


def click(v, x, y, button=glfw.MOUSE_BUTTON_LEFT):
    """A click on the panel: imgui sees the move, the press and the release in separate frames."""
    v.on_cursor_pos(x, y)
    v.frame(DT)
    v.on_mouse_button(button, glfw.PRESS, 0)
    v.frame(DT)
    v.on_mouse_button(button, glfw.RELEASE, 0)
    v.frame(DT)


def centre(rect):
    """The centre of an (x0, y0, x1, y1) rectangle."""
    return 0.5 * (rect[0] + rect[2]), 0.5 * (rect[1] + rect[3])


def reveal(v, label, height=H):
    """Scroll the panel with the wheel until ``label`` is in view; its centre."""
    for _ in range(12):
        r = v.panel.item_rects.get(label)
        if r is not None and r[1] > 4 and r[3] < height - 4:
            return centre(r)
        v.on_cursor_pos(150, height / 2)
        v.frame(DT)
        v.on_scroll(0.0, -2.0 if r is None or r[3] >= height - 4 else 2.0)
        v.frame(DT)
        v.frame(DT)
    raise AssertionError(f"{label} never came into view")


def tree_pixels(v, w, h, threshold):
    """Pixels where the tree differs by more than ``threshold`` from the same view without it
    (the renderer told that nothing is present; the panel not drawn), and the view with it."""
    v.show_panel, shown = False, v.show_panel
    v.frame(DT)
    scene = v.read_pixels()
    r = v.renderer
    r.update(v.sim.positions, v.sim.rotations, present=np.zeros(v.tree.n_objects, bool))
    v.window.framebuffer.use()
    r.draw(v.camera, w, h, season=v.sim.season)
    empty = v.read_pixels()
    v._uploaded = None  # the viewer uploads its pose again on its next frame
    v.show_panel = shown
    return np.abs(scene.astype(int) - empty.astype(int)).max(axis=2) > threshold, scene


def check_tree_and_panel(v, samples):
    """Draw two frames with the panel and check the picture: the tree in the middle of the
    window, the panel over the scene at the left where its rectangle says, nothing else
    changed; ``samples`` the MSAA sample counts the window may have."""
    v.show_panel = True
    assert v.frame(DT)
    assert v.frame(DT)  # imgui sizes a new window to its content over its first frames
    with_panel = v.read_pixels()
    assert with_panel.shape == (H, W, 3)
    assert v.window.samples in samples
    tree_px, scene = tree_pixels(v, W, H, 24)
    assert v.ctx.error == "GL_NO_ERROR"
    assert tree_px.mean() > 0.03, "the tree covers too little of the window"
    ys, xs = np.nonzero(tree_px)
    assert 0.1 * W < xs.mean() < 0.9 * W and 0.1 * H < ys.mean() < 0.9 * H
    x0, y0, x1, y1 = (int(round(c)) for c in v.panel.rect)
    assert x0 < 20 and x1 > 200 and y1 > 100
    differs = np.abs(with_panel.astype(int) - scene.astype(int)).max(axis=2) > 24
    assert differs[y0 + 2:y1 - 2, x0 + 2:x1 - 2].mean() > 0.5
    assert differs[:, x1 + 4:].mean() < 0.01


def branch_on_screen(v, w=W, h=H, exclude=()):
    """A branch (not one of ``exclude``) whose tip region is visible and picks as itself:
    (object, x, y)."""
    tree, P = v.tree, v.sim.positions
    branches = [i for i in np.flatnonzero(tree.kind == "branch") if tree.level[i] >= 2 and i not in exclude]

    def length(i):
        return np.linalg.norm(np.diff(tree.rest_positions[tree.object_nodes(i)], axis=0), axis=1).sum()

    for i in sorted(branches, key=length, reverse=True):
        nodes = tree.object_nodes(i)
        for f in (0.75, 0.6, 0.9):
            pt = P[nodes[0]] + f * (P[nodes[-1]] - P[nodes[0]])
            x, y, z = v.camera.project(pt, w, h)[0]
            if not (40 < x < w - 40 and 40 < y < h - 40 and 0 < z < 1):
                continue
            hit = v.pick(x, y)
            if hit is not None and hit.object == i:
                return int(i), float(x), float(y)
    raise AssertionError("no branch of the small cherry is visible on its own")


def unsimulable(name="beam"):
    """A preset's tree whose physics has no f/ζ range for its branches (Simulation: ValueError)."""
    tree = ta.load_preset(name)
    p = tree.physics
    physics = dataclasses.replace(p, summer=dataclasses.replace(p.summer, branch=None),
                                  winter=dataclasses.replace(p.winter, branch=None))
    return dataclasses.replace(tree, physics=physics)


def open_viewer(win, tree, ready=lambda v: None):
    """A viewer of ``tree`` in ``win`` as the app tests use it (calm, the tree model, panel
    hidden, its widgets' rects recorded), ``ready(v)`` then one frame drawn; yields it, and
    releases it and closes the window after (the window too if the viewer fails to open)."""
    try:
        v = Viewer(win, tree, wind_speed=0.0, show_panel=False)
    except BaseException:
        win.close()
        raise
    try:
        v.panel.record_rects = True  # where the widgets are, to click on them
        win.connect(v)
        ready(v)
        v.frame(DT)
        yield v
    finally:
        v.release()
        win.close()


def drag_and_let_go(v, dx, dy, steps):
    """Press on a branch on screen, move the cursor by (dx, dy), hold ``steps`` steps, let go;
    the branch's object."""
    obj, x, y = branch_on_screen(v)
    press(v, x, y)
    v.on_cursor_pos(x + dx, y + dy)
    for _ in range(steps):
        v.advance(DT)
    v.on_mouse_button(glfw.MOUSE_BUTTON_LEFT, glfw.RELEASE, 0)
    return obj
