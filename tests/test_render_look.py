"""The look (issue #13) tested by the pixels of real renders through EGL: the sun's shadows on
the ground and in the crown, and light through the leaves."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import treeanim as ta
from conftest import _curve, grass_patch, rest_pose
from treeanim.model.build import ObjectSpec, assemble
from treeanim.render.camera import OrbitCamera
from treeanim.render.scene import Scene

W, H = 200, 150


def luminance(img):
    return img.astype(float) @ np.array([0.2126, 0.7152, 0.0722])


def render(off, tree, cam, present=None, **scene):
    off.resize(W, H)
    off.load(tree, scene=Scene(**scene))
    off.update(*rest_pose(tree), present=present)
    return off.render(cam)


def overhead(tree):
    """A camera high above the tree, looking down at it and the ground round it."""
    return OrbitCamera(target=(0.0, 0.0, 0.0), distance=7.0, azimuth=20.0, elevation=70.0)


def cast_on_ground(points, sun):
    """Where the sun casts ``points`` on the ground y = 0."""
    sun = np.asarray(sun, float) / np.linalg.norm(sun)
    return points - np.outer(points[:, 1] / sun[1], sun)


def shadow_pixels(off, tree, cam, sun):
    """Ground pixels the tree's shadow darkens: shadowed render against unshadowed, away from
    the tree's own pixels."""
    lit = render(off, tree, cam, shadow=False, sun_direction=sun)
    shaded = render(off, tree, cam, shadow=True, sun_direction=sun)
    bare = render(off, tree, cam, present=np.zeros(tree.n_objects, bool), shadow=False, sun_direction=sun)
    on_tree = np.abs(lit.astype(int) - bare.astype(int)).max(axis=2) > 6
    darker = luminance(lit) - luminance(shaded)
    return (darker > 12) & ~on_tree, darker, on_tree, lit, shaded


@pytest.mark.parametrize("sun", [(0.6, 0.75, 0.2), (-0.6, 0.75, -0.1)])
def test_the_tree_shadows_the_ground_where_the_sun_casts_it(offscreen, tree, sun):
    cam = overhead(tree)
    dark, darker, on_tree, *_ = shadow_pixels(offscreen, tree, cam, sun)
    assert dark.sum() > 150, dark.sum()
    # The crown's cast outline on the ground, projected to the screen: the dark pixels lie there.
    leafy = np.isin(tree.node_object, np.flatnonzero(tree.kind == "leaf"))
    cast = cam.project(cast_on_ground(tree.rest_positions[leafy], sun), W, H)[:, :2]
    ys, xs = np.nonzero(dark)
    assert np.hypot(xs.mean() - cast[:, 0].mean(), ys.mean() - cast[:, 1].mean()) < 0.06 * W
    # Ground far from any cast point (and off the tree) is not darkened.
    gy, gx = np.mgrid[0:H, 0:W]
    near = np.min(np.hypot(gx[..., None] - cast[:, 0], gy[..., None] - cast[:, 1]), axis=2)
    far = (near > 0.15 * W) & ~on_tree
    assert far.sum() > 1000 and np.abs(darker[far]).mean() < 1.5, np.abs(darker[far]).mean()


def test_the_shadow_moves_when_the_sun_moves(offscreen, tree):
    cam = overhead(tree)
    centres = []
    for sun in [(0.6, 0.75, 0.2), (-0.6, 0.75, -0.1)]:
        dark = shadow_pixels(offscreen, tree, cam, sun)[0]
        ys, xs = np.nonzero(dark)
        centres.append(np.array([xs.mean(), ys.mean()]))
    # The two suns cast on opposite sides of the trunk: the shadow moved across the screen by
    # about the distance between the two cast crowns.
    foot = cam.project([[0.0, 0.0, 0.0]], W, H)[0, :2]
    a, b = centres[0] - foot, centres[1] - foot
    assert np.dot(a, b) < 0, (a, b)
    assert np.linalg.norm(centres[0] - centres[1]) > 0.2 * W


@pytest.mark.parametrize("sun", [(0.2, 0.9, 0.35), (0.1, 0.9, -0.4)])  # high, in front and behind
def test_the_crown_shades_itself(offscreen, sun):
    tree = ta.load_preset("small_cherry")
    lo, hi = tree.rest_positions.min(axis=0), tree.rest_positions.max(axis=0)
    cam = OrbitCamera(target=tuple(0.5 * (lo + hi)), distance=1.6 * float((hi - lo).max()), elevation=10.0)
    *_, on_tree, lit, shaded = shadow_pixels(offscreen, tree, cam, sun)
    drop = luminance(lit)[on_tree] - luminance(shaded)[on_tree]
    assert on_tree.sum() > 1000
    assert np.mean(drop > 8) > 0.12, np.mean(drop > 8)  # the upper leaves shade the inner crown
    assert np.mean(drop < -8) < 0.01  # and shade never brightens


def test_a_leaf_lit_from_behind_glows_with_translucency(offscreen, tree):
    cam = OrbitCamera(target=(0.0, 1.5, 0.0), distance=2.5, azimuth=0.0, elevation=5.0)
    leaves = tree.kind == "leaf"
    for sun, least in [((0.0, 0.45, -1.0), 1.15), ((0.0, 0.45, 1.0), None)]:  # behind, then in front
        bare = render(offscreen, tree, cam, present=~leaves, shadow=False, sun_direction=sun)  # the same sky
        glow = render(offscreen, tree, cam, shadow=False, sun_direction=sun, translucency=1.0)
        flat = render(offscreen, tree, cam, shadow=False, sun_direction=sun, translucency=0.0)
        leaf = np.abs(glow.astype(int) - bare.astype(int)).max(axis=2) > 24
        assert leaf.sum() > 300
        ratio = luminance(glow)[leaf].mean() / luminance(flat)[leaf].mean()
        if least is not None:
            assert ratio > least, ratio
        else:  # lit from the camera's side the faces we see take the sun directly
            assert 1.0 <= ratio < 1.1, ratio


def test_shadows_off_is_the_same_picture_without_the_shadow_pass(offscreen, tree):
    cam = overhead(tree)
    sun = (0.6, 0.75, 0.2)
    a = render(offscreen, tree, cam, shadow=False, sun_direction=sun)
    b = render(offscreen, tree, cam, shadow=False, sun_direction=sun, shadow_size=64)
    np.testing.assert_array_equal(a, b)


def test_scene_defaults_have_shadows_and_translucency():
    s = Scene()
    assert s.shadow and s.translucency == 1.0 and s.shadow_size >= 1024
    assert dataclasses.replace(s, shadow=False).shadow is False


# ------------------------------------------------------------------------------ thin twigs
def thin_twig():
    """One 3 m twig, 1 cm thick, rising at 40° from the ground."""
    from treeanim.model.build import ObjectSpec, assemble

    d = np.array([np.cos(np.radians(40)), np.sin(np.radians(40)), 0.0])
    pts = np.outer(np.linspace(0.0, 3.0, 4), d) + (-1.2, 0.2, 0.0)
    return assemble([ObjectSpec(pts, np.full(4, 0.01), "branch", 1)], name="thin_twig")


def twig_coverage(off, tree, cam, shift, thin_pixels):
    """Per screen column along the twig (at rest): how much it darkens the sky there (summed
    over the column's pixels), for the twig moved by ``shift`` metres."""
    off.resize(W, H)
    off.load(tree, scene=Scene(shadow=False, thin_pixels=thin_pixels))
    P = tree.rest_positions + shift
    R = np.broadcast_to(np.eye(3), (tree.n_nodes, 3, 3))
    off.update(P, R, present=np.zeros(tree.n_objects, bool))
    sky = luminance(off.render(cam))
    off.update(P, R)
    dark = np.clip(sky - luminance(off.render(cam)), 0.0, None)
    ends = cam.project(tree.rest_positions[[0, -1]], W, H)
    cols = np.arange(int(np.ceil(ends[:, 0].min())) + 2, int(ends[:, 0].max()) - 2)
    return dark[:, cols].sum(axis=0)


def test_a_thin_twig_stays_continuous_from_frame_to_frame(offscreen):
    """Thinner than a pixel (0.2 px here, 10 m away), a twig is drawn as a soft line about two
    pixels wide and faint in proportion: every column along it is covered, in two frames a
    third of a pixel apart, with about the same weight; drawn at its true width it breaks up."""
    tree = thin_twig()
    cam = OrbitCamera(target=(0.0, 1.2, 0.0), distance=10.0, elevation=0.0)
    off = type(offscreen)(W, H, samples=0, ctx=offscreen.ctx)  # no MSAA, as the viewer on llvmpipe
    try:
        frames = [twig_coverage(off, tree, cam, (dx, 0.0, 0.0), 1.5) for dx in (0.0, 0.016)]
        true_width = twig_coverage(off, tree, cam, (0.0, 0.0, 0.0), 0.0)
    finally:
        off.release()
    assert len(frames[0]) > 40
    for cov in frames:
        assert np.all(cov > 3.0), np.flatnonzero(cov <= 3.0)  # no gap along the twig
    # The twig's weight per column stays put as it moves by a fraction of a pixel
    ratio = frames[1] / frames[0]
    assert 0.9 < frames[1].sum() / frames[0].sum() < 1.1
    assert np.percentile(np.abs(ratio - 1.0), 90) < 0.3, ratio
    # Without the minimum width it falls apart into dots
    assert np.mean(true_width > 3.0) < 0.8, np.mean(true_width > 3.0)


def test_the_bark_takes_its_species_colour(offscreen):
    """The same trunk with a grey and a red-brown [bark] colour: its pixels follow it."""
    from treeanim.model.build import ObjectSpec, assemble
    from treeanim.model.look import Bark

    pts = np.outer(np.linspace(0.0, 2.0, 3), (0.0, 1.0, 0.0))
    cam = OrbitCamera(target=(0.0, 1.0, 0.0), distance=2.5, elevation=0.0)
    means = []
    for color in ((0.5, 0.5, 0.5), (0.5, 0.25, 0.15)):
        tree = assemble([ObjectSpec(pts, np.array([0.3, 0.28, 0.26]), "branch", 1)], name="trunk",
                        bark=Bark(color=color, lenticels=0.5))
        img = render(offscreen, tree, cam, shadow=False).astype(float)
        trunk = img[H // 4: 3 * H // 4, W // 2 - 8: W // 2 + 8].reshape(-1, 3)
        means.append(trunk.mean(axis=0))
    grey, brown = means
    assert abs(grey[0] - grey[2]) < 12  # grey stays grey under the lights
    assert brown[0] - brown[2] > 40 and brown[0] - brown[2] > grey[0] - grey[2] + 30


def test_a_thin_twig_in_front_never_opens_a_hole_in_what_is_behind_it(offscreen):
    """A 0.2 px twig drawn before a thick trunk behind it: its faint pixels must not keep the
    trunk out (the sky showing through along the twig, as it did across a gale's crown)."""
    from treeanim.model.build import ObjectSpec, assemble

    d = np.array([np.cos(np.radians(40)), np.sin(np.radians(40)), 0.0])
    twig = np.outer(np.linspace(0.0, 3.0, 4), d) + (-1.2, 0.2, 0.5)
    trunk = np.outer(np.linspace(0.0, 3.0, 3), (0.0, 1.0, 0.0)) + (0.0, 0.0, -0.5)
    tree = assemble([ObjectSpec(twig, np.full(4, 0.01), "branch", 1),  # drawn first
                     ObjectSpec(trunk, np.full(3, 1.2), "branch", 1)], name="twig_before_trunk")
    cam = OrbitCamera(target=(0.0, 1.2, 0.0), distance=10.0, elevation=0.0)
    off = type(offscreen)(W, H, samples=0, ctx=offscreen.ctx)
    try:
        both = luminance(render(off, tree, cam, shadow=False))
        twig_only = luminance(render(off, tree, cam, present=np.array([True, False]), shadow=False))
        trunk_only = luminance(render(off, tree, cam, present=np.array([False, True]), shadow=False))
        sky_only = luminance(render(off, tree, cam, present=np.array([False, False]), shadow=False))
    finally:
        off.release()
    on_twig = np.abs(twig_only - sky_only) > 2  # where the twig is ...
    over_trunk = np.abs(trunk_only - sky_only) > 40  # ... across the trunk
    where = on_twig & over_trunk
    assert where.sum() > 10
    # There the picture stays the trunk's, far nearer it than the sky.
    assert np.mean(np.abs(both - trunk_only)[where]) < 0.4 * np.mean(np.abs(sky_only - trunk_only)[where])
    assert np.all(np.abs(both - twig_only)[on_twig & ~over_trunk] < 3)  # and over the sky the twig shows


# ----------------------------------------------------------------------------- the look's cost
def inside_convex(polygon, points):
    """Which ``points`` (P, 2) lie inside the convex ``polygon`` (K, 2), either winding."""
    edges = np.roll(polygon, -1, axis=0) - polygon
    rel = points[:, None, :] - polygon[None, :, :]
    cross = edges[None, :, 0] * rel[..., 1] - edges[None, :, 1] * rel[..., 0]
    return np.all(cross >= 0, axis=1) | np.all(cross <= 0, axis=1)


def test_the_ground_looks_the_shadow_up_only_where_a_shadow_can_fall(offscreen):
    """The ground reads the shadow map only over the shadow's footprint (issue #13's frame
    budget), and the picture is the one a lookup everywhere makes, for a tree in a gale under a
    low sun."""
    tree = ta.load_preset("small_cherry")
    sim = ta.Simulation(tree, wind=ta.WindField(speed=25.0, seed=0))
    for _ in range(45):
        sim.step(1 / 30)
    cam = OrbitCamera(target=(-1.0, 0.0, -1.0), distance=9.0, azimuth=30.0, elevation=40.0)
    offscreen.resize(W, H)
    r = offscreen.load(tree, scene=Scene(sun_direction=(0.55, 0.4, 0.35)))
    offscreen.update(sim.positions, sim.rotations, sim.shown)
    fitted = offscreen.render(cam)
    footprint = r.shadow.footprint.copy()
    r.shadow.footprint = np.array([[-1e3, -1e3], [1e3, -1e3], [1e3, 1e3], [-1e3, 1e3]])
    everywhere = offscreen.render(cam)
    r.shadow.footprint = np.array([[50.0, 50.0], [51.0, 50.0], [51.0, 51.0]])
    nowhere = offscreen.render(cam)
    np.testing.assert_array_equal(fitted, everywhere)
    assert (luminance(everywhere) < luminance(nowhere) - 12).sum() > 400  # there is a shadow to miss
    # The footprint holds the tree's foot and its shadow, not the ground 4 m off.
    xz = np.array([[0.0, 0.0], [-2.0, -1.5], [4.0, 4.0], [-4.0, 4.0], [4.0, -4.0]])
    assert inside_convex(footprint, xz).tolist() == [True, True, False, False, False]


def test_a_blade_in_a_shadow_is_darker(offscreen):
    """Blades are lit at their vertices (tree.vert): a post's shadow still darkens the blades
    it falls on, and only those."""
    blades = grass_patch(n=80, seed=3)
    post = ObjectSpec(_curve((0.0, 0.0, 0.0), (0.0, 1.0, 0.0), 1.2, 3), np.full(3, 0.35), "branch", 1)
    specs = [post] + [ObjectSpec(blades.rest_positions[blades.object_nodes(i)], blades.node_diameter[blades.object_nodes(i)],
                                 "blade", 1) for i in range(blades.n_objects)]
    tree = assemble(specs, name="post_in_grass")
    sun = np.array([-0.6, 0.45, 0.65])  # low, from the front left: the blades facing us take it
    cam = OrbitCamera(target=(0.0, 0.1, 0.0), distance=2.2, azimuth=0.0, elevation=35.0)
    look = dict(sun_direction=tuple(sun), show_ground=False)  # no ground: only the blades' own light changes
    only_post = render(offscreen, tree, cam, present=np.asarray(tree.kind) == "branch", **look)
    lit = render(offscreen, tree, cam, shadow=False, **look)
    shaded = render(offscreen, tree, cam, shadow=True, **look)
    blade_px = np.abs(lit.astype(int) - only_post.astype(int)).max(axis=2) > 20
    # Where the post's shadow falls: within its radius (on screen) of its axis' cast, up to the blades' height.
    axis = cast_on_ground(np.array([[0.0, y, 0.0] for y in np.linspace(0.0, 1.2, 25)]), sun)
    cast = cam.project(np.concatenate([axis + [0.0, h, 0.0] for h in (0.0, 0.15, 0.3)]), W, H)[:, :2]
    radius = np.ptp(cam.project([[-0.175, 0.0, 0.0], [0.175, 0.0, 0.0]], W, H)[:, 0]) / 2
    gy, gx = np.mgrid[0:H, 0:W]
    dist = np.min(np.hypot(gx[..., None] - cast[:, 0], gy[..., None] - cast[:, 1]), axis=2)
    drop = luminance(lit) - luminance(shaded)
    inside, outside = blade_px & (dist < 0.6 * radius), blade_px & (dist > 2.0 * radius)
    assert inside.sum() > 50 and outside.sum() > 300
    assert np.median(drop[inside]) > 4, np.median(drop[inside])  # 0 if blades ignored the shadow map
    assert np.median(drop[outside]) < 1.5, np.median(drop[outside])


def test_the_background_cache_follows_the_camera_the_scene_and_the_size(offscreen, tree):
    """Sky and ground without shadows are drawn into a cache once the camera, the viewport and
    the scene hold still for a second frame, and copied from it after: a renderer that drew
    another view, sun or size just before, or the same one (drawn, cached, copied), draws the
    picture a fresh one draws (but for the horizon's multisampled edge, one grey level)."""

    def same(a, b):
        d = np.abs(a.astype(int) - b.astype(int))
        assert d.max() <= 1 and np.mean(d.max(axis=2) > 0) < 0.01, (d.max(), np.mean(d.max(axis=2) > 0))

    cams = [overhead(tree), OrbitCamera(target=(0.0, 1.0, 0.0), distance=5.0, azimuth=-40.0, elevation=15.0)]
    suns = [(0.6, 0.75, 0.2), (-0.6, 0.75, -0.1)]
    fresh = {(c, s): render(offscreen, tree, cams[c], sun_direction=suns[s]) for c in (0, 1) for s in (0, 1)}
    r = offscreen.load(tree, scene=Scene(sun_direction=suns[0]))
    offscreen.update(*rest_pose(tree))
    for c, s in [(0, 0), (1, 0), (1, 0), (1, 0), (0, 0), (0, 0), (0, 1), (0, 1), (0, 1), (1, 1)]:
        r.scene.sun_direction = suns[s]
        same(offscreen.render(cams[c]), fresh[c, s])
    offscreen.resize(W // 2, H // 2)
    small = [offscreen.render(cams[1]) for _ in range(3)]  # drawn, cached, copied
    offscreen.load(tree, scene=Scene(sun_direction=suns[1]))
    offscreen.update(*rest_pose(tree))
    first = offscreen.render(cams[1])
    for img in small:
        same(img, first)
