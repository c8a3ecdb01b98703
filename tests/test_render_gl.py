"""The renderer tested by the pixels of real renders through EGL (Mesa llvmpipe in CI)."""

from __future__ import annotations

import dataclasses

import moderngl
import numpy as np
import pytest

from conftest import grass_patch, rest_pose, rot, small_tree
from treeanim.render.camera import OrbitCamera
from treeanim.render.offscreen import OffscreenRenderer, create_egl_context
from treeanim.render.overlays import LocalFrames, PullTrace, WindArrow, WindSlices
from treeanim.render.renderer import Renderer
from treeanim.render.shaders import shader_source

W, H = 160, 120


def framed_camera(renderer, aspect=W / H, **kw):
    cam = OrbitCamera(azimuth=0.0, elevation=5.0, **kw)
    cam.frame(renderer.bounds(), aspect=aspect)
    return cam


def changed(a, b, thr=24):
    """Pixels where two images differ noticeably."""
    return np.abs(a.astype(int) - b.astype(int)).max(axis=2) > thr


@pytest.fixture()
def scene(offscreen, tree):
    offscreen.resize(W, H)
    r = offscreen.load(tree)
    return offscreen, r, framed_camera(r)


def background(off, r, cam, season=0.0):
    off.update(*rest_pose(r.tree), present=np.zeros(r.tree.n_objects, bool))
    img = off.render(cam, season=season)
    off.update(*rest_pose(r.tree))
    return img


# ------------------------------------------------------------------------------ basics
def test_shader_sources_expand_includes():
    src = shader_source("tree.vert")
    assert "#include" not in src and "node_transform" in src and src.startswith("#version 330 core")
    assert "#include" not in shader_source("line.vert")


def test_the_shaders_take_their_material_ids_and_colours_from_python():
    import re

    from treeanim.render import mesh, palette

    for name in ("tree.vert", "tree.frag"):
        src = shader_source(name)
        for material in ("BARK", "PETIOLE", "LAMINA", "BLADE"):
            assert f"const int {material} = {getattr(mesh, 'MATERIAL_' + material)};" in src
        assert not re.search(r"v_material\s*[!=]=\s*\d", src), "a material id written by hand"
    vert = shader_source("tree.vert")
    for name, (r, g, b) in palette.COLOURS.items():
        assert f"const vec3 C_{name} = vec3({r!r}, {g!r}, {b!r});" in vert
    body = vert.split("void main()")[0].split("const vec3 C_BLADE_WINTER")[1]
    assert not re.search(r"lin\(vec3\(\d", body), "a colour written by hand in the shader"


def test_tree_is_drawn_where_the_camera_looks(scene):
    off, r, cam = scene
    img = off.render(cam)
    assert img.shape == (H, W, 3) and img.dtype == np.uint8
    bg = background(off, r, cam)
    mask = changed(img, bg)
    assert mask.sum() > 0.03 * W * H, mask.sum()
    ys, xs = np.nonzero(mask)
    assert abs(xs.mean() - W / 2) < 0.15 * W and abs(ys.mean() - H / 2) < 0.2 * H
    # Tree pixels are in the middle; the border columns stay background.
    assert mask[:, : W // 10].mean() < 0.02 and mask[:, -W // 10:].mean() < 0.02
    # Sky at the top: blue above red; ground at the bottom: green above blue.
    top = bg[:8].reshape(-1, 3).astype(float).mean(0)
    bottom = bg[-8:].reshape(-1, 3).astype(float).mean(0)
    assert top[2] > top[0] + 20 and top[2] > 150, top
    assert bottom[1] > bottom[2] + 20, bottom
    # Leaves: green tree pixels; bark: brownish (red > blue) tree pixels.
    px = img[mask].astype(float)
    green = (px[:, 1] > px[:, 0] + 10) & (px[:, 1] > px[:, 2] + 10)
    brown = (px[:, 0] > px[:, 2] + 8) & (px[:, 0] >= px[:, 1] - 5)
    assert green.mean() > 0.15 and brown.mean() > 0.05, (green.mean(), brown.mean())


def test_pose_moves_pixels_and_matches_a_rotated_tree(offscreen):
    """Skinning a rigid rotation of the rest pose draws what a pre-rotated tree draws at rest."""
    offscreen.resize(W, H)
    tree = small_tree()
    r = offscreen.load(tree)
    cam = framed_camera(r)
    cam.distance *= 1.3
    rest_img = offscreen.render(cam)
    bg = background(offscreen, r, cam)
    R = rot((0, 0, 1), -0.35)  # lean towards +x (to the right on screen)
    P, I = rest_pose(tree)
    offscreen.update(P @ R.T, np.broadcast_to(R, I.shape))
    bent = offscreen.render(cam)
    m_rest, m_bent = changed(rest_img, bg), changed(bent, bg)
    assert (m_rest ^ m_bent).sum() > 0.2 * m_rest.sum()
    assert np.nonzero(m_bent)[1].mean() > np.nonzero(m_rest)[1].mean() + 3

    # The same tree built rotated, drawn at rest: same silhouette.
    rotated = dataclasses.replace(tree, rest_positions=P @ R.T, rest_w=tree.rest_w @ R.T)
    with offscreen.ctx:
        r2 = Renderer(offscreen.ctx, rotated)
    ref = offscreen.render(cam, renderer=r2)
    with offscreen.ctx:
        r2.release()
    m_ref = changed(ref, bg)
    iou = (m_ref & m_bent).sum() / (m_ref | m_bent).sum()
    assert iou > 0.9, iou

    # A pure displacement moves pixels too.
    offscreen.update(P + [0.0, 0.4, 0.0], I)
    up = offscreen.render(cam)
    assert np.nonzero(changed(up, bg))[0].mean() < np.nonzero(m_rest)[0].mean() - 3


def test_inner_joint_bend_keeps_the_tube_closed(offscreen):
    """Bend the trunk at one joint: no gap opens there (skinned rings follow both segments)."""
    from conftest import beam_tree

    offscreen.resize(W, H)
    tree = beam_tree()
    r = offscreen.load(tree)
    cam = framed_camera(r)
    P, I = rest_pose(tree)
    j = 4
    R = rot((0, 0, 1), -0.8)
    pos = P.copy()
    pos[j + 1:] = P[j] + (P[j + 1:] - P[j]) @ R.T
    rots = np.array(I)
    rots[j:] = R
    offscreen.update(pos, rots)
    img = offscreen.render(cam)
    bg = background(offscreen, r, cam)
    mask = changed(img, bg)
    # Walk along the bent axis on screen across the joint: every sample is covered by the tube.
    axis_pts = np.concatenate([np.linspace(pos[k], pos[k + 1], 12) for k in (j - 1, j)])
    xy = cam.project(axis_pts, W, H)[:, :2].astype(int)
    assert np.all((xy >= 0) & (xy < [W, H]))
    assert mask[xy[:, 1], xy[:, 0]].all()


def test_a_hard_pulled_one_segment_twig_is_drawn_as_a_curve(offscreen):
    """Pull a one-segment twig's tip down with the simulation: the drawn twig leaves the trunk
    level and bows above its chord (a rod under a tip load, not a stick hinged at the trunk),
    where the CPU skinning puts it."""
    from conftest import twig_tree
    from treeanim.physics.simulation import Simulation

    offscreen.resize(W, H)
    tree = twig_tree()
    r = offscreen.load(tree)
    sim = Simulation(tree, model="paper")  # the paper's bent beam: its tip frame turns past the chord
    sim.pull(1, (0.0, -600.0, 0.0))
    for _ in range(300):
        sim.step(1 / 60)
    P, R = sim.positions, sim.rotations
    base, tip = P[tree.object_start[1]], P[tree.object_start[1] + 1]
    assert 25 < np.degrees(np.arctan2(base[1] - tip[1], tip[0] - base[0])) < 60  # the chord's slope
    cam = OrbitCamera(target=0.5 * (base + tip), distance=1.2, azimuth=0.0, elevation=0.0)
    bg = background(offscreen, r, cam)
    offscreen.update(P, R, present=np.array([False, True]))  # the twig alone
    twig = changed(offscreen.render(cam), bg)
    (bx, by), (tx, ty) = cam.project(np.array([base, tip]), W, H)[:, :2]
    cols = np.arange(int(bx) + 4, int(tx) - 4)
    assert len(cols) > 40
    rows = np.array([np.nonzero(twig[:, c])[0].mean() for c in cols])
    chord = by + (cols + 0.5 - bx) * (ty - by) / (tx - bx)
    bow = chord - (rows + 0.5)  # pixels above the chord (image rows grow downwards)
    assert bow.max() > 4, bow.max()
    assert 0.25 < np.argmax(bow) / len(cols) < 0.6  # widest at 0.42 of the way, as a rod's
    # The GPU draws where TreeMesh.skin puts the twig's axis.
    mesh = r.mesh
    pts, _ = mesh.skin(P, R)
    t = mesh.vertices["curve"][:, 0]
    inner = [pts[(mesh.object == 1) & (t == ti)].mean(axis=0) for ti in (0.25, 0.5, 0.75)]
    for x, y in cam.project(np.array(inner), W, H)[:, :2]:
        drawn = np.nonzero(twig[:, int(x)])[0].mean() + 0.5
        assert abs(drawn - y) < 1.0, (x, y, drawn)


def test_a_bent_beam_is_picked_where_it_is_drawn(offscreen):
    """Issue 26: a press on the drawn beam grabs it. The beam preset in one segment (drawn in
    four bands along its Hermite curve), pulled sideways by the simulation: every pixel the
    drawn beam covers picks it, though the segment's chord runs far beside it."""
    import treeanim as ta
    from treeanim.model.generate import generate
    from treeanim.model.presets import read_spec
    from treeanim.physics.simulation import Simulation
    from treeanim.render.camera import framed_camera as frame
    from treeanim.render.picking import Picker

    w, h = 320, 240
    spec = read_spec(ta.load_preset("beam").source)
    tree = generate(dataclasses.replace(spec, beam=dataclasses.replace(spec.beam, segments=1)))
    sim = Simulation(tree, model="paper")  # a hard bend from a pull
    sim.pull(0, (30.0, 0.0, 0.0))
    for _ in range(30):
        sim.step(1 / 60)
    P, R = sim.positions, sim.rotations
    offscreen.resize(w, h)
    r = offscreen.load(tree)
    cam = frame(tree, w, h)
    bg = background(offscreen, r, cam)
    offscreen.update(P, R)
    beam = changed(offscreen.render(cam), bg)

    (bx, by), (tx, ty) = cam.project(P, w, h)[:, :2]
    assert tx > bx + 40  # bent well to the right
    picker = Picker(tree)
    gaps = []
    for y in np.linspace(ty, by, 10)[1:-2].astype(int):  # clear of the tip and of the shadow at the base
        cols = np.flatnonzero(beam[y])
        assert len(cols) and np.ptp(cols) == len(cols) - 1, (y, cols)  # one run of covered pixels
        for x in cols:
            o, d = cam.ray(x + 0.5, y + 0.5, w, h)
            hit = picker.pick(P, R, o, d, pixel_angle=cam.pixel_angle(h), min_pixels=4.0)
            assert hit is not None and hit.object == 0, (x, y)
            assert np.hypot(*(cam.project(hit.point, w, h)[0, :2] - (x + 0.5, y + 0.5))) < 5.0
        chord_x = bx + (y + 0.5 - by) * (tx - bx) / (ty - by)
        gaps.append(abs(chord_x - 0.5 * (cols[0] + cols[-1] + 1)) - 0.5 * len(cols))
    # The chord's capsule (4 px around it) misses the drawn beam on most of these rows.
    assert np.sum(np.array(gaps) > 6.0) >= len(gaps) // 2, gaps


# ------------------------------------------------------------------------------ leaves, season
def bare(off, r, cam, season=0.0):
    """The tree with every leaf hidden."""
    off.update(*rest_pose(r.tree), present=r.tree.kind != "leaf")
    img = off.render(cam, season=season)
    off.update(*rest_pose(r.tree))
    return img


def leaf_pixels(img, bare_img):
    """Colours of the pixels that the leaves change."""
    return img[changed(img, bare_img)].astype(float)


def test_hidden_leaves_show_far_fewer_leaf_pixels(scene):
    off, r, cam = scene
    tree = r.tree
    bg = background(off, r, cam)
    no_leaves = bare(off, r, cam)
    off.update(*rest_pose(tree))  # present from the season
    summer = leaf_pixels(off.render(cam, season=0.0), no_leaves)
    off.update(*rest_pose(tree), present=tree.leaves_present(1.0))
    winter_mask = leaf_pixels(off.render(cam, season=0.0), no_leaves)
    off.update(*rest_pose(tree))
    winter_season = leaf_pixels(off.render(cam, season=1.0), bare(off, r, cam, season=1.0))
    assert len(summer) > 200
    assert len(winter_mask) < 0.25 * len(summer), (len(winter_mask), len(summer))
    assert len(winter_season) < 0.25 * len(summer), (len(winter_season), len(summer))
    # Hiding everything leaves only the background.
    off.update(*rest_pose(tree), present=np.zeros(tree.n_objects, bool))
    assert not changed(off.render(cam), bg).any()


def test_season_turns_leaves_from_green_to_autumn_colours(scene):
    off, r, cam = scene
    tree = r.tree
    everything = np.ones(tree.n_objects, bool)
    ratios = []
    for season in (0.0, 0.35, 0.7):
        no_leaves = bare(off, r, cam, season)
        off.update(*rest_pose(tree), present=everything)
        px = leaf_pixels(off.render(cam, season=season), no_leaves)
        assert len(px) > 200
        ratios.append(float(np.mean(px[:, 0] / np.maximum(px[:, 1], 1.0))))
    assert ratios[0] < 0.8, ratios  # summer: green
    assert ratios[1] > ratios[0] + 0.15 and ratios[2] > ratios[1] + 0.1, ratios
    assert ratios[2] > 1.1, ratios  # autumn: red/orange over green


def test_blades_render(offscreen):
    offscreen.resize(W, H)
    grass = grass_patch()
    r = offscreen.load(grass)
    cam = framed_camera(r)
    img = offscreen.render(cam)
    bg = background(offscreen, r, cam)
    assert changed(img, bg, thr=12).sum() > 0.02 * W * H


def test_highlight_tints_the_object(scene):
    off, r, cam = scene
    base = off.render(cam)
    off.update(*rest_pose(r.tree), highlight=0)  # the trunk
    lit = off.render(cam)
    off.update(*rest_pose(r.tree))
    diff = changed(lit, base)
    assert diff.sum() > 30
    px = lit[diff].astype(float)
    assert np.mean(px[:, 0] - px[:, 1]) > 60 and np.mean(px[:, 2] - px[:, 1]) > 60  # violet
    assert not changed(off.render(cam), base).any()


def test_the_highlight_stands_apart_from_every_leaf_blade_and_bark_colour():
    """Issue 31: the orange highlight vanished among autumn leaves. Its hue is now at least 60°
    from every colour of the palette, summer's greens through autumn's reds, and from the
    presets' bark."""
    import colorsys

    from treeanim.model.presets import list_presets, load_preset
    from treeanim.render import palette

    def hue(rgb):
        return 360.0 * colorsys.rgb_to_hsv(*rgb)[0]

    h = hue(palette.HIGHLIGHT)
    others = [c for n, c in palette.COLOURS.items() if n != "HIGHLIGHT"]
    others += [load_preset(p).bark.color for p in list_presets()]
    for rgb in others:
        d = abs(h - hue(rgb)) % 360.0
        assert min(d, 360.0 - d) >= 60.0, (rgb, hue(rgb), h)


# ------------------------------------------------------------------------------ overlays
def _overlays(tree, renderer):
    lo, hi = renderer.bounds()
    trace = PullTrace(capacity=150)
    top = tree.rest_positions[tree.object_start[0] + tree.object_count[0] - 1]
    t = np.linspace(0, 6, 200)[:, None]
    trace.extend(top + 0.6 * np.concatenate([np.sin(3 * t), 0.5 * np.cos(t), np.sin(2 * t)], 1))
    assert len(trace) == 150
    wind = lambda p: np.stack([2.0 + np.sin(p[:, 1]), 0.3 * np.cos(p[:, 0]), 0.5 * np.sin(p[:, 2])], 1)  # noqa: E731
    return {
        "trace": trace,
        "frames": LocalFrames(),
        "slices": WindSlices(wind, (lo, hi), resolution=6),
        "arrow": WindArrow((1.0, 0.0, 0.3), 6.0, origin=lo + [0.0, 0.2, 0.0], length=0.5 * (hi - lo)[0]),
    }


@pytest.mark.parametrize("name", ["trace", "frames", "slices", "arrow"])
def test_each_overlay_adds_pixels(scene, name):
    off, r, cam = scene
    ov = _overlays(r.tree, r)[name]
    plain = off.render(cam)
    with_ov = off.render(cam, overlays=[ov])
    added = changed(with_ov, plain, thr=30).sum()
    assert added > 40, added
    assert not changed(off.render(cam), plain).any()  # gone when not asked for


def test_frames_overlay_follows_the_pose(scene):
    off, r, cam = scene
    ov = LocalFrames(kinds=("branch",))
    P, I = rest_pose(r.tree)
    a = off.render(cam, overlays=[ov])
    R = rot((0, 0, 1), 0.4)
    off.update(P @ R.T, np.broadcast_to(R, I.shape))
    b = off.render(cam, overlays=[ov])
    off.update(P, I)
    plain_b = off.render(cam)
    assert changed(a, b).sum() > 100
    assert changed(b, plain_b).sum() > 40


# ------------------------------------------------------------------------------ sizes, lifetime
def test_resize_to_odd_sizes_tiny_and_empty(offscreen, tree):
    r = offscreen.load(tree)
    for w, h in [(161, 97), (33, 201), (1, 1), (0, 0), (5, 0), (64, 48)]:
        offscreen.resize(w, h)
        cam = framed_camera(r, aspect=max(w, 1) / max(h, 1))
        img = offscreen.render(cam, overlays=[LocalFrames()])
        assert img.shape == (h, w, 3)
        if w * h:
            assert img.any()
    offscreen.resize(W, H)


def test_zero_viewport_draw_is_a_no_op(offscreen, tree):
    offscreen.resize(W, H)
    r = offscreen.load(tree)
    cam = framed_camera(r)
    first = offscreen.render(cam)
    with offscreen.ctx:
        offscreen.fbo.use()
        r.draw(cam, 0, 0)
        r.draw(cam, 0, 17)
        offscreen.ctx.copy_framebuffer(offscreen.resolve_fbo, offscreen.fbo)
        raw = np.frombuffer(offscreen.resolve_fbo.read(components=3, alignment=1), np.uint8)
    assert np.array_equal(raw.reshape(H, W, 3)[::-1], first)


def test_renderer_on_a_plain_context_and_release(tree):
    ctx = create_egl_context()
    try:
        ctx.__enter__()
        r = Renderer(ctx, tree)
        fbo = ctx.simple_framebuffer((W, H))
        cam = framed_camera(r)
        r.update(*rest_pose(tree))
        r.draw(cam, W, H, framebuffer=fbo, overlays=[LocalFrames()])
        img = np.frombuffer(fbo.read(components=3), np.uint8).reshape(H, W, 3)
        assert img.std() > 5
        r.release()
        r.release()  # idempotent
        with pytest.raises(RuntimeError):
            r.draw(cam, W, H)
        assert ctx.error == "GL_NO_ERROR"
    finally:
        ctx.__exit__(None, None, None)
        ctx.release()


@pytest.mark.parametrize("fail_at", ["line program", "ground"])
def test_renderer_frees_what_it_made_when_construction_fails(tree, monkeypatch, fail_at):
    """A failure part-way through Renderer() (a shader that does not build, any later step)
    leaves no GL object behind: everything made before it is released."""
    import treeanim.render.passes as passes_module

    ctx = create_egl_context()
    made = []

    def recording(make):
        def wrapper(*a, **k):
            obj = make(*a, **k)
            made.append(obj)
            return obj
        return wrapper

    for name in ("program", "buffer", "texture", "vertex_array"):
        monkeypatch.setattr(ctx, name, recording(getattr(ctx, name)))
    load_program = passes_module.load_program

    def failing_load(c, vertex, *rest, **kw):
        if fail_at == "line program" and vertex == "line.vert":
            raise RuntimeError("shader program line.vert + line.frag failed to build: (test)")
        return load_program(c, vertex, *rest, **kw)

    def failing_ground(self, *a):
        raise MemoryError("(test)")

    monkeypatch.setattr(passes_module, "load_program", failing_load)
    if fail_at == "ground":  # the last pass made: after programs, buffers, textures and vertex arrays
        monkeypatch.setattr(passes_module.GroundPass, "_place", failing_ground)
    try:
        with ctx:
            with pytest.raises(RuntimeError if fail_at == "line program" else MemoryError):
                Renderer(ctx, tree)
            kinds = {type(o).__name__ for o in made}
            assert kinds >= ({"Program"} if fail_at == "line program" else {"Program", "Buffer", "Texture",
                                                                             "VertexArray"})
            alive = [o for o in made if type(o.mglo).__name__ != "InvalidObject"]
            assert not alive, f"left behind: {alive}"
            assert ctx.error == "GL_NO_ERROR"
    finally:
        ctx.release()


def test_missing_egl_is_a_clear_runtime_error(monkeypatch):
    def fail(*a, **k):
        raise Exception("eglGetDisplay failed\n(no display)")

    monkeypatch.setattr(moderngl, "create_standalone_context", fail)
    with pytest.raises(RuntimeError) as err:
        OffscreenRenderer(8, 8)
    msg = str(err.value)
    assert "\n" not in msg and "EGL" in msg and "3.3" in msg


def test_renderer_refuses_old_gl(tree):
    class Old:
        version_code = 210

    with pytest.raises(RuntimeError, match="3.3"):
        Renderer(Old(), tree)


def test_no_gl_errors_after_a_frame(scene):
    off, r, cam = scene
    off.render(cam, overlays=list(_overlays(r.tree, r).values()))
    with off.ctx:
        assert off.ctx.error == "GL_NO_ERROR"


def test_the_depths_the_renderer_draws_at_keep_their_order():
    """Thin twigs, then the ground over the shadow's footprint, then the rest of the ground, then
    the sky, each 25 or more steps of a 24-bit depth buffer behind the one before (window depth
    = (NDC z + 1) / 2)."""
    from treeanim.render.shaders import DEPTH_FOOTPRINT, DEPTH_GROUND, DEPTH_THIN

    steps = [(z + 1.0) / 2.0 * 2**24 for z in (DEPTH_THIN, DEPTH_FOOTPRINT, DEPTH_GROUND, 1.0)]
    assert all(b - a >= 25 for a, b in zip(steps, steps[1:])), np.diff(steps)
