"""The one framing (render/camera.py): points fit the free part of the view, centred there by a
lens shift, and the orbit pivots on the framed centre; rays and projections agree with the shift."""

from __future__ import annotations

import numpy as np
import pytest

import treeanim as ta
from treeanim.render.camera import FRAME_MARGIN, OrbitCamera, frame_tree, framed_camera, tree_extent


@pytest.mark.parametrize("left", [0.0, 346.0])
@pytest.mark.parametrize("elevation", [8.0, 25.0, 60.0])
def test_points_fill_the_free_view_centred(left, elevation):
    rng = np.random.default_rng(1)
    P = rng.normal(size=(400, 3)) * [4.0, 0.3, 3.0] + [1.0, 0.4, -2.0]  # a wide, flat patch
    w, h = 960, 540
    cam = OrbitCamera(azimuth=30.0, elevation=elevation)
    cam.frame_points(P, 0.05, width=w, height=h, left=left)
    np.testing.assert_allclose(cam.target, 0.5 * (P.min(0) + P.max(0)))
    x, y, depth = cam.project(P, w, h).T
    assert x.min() > left and x.max() < w and y.min() > 0 and y.max() < h and (0 < depth).all() and (depth < 1).all()
    # centred in the free part, one of its sides filled to the margin
    assert 0.5 * (x.min() + x.max()) == pytest.approx(0.5 * (left + w), abs=3.0)
    assert 0.5 * (y.min() + y.max()) == pytest.approx(0.5 * h, abs=3.0)
    fill = max((x.max() - x.min()) / (w - left), (y.max() - y.min()) / h)
    assert 0.95 / FRAME_MARGIN < fill < 1.0 / FRAME_MARGIN + 1e-3


def test_the_orbit_pivots_on_the_framed_centre_and_rays_meet_projections():
    tree = ta.load_preset("small_cherry")
    w, h = 800, 600
    cam = frame_tree(OrbitCamera(azimuth=20.0), tree, w, h, left=300.0)
    assert np.any(cam.shift != 0)
    centre = cam.target.copy()
    before = cam.project(centre, w, h)[0, :2]
    assert 300.0 < before[0] < w
    cam.orbit(40.0, 15.0)
    np.testing.assert_allclose(cam.project(centre, w, h)[0, :2], before, atol=1e-6)
    P, _ = tree_extent(tree)
    for p in P[:: len(P) // 7]:
        x, y, _ = cam.project(p, w, h)[0]
        o, d = cam.ray(x, y, w, h)
        assert np.linalg.norm(np.cross(p - o, d)) < 1e-6 * np.linalg.norm(p - o)


def test_framed_camera_keeps_a_given_distance():
    tree = ta.load_preset("beam")
    cam = framed_camera(tree, 320, 240, azimuth=10.0, distance=7.5)
    assert cam.distance == 7.5 and cam.azimuth == 10.0 and cam.elevation == 8.0
    assert framed_camera(ta.load_preset("grassland"), 320, 240).elevation == 25.0
