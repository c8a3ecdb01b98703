"""Species that read (issue 30, point 4), measured on real renders through EGL: crowns whose
leaves fill their outline, and a meadow that covers its ground from 10 m."""

from __future__ import annotations

import numpy as np
import pytest

import treeanim as ta
from conftest import rest_pose
from test_render_look import inside_convex
from treeanim.render.camera import OrbitCamera
from treeanim.render.scene import Scene

W, H = 320, 180


def covered(off, tree, cam, present=None) -> np.ndarray:
    """(H, W) bool: the pixels the ``present`` objects (None: all) change against the sky alone."""
    off.resize(W, H)
    off.load(tree, scene=Scene(show_ground=False))
    frames = []
    for shown in (present, np.zeros(tree.n_objects, bool)):
        off.update(*rest_pose(tree), present=shown)
        frames.append(off.render(cam).astype(int))
    return np.abs(frames[0] - frames[1]).max(axis=2) > 12


def crown_cover(off, tree) -> float:
    """The share of the crown's outline its leaves cover, seen from the side: leaf pixels over
    the pixels between the leftmost and rightmost leaf pixel of each row."""
    top = float(tree.rest_positions[:, 1].max())
    cam = OrbitCamera(target=(0.0, 0.55 * top, 0.0), distance=2.2 * top, azimuth=0.0, elevation=10.0)
    leaf = covered(off, tree, cam, np.asarray(tree.kind) == "leaf")
    rows = np.flatnonzero(leaf.any(axis=1))
    left = np.argmax(leaf[rows], axis=1)
    right = W - 1 - np.argmax(leaf[rows, ::-1], axis=1)
    return float(leaf[rows].sum() / np.sum(right - left + 1))


@pytest.mark.parametrize("name,least", [("small_cherry", 0.66), ("tulip_poplar", 0.75)])
def test_a_crown_is_leaf_inside_its_outline(offscreen, name, least):
    """Before: 0.56 of the small cherry's outline was leaf (sparse bunches at its twig tips, blades
    facing up, seen edge on), 0.70 of the poplar's; now 0.73 and 0.79."""
    assert crown_cover(offscreen, ta.load_preset(name)) > least


def test_the_meadow_covers_its_ground_from_ten_metres(offscreen):
    """The patch's middle (roots within 2.5 m of its centre) seen from 10 m, 30° above: before,
    one blade drawn for each simulated one, 0.64 of it showed blades (dark hair on the ground); drawn
    in clumps of three (render/mesh.py, BLADE_CLUMP) 0.82."""
    cam = OrbitCamera(target=(0.0, 0.0, 0.0), distance=10.0, azimuth=0.0, elevation=30.0)
    blades = covered(offscreen, ta.load_preset("grassland"), cam)
    ring = 2.5 * np.array([[np.cos(a), 0.0, np.sin(a)] for a in np.linspace(0, 2 * np.pi, 64, endpoint=False)])
    p = cam.project(ring, W, H)[:, :2]
    gy, gx = np.mgrid[0:H, 0:W]
    inside = inside_convex(p, np.column_stack([gx.ravel(), gy.ravel()])).reshape(H, W)
    assert inside.sum() > 2000
    assert blades[inside].mean() > 0.75, blades[inside].mean()
