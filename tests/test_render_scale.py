"""A scene drawn at scale (docs/design.md §17, Drawing): trees and grass out of view not drawn,
far trees and grass with fewer triangles and no pop, the sun's shadow map fitted to the view and
drawn with the casters it needs; the offline render as the viewer. Real renders through EGL."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.ndimage import uniform_filter

import treeanim as ta
from conftest import grass_patch, rest_pose, small_tree
from treeanim.model.scene import make_scene
from treeanim.offline.render import RenderJob, run_render
from treeanim.offline.target import Target
from treeanim.physics.lod import choose_detail, tree_extents
from treeanim.render import passes as passes_module
from treeanim.render import renderer as renderer_module
from treeanim.render import shadow as shadow_module
from treeanim.render.camera import OrbitCamera, framed_camera
from treeanim.render.culling import TreeOrder, frustum_planes
from treeanim.render.lod import coarse_tubes
from treeanim.render.mesh import build_mesh
from treeanim.render.shadow import sun_basis
from treeanim.render.shadow_view import seen_corners, view_slice, view_window

W, H = 320, 180


def grove(pitch: float) -> "Scene":  # noqa: F821
    """25 small trees on a 5 × 5 grid ``pitch`` metres apart, each turned its own way."""
    tree = small_tree()
    where = [(pitch * (i - 2), 0.0, pitch * (j - 2)) for i in range(5) for j in range(5)]
    return make_scene([tree] * 25, where, [37.0 * k for k in range(25)])


def blocks(img: np.ndarray, n: int = 10) -> np.ndarray:
    """The mean colour of each n × n block of pixels."""
    h, w = img.shape[0] // n * n, img.shape[1] // n * n
    return img[:h, :w].reshape(h // n, n, w // n, n, 3).mean(axis=(1, 3))


@pytest.fixture(scope="module")
def meadow():
    """25 grass patches of 60 blades, 1 m apart: a 5 m meadow."""
    where = [(1.0 * (i - 2), 0.0, 1.0 * (j - 2)) for i in range(5) for j in range(5)]
    return make_scene([grass_patch()] * 25, where, [37.0 * k for k in range(25)])


@pytest.fixture(scope="module")
def near_grove():
    return grove(4.0)


@pytest.fixture(scope="module")
def wide_grove():
    return grove(16.0)


def load(offscreen, scene):
    offscreen.resize(W, H)
    r = offscreen.load(scene)
    offscreen.update(*rest_pose(scene))
    return r


def render(offscreen, cam):
    return offscreen.render(cam).astype(float)


def all_visible(monkeypatch):
    monkeypatch.setattr(TreeOrder, "visible", lambda self, view_proj: np.ones(self.n_trees, bool))


def no_lod(monkeypatch):
    monkeypatch.setattr(passes_module, "lod_band", lambda leaf, ppm: (1e30, 2e30))


def pixels_per_metre(cam):
    return 0.5 * H / np.tan(np.radians(cam.fov_y / 2))


def band_sweeps(monkeypatch, offscreen, r, cam, name, near, far, scales):
    """Render ``cam`` with the pass's hand-over band ``name`` moved to (near·s, far·s) for each
    scale s, then as a switch at far·s: the largest change of a step in any 7 × 7 pixels of
    each sweep, and the triangles drawn at each step of the first."""
    def sweep(band):
        frames, triangles = [], []
        for s in scales:
            monkeypatch.setattr(passes_module, name, lambda *args, s=s: band(s))
            frames.append(render(offscreen, cam))
            triangles.append(r.drawn["triangles"])
        return max(uniform_filter(np.abs(b - a).max(axis=2), 7).max() for a, b in zip(frames, frames[1:])), triangles

    faded, triangles = sweep(lambda s: (near * s, far * s))
    switched, _ = sweep(lambda s: (far * s - 1e-3, far * s))
    return faded, switched, triangles


def test_trees_out_of_view_are_not_drawn(offscreen, near_grove):
    r = load(offscreen, near_grove)
    render(offscreen, OrbitCamera(target=(0.0, 1.0, 0.0), distance=30.0, elevation=30.0))
    assert r.drawn["trees"] == 25 and r.drawn["triangles"] > 0
    # From the grove's edge looking out: nothing of it in view.
    render(offscreen, OrbitCamera(target=(0.0, 1.5, 20.0), distance=8.0, azimuth=180.0, elevation=5.0))
    assert r.drawn == dict(r.drawn, trees=0, triangles=0, draws=0)
    # From its middle looking along +x: some of it.
    render(offscreen, OrbitCamera(target=(6.0, 1.5, 0.0), distance=6.0, azimuth=90.0, elevation=5.0))
    assert 0 < r.drawn["trees"] < 25


def test_a_culled_frame_matches_one_drawn_whole(offscreen, near_grove, monkeypatch):
    """The trees culled (from the colour passes and from the sun's map) are none that show."""
    r = load(offscreen, near_grove)
    cam = OrbitCamera(target=(4.0, 1.5, 1.0), distance=7.0, azimuth=80.0, elevation=6.0)
    culled = render(offscreen, cam)
    drawn, shadow = r.drawn["trees"], r.drawn["shadow_triangles"]
    all_visible(monkeypatch)
    whole = render(offscreen, cam)
    assert r.drawn["trees"] == 25 > drawn and r.drawn["shadow_triangles"] > shadow
    assert np.abs(culled - whole).max() <= 2.0


def test_far_trees_are_drawn_with_fewer_triangles_and_look_the_same(offscreen, near_grove, monkeypatch):
    r = load(offscreen, near_grove)
    cam = OrbitCamera(target=(0.0, 1.2, 0.0), distance=45.0, elevation=12.0)
    far = render(offscreen, cam)
    coarse = r.drawn["triangles"]
    no_lod(monkeypatch)
    full = render(offscreen, cam)
    assert r.drawn["trees"] == 25 and coarse < 0.4 * r.drawn["triangles"]
    # The same coverage and colour: a leaf a few pixels long, its outline's 8 corners or 24.
    tree = (np.abs(full - render_background(offscreen, r, cam)).max(axis=2) > 24)
    assert np.abs(far - full)[tree].mean() < 0.1 * np.abs(full - render_background(offscreen, r, cam))[tree].mean()


def render_background(offscreen, r, cam):
    present = np.ones(r.tree.n_objects, bool)
    offscreen.update(*rest_pose(r.tree), present=np.zeros_like(present))
    img = render(offscreen, cam)
    offscreen.update(*rest_pose(r.tree), present=present)
    return img


def test_the_switch_to_coarse_trees_does_not_pop(offscreen, near_grove, monkeypatch):
    """The hand-over band swept over the grove from a still camera, in small steps: each step
    changes the picture a little here and there, not a whole leaf or branch at once as a
    switch without the band's dither does."""
    r = load(offscreen, near_grove)
    cam = OrbitCamera(target=(0.0, 1.4, 8.0), distance=3.0, elevation=4.0)
    near, far = passes_module.lod_band(r.tree_pass.leaf, 0.5 * H / np.tan(np.radians(cam.fov_y / 2)))

    faded, switched, triangles = band_sweeps(monkeypatch, offscreen, r, cam, "lod_band", near, far, np.linspace(0.6, 2.0, 29))
    assert triangles[0] < 0.8 * triangles[-1]  # the band swept past the trees
    assert faded < 0.6 * switched and faded < 12.0


def test_coarse_tubes_keep_every_other_side():
    tree = small_tree()
    mesh = build_mesh(tree)
    fine, coarse = mesh.part_indices("BARK"), coarse_tubes(mesh)
    assert 2 * len(coarse) == len(fine) and len(np.unique(np.sort(coarse, axis=1), axis=0)) == len(coarse)
    assert set(np.unique(coarse)) <= set(np.unique(fine))
    v = mesh.vertices["offset"].astype(float) + tree.rest_positions[mesh.vertices["ids"][:, 0]]

    def area(t):
        return np.linalg.norm(np.cross(v[t[:, 1]] - v[t[:, 0]], v[t[:, 2]] - v[t[:, 0]]), axis=1).sum() / 2

    assert 0.95 * area(fine) < area(coarse) < area(fine)  # an octagon's 0.90 of a circle, a 16-gon's 0.97


def test_the_shadow_map_follows_a_low_camera_with_finer_texels_that_stay_put(offscreen, wide_grove, monkeypatch):
    r = load(offscreen, wide_grove)
    render(offscreen, OrbitCamera(target=(0.0, 1.0, 0.0), distance=150.0, elevation=40.0))
    whole = r.shadow.texel
    assert r.shadow.window is None  # the whole scene in view: the map holds all of it
    texels, corners = [], []
    for x in (0.0, 0.05, 0.3):  # the viewer steps sideways
        img = render(offscreen, OrbitCamera(target=(x, 0.8, 0.0), distance=6.0, azimuth=20.0, elevation=12.0))
        texels.append(r.shadow.texel)
        corners.append(np.array(r.shadow.window)[[0, 2]])
    assert texels[0] < whole / 3 and texels == [texels[0]] * 3
    moved = (corners[2] - corners[0]) / texels[0]
    assert np.allclose(moved, np.round(moved), atol=1e-6)
    # The tree before the eye casts its shadow onto the ground at its foot, sharper (more of
    # its branches' shadows dark) than the whole scene's map draws it.
    cam = OrbitCamera(target=(0.3, 0.8, 0.0), distance=6.0, azimuth=20.0, elevation=12.0)
    r.scene.shadow = False
    lit = render(offscreen, cam).sum(axis=2)
    r.scene.shadow = True
    monkeypatch.setattr(shadow_module, "view_window", lambda *args: None)
    coarse = render(offscreen, cam).sum(axis=2)
    assert r.shadow.texel == whole
    followed, blurred = (lit - img.sum(axis=2) > 30).mean(), (lit - coarse > 30).mean()
    assert followed > max(1.5 * blurred, 0.002)


def test_the_view_window_holds_what_the_view_sees_of_the_receivers():
    rng = np.random.default_rng(1)
    sun = np.array([0.4, 0.85, 0.35])
    basis = sun_basis(sun)
    lo, hi = np.array([-30.0, 0.0, -30.0]), np.array([30.0, 4.0, 30.0])
    cam = OrbitCamera(target=(3.0, 1.2, -2.0), distance=9.0, azimuth=130.0, elevation=3.0)
    vp = cam.view_projection(W, H)
    planes = view_slice(vp, cam.eye, cam.forward, 14.0)
    x0, x1, y0, y1 = view_window(basis, seen_corners((lo, hi), planes), 1024, 200.0)
    assert x1 - x0 < 30.0
    p = lo + (hi - lo) * rng.random((200_000, 3))
    seen = p[np.all(p @ planes[:, :3].T + planes[:, 3] >= 0, axis=1)]
    assert len(seen) > 100
    x, y = seen @ basis[0], seen @ basis[1]
    assert x.min() >= x0 and x.max() <= x1 and y.min() >= y0 and y.max() <= y1
    # ... and the frustum's planes are the camera's: the target inside, the eye's back outside.
    inside = frustum_planes(vp)
    assert np.all(inside[:, :3] @ cam.target + inside[:, 3] > 0)
    assert np.any(inside[:, :3] @ (cam.eye - cam.forward) + inside[:, 3] < 0)


def test_twigs_far_thinner_than_a_shadow_texel_cast_no_shadow_and_are_not_missed(offscreen, wide_grove, monkeypatch):
    r = load(offscreen, wide_grove)
    cam = OrbitCamera(target=(0.0, 1.0, 0.0), distance=150.0, elevation=40.0)
    img = render(offscreen, cam)
    cast = r.drawn["shadow_triangles"]
    monkeypatch.setattr(renderer_module, "THIN_CASTER_TEXELS", 0.0)
    every = render(offscreen, cam)
    assert cast < 0.7 * r.drawn["shadow_triangles"]
    assert np.abs(img - every).mean() < 0.05 and np.percentile(np.abs(img - every).max(axis=2), 99.9) < 16


def test_far_grass_is_drawn_one_blade_a_clump_and_keeps_its_look(offscreen, meadow, monkeypatch):
    """Beyond the grass's band a clump is its simulated blade alone, drawn as wide as the clump's
    blades together: the meadow's colour, block by block, stays far closer to the full clumps'
    than the grass's own mark on the ground is large."""
    r = load(offscreen, meadow)
    cam = OrbitCamera(target=(0.0, 0.0, 0.0), distance=12.0, elevation=35.0)
    assert passes_module.blade_band(r.tree_pass.blade, pixels_per_metre(cam))[1] < 12.0 - 4.0  # all beyond it
    far = render(offscreen, cam)
    one = r.drawn["triangles"]
    monkeypatch.setattr(passes_module, "blade_band", lambda width, ppm: (1e30, 2e30))
    full = render(offscreen, cam)
    assert 3 * one == r.drawn["triangles"]  # a clump is three blades
    ground = render_background(offscreen, r, cam)
    mark, err = np.abs(blocks(full) - blocks(ground)).mean(), np.abs(blocks(far) - blocks(full)).mean()
    assert mark > 0.1 and err < 0.45 * mark  # copies dropped, the blade not widened: 0.57


def test_the_switch_to_one_blade_a_clump_does_not_pop(offscreen, meadow, monkeypatch):
    """The grass's band swept over the meadow from a still camera: each step fades the copies a
    little and widens the simulated blades a little, where a switch without the band drops two
    blades of three at once."""
    r = load(offscreen, meadow)
    cam = OrbitCamera(target=(0.0, 0.2, 0.0), distance=5.0, elevation=10.0)
    near, far = passes_module.blade_band(r.tree_pass.blade, pixels_per_metre(cam))

    faded, switched, triangles = band_sweeps(monkeypatch, offscreen, r, cam, "blade_band", near, far, np.linspace(0.3, 2.0, 35))
    assert triangles[0] < 0.5 * triangles[-1]  # the band swept past the meadow
    assert faded < 0.5 * switched and faded < 12.0


def test_a_lone_meadow_out_of_view_is_not_drawn(offscreen, grass):
    """A lone tree is drawn whole, but its grass square by square of the ground, those in view."""
    r = load(offscreen, grass)
    render(offscreen, OrbitCamera(target=(0.0, 0.2, 0.0), distance=3.0, elevation=20.0))
    assert r.drawn["triangles"] == r.tree_pass.ranges["BLADES"].total // 3 + r.tree_pass.ranges["BLADE_COPIES"].total // 3
    render(offscreen, OrbitCamera(target=(0.0, 0.5, 6.0), distance=3.0, azimuth=180.0, elevation=5.0))  # looking away
    assert r.drawn["triangles"] == 0


def test_a_view_that_sees_nothing_the_map_shades_draws_no_casters(offscreen, near_grove):
    r = load(offscreen, near_grove)
    cam = OrbitCamera(target=(0.0, 1.5, 26.0), distance=8.0, azimuth=180.0, elevation=5.0)  # from its edge, looking out
    img = render(offscreen, cam)
    assert r.drawn["trees"] == 0 and r.drawn["shadow_triangles"] == 0 and not r.shadow.seen
    r.scene.shadow = False
    try:
        lit = render(offscreen, cam)
    finally:
        r.scene.shadow = True
    assert np.array_equal(img, lit)
    # Turned round to face the grove: the casters in the sun's view of what it sees, again.
    render(offscreen, OrbitCamera(target=(0.0, 1.5, 4.0), distance=8.0, azimuth=0.0, elevation=5.0))
    assert r.shadow.seen and r.drawn["shadow_triangles"] > 0


def test_a_lone_tree_behind_the_camera_casts_nothing(offscreen, tree):
    r = load(offscreen, tree)
    render(offscreen, OrbitCamera(target=(0.0, 1.0, 0.0), distance=6.0, elevation=10.0))
    assert r.drawn["shadow_triangles"] > 0
    cam = OrbitCamera(target=(0.0, 1.5, 40.0), distance=8.0, azimuth=180.0, elevation=5.0)  # looking away
    img = render(offscreen, cam)
    assert r.drawn["shadow_triangles"] == 0
    r.scene.shadow = False
    try:
        assert np.array_equal(img, render(offscreen, cam))
    finally:
        r.scene.shadow = True


def test_an_offline_render_simulates_a_scene_at_the_viewers_detail(tmp_path, near_grove):
    """The trees of a scene far from the camera step coarse, as the viewer steps them (the
    picture is drawn by the same renderer: culled, far trees coarse)."""
    w, h = W, H
    sim = ta.Simulation(near_grove)
    job = RenderJob(Target("still", tmp_path / "grove.png"), w, h, fps=10.0, seconds=0.1, distance=120.0,
                    samples=0, quiet=True)
    run_render(job, near_grove, sim)
    cam = framed_camera(near_grove, w, h, distance=120.0)
    focal = h / (2.0 * np.tan(np.radians(cam.fov_y) / 2.0))
    expected = choose_detail(cam.eye, *tree_extents(near_grove), focal)
    assert expected.min() > 0 and np.array_equal(sim.detail, expected)
