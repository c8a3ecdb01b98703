"""The setting (issue #30) tested by the pixels of real renders through EGL: the sun's disc, the
clouds, grass without a disc of soil under the tree, and haze that fades sky, ground and trees
into one colour at the horizon."""

from __future__ import annotations

import numpy as np
import pytest

from conftest import rest_pose
from treeanim.render.camera import OrbitCamera
from treeanim.render.scene import Scene, sun_direction

W, H = 240, 160


def luminance(img):
    return img.astype(float) @ np.array([0.2126, 0.7152, 0.0722])


def render(off, tree, cam, show_tree=False, **scene):
    """The picture from ``cam``, the tree hidden unless ``show_tree`` (the ground's features
    still lie where the tree stands)."""
    off.resize(W, H)
    off.load(tree, scene=Scene(**scene))
    off.update(*rest_pose(tree), present=None if show_tree else np.zeros(tree.n_objects, bool))
    return off.render(cam)


def sample(img, cam, points):
    """The pixels where world ``points`` (K, 3) fall (those inside the picture)."""
    xy = np.round(cam.project(points, W, H)[:, :2] - 0.5).astype(int)
    inside = (xy[:, 0] >= 0) & (xy[:, 0] < W) & (xy[:, 1] >= 0) & (xy[:, 1] < H)
    return img[xy[inside, 1], xy[inside, 0]]


@pytest.mark.parametrize("azimuth, elevation", [(30.0, 12.0), (200.0, 25.0)])
def test_the_sun_disc_is_brightest_where_the_sun_direction_projects(offscreen, tree, azimuth, elevation):
    sun = np.array(sun_direction(azimuth, elevation))
    # Looking towards the sun, a little to its side, so it is not at the picture's centre.
    cam = OrbitCamera(target=(0.0, 1.5, 0.0), distance=6.0, azimuth=azimuth + 180.0 + 8.0, elevation=-elevation + 4.0)
    lum = luminance(render(offscreen, tree, cam, sun_direction=tuple(sun)))
    at = cam.project(cam.eye + 1e3 * sun, W, H)[0, :2]
    ys, xs = np.nonzero(lum >= lum.max() - 2.0)
    assert len(xs) < 60, len(xs)                       # a disc, not a bright stretch of sky
    assert np.hypot(xs.mean() + 0.5 - at[0], ys.mean() + 0.5 - at[1]) < 2.0, (xs.mean(), ys.mean(), at)


def cloud_and_pixel_scale(lum, clear, block=12):
    """(The spread of the sky's brightness about a clear sky's from block to block; the spread of
    each pixel about its 3 × 3 neighbourhood)."""
    h, w = (lum.shape[0] // block) * block, (lum.shape[1] // block) * block
    blocks = (lum - clear)[:h, :w].reshape(h // block, block, w // block, block).mean(axis=(1, 3))
    box = sum(np.roll(np.roll(lum, i, 0), j, 1) for i in (-1, 0, 1) for j in (-1, 0, 1)) / 9.0
    return np.std(blocks), np.std((lum - box)[1:-1, 1:-1])


def test_the_sky_has_soft_clouds_and_none_when_clear(offscreen, tree):
    # Looking up from under the tree, away from the sun: only sky in the picture.
    cam = OrbitCamera(target=(0.0, 8.0, 0.0), distance=6.0, azimuth=0.0, elevation=-40.0)
    sun = sun_direction(0.0, 50.0)
    cloudy = luminance(render(offscreen, tree, cam, sun_direction=sun))
    clear = luminance(render(offscreen, tree, cam, sun_direction=sun, clouds=0.0))
    cloud, pixel = cloud_and_pixel_scale(cloudy, clear)
    assert cloud > 6.0, cloud                           # clouds: grey levels of structure blocks apart
    assert pixel < 0.8, pixel                           # ... soft: no noise from pixel to pixel
    assert cloud_and_pixel_scale(clear, clear)[1] < 0.8  # a clear sky as smooth


def rings(radii, n=180):
    """Points on the ground on circles of the given radii round the trunk's foot (the origin)."""
    a = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    r = np.asarray(radii, float)[:, None]
    return np.stack([r * np.cos(a), np.zeros_like(r * a), r * np.sin(a)], -1).reshape(-1, 3)


def redness(rgb):
    """How much redder than green a colour is (soil > 0 > grass), independent of brightness."""
    rgb = rgb.astype(float)
    return (rgb[..., 0] - rgb[..., 1]) / (rgb[..., 0] + rgb[..., 1] + 1.0)


def test_no_disc_of_soil_round_the_trunk_yet_the_ground_varies(offscreen, tree):
    """The ground at the trunk's foot is the grass 3 m away (the brown disc under every tree is
    gone), while grass and soil vary across it."""
    cam = OrbitCamera(target=(0.0, 0.0, 0.0), distance=14.0, azimuth=20.0, elevation=80.0)
    img = render(offscreen, tree, cam, shadow=False)
    near = sample(img, cam, rings(np.linspace(0.25, 0.6, 5)))
    far = sample(img, cam, rings(np.linspace(2.7, 3.3, 5)))
    assert len(near) > 500 and len(far) > 500
    assert abs(redness(near).mean() - redness(far).mean()) < 0.03, (redness(near).mean(), redness(far).mean())
    # Grass and soil vary across it (the picture: 13 × 9 m).
    assert np.std(luminance(img)) > 2.5 and np.std(redness(img)) > 0.01, (np.std(luminance(img)), np.std(redness(img)))


def horizon_column(off, tree, towards_sun):
    """Luminance down the middle column of a narrow view along the ground towards a low sun (or
    away from it), the tree hidden and no clouds; and the row of the horizon."""
    sun = sun_direction(0.0, 8.0)
    cam = OrbitCamera(target=(0.0, 1.5, 0.0), distance=6.0, azimuth=192.0 if towards_sun else 12.0,
                      elevation=0.0, fov_y=10.0)
    lum = luminance(render(off, tree, cam, sun_direction=sun, clouds=0.0))
    horizon = cam.project(cam.eye + 1e6 * cam.forward * np.array([1.0, 0.0, 1.0]), W, H)[0, 1]
    return lum[:, W // 2], horizon


@pytest.mark.parametrize("towards_sun", [True, False])
def test_far_ground_fades_into_the_sky_at_the_horizon(offscreen, tree, towards_sun):
    """Haze lays the air's colour over the far ground: the colour the sky has at the horizon in
    that direction (with the sun's glow towards it)."""
    lum, horizon = horizon_column(offscreen, tree, towards_sun)
    sky, ground = lum[int(horizon - 2.5)], lum[int(horizon + 2.5)]   # pixels whose centres lie 2 to 3 rows off it
    assert abs(ground - sky) < 3.0, (ground, sky)
    assert abs(lum[-1] - sky) > 10.0, (lum[-1], sky)                 # the near ground is not hazed


def test_the_air_is_brighter_towards_the_sun(offscreen, tree):
    (towards, h1), (away, h2) = horizon_column(offscreen, tree, True), horizon_column(offscreen, tree, False)
    assert towards[int(h1 + 2.5)] > away[int(h2 + 2.5)] + 8.0, (towards[int(h1 + 2.5)], away[int(h2 + 2.5)])


def ground_bands(img, cam, bands):
    """Luminance across the ground between distances (near, far) metres from the eye along the
    view, each row less its mean: (the spread of steps from pixel to pixel along the rows; the
    spread of 16-pixel blocks' means)."""
    lum = luminance(img)
    ahead = cam.forward * np.array([1.0, 0.0, 1.0])
    ahead /= np.linalg.norm(ahead)
    for near, far in bands:
        rows = cam.project(cam.eye * np.array([1.0, 0.0, 1.0]) + np.array([[near], [far]]) * ahead, W, H)[:, 1]
        band = lum[int(rows.min()):int(rows.max()) + 1]
        band = band - band.mean(axis=1, keepdims=True)
        blocks = band[:, :W // 16 * 16].reshape(len(band), W // 16, 16).mean(axis=2)
        yield np.std(np.diff(band, axis=1)), np.std(blocks)


def test_the_ground_has_grain_near_and_fades_to_its_mean_not_into_blotches(offscreen, tree):
    """Looking across the ground from eye height (1.7 m, 12° down), the grass 3-6 m away has
    grain from pixel to pixel (before: 0.8 grey levels, noise faded by a pixel's longest side
    on the ground), and 8-16 m away no blotches of a metre or two smeared along the view
    (before: 2.7 grey levels from block to block): its detail fades to its mean."""
    cam = OrbitCamera(target=(0.0, 1.7, 0.0), distance=0.01, azimuth=0.0, elevation=12.0)
    img = render(offscreen, tree, cam, shadow=False, clouds=0.0)
    (grain, _), (_, blotches) = ground_bands(img, cam, [(3.0, 6.0), (8.0, 16.0)])
    assert grain > 2.0 and blotches < 2.0, (grain, blotches)


def test_bare_soil_is_dry_earth_no_darker_than_the_grass(offscreen, tree):
    """Seen from above, the ground has patches of bare soil (redder than green) and they are
    dry earth, at least as bright as the grass round them, not dark puddles (before: none in
    this view, and the soil a dark brown)."""
    cam = OrbitCamera(target=(0.0, 0.0, 0.0), distance=14.0, azimuth=20.0, elevation=80.0)
    img = render(offscreen, tree, cam, shadow=False)
    red, lum = redness(img), luminance(img)
    soil, grass = red > 0.02, red < -0.1
    assert soil.mean() > 0.002 and grass.mean() > 0.8, (soil.mean(), grass.mean())
    assert np.median(lum[soil]) > np.median(lum[grass]), (np.median(lum[soil]), np.median(lum[grass]))
