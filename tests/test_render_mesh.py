"""Render core without GL: mesh construction and CPU skinning, camera, picking."""

from __future__ import annotations

import re

import numpy as np
import pytest

from conftest import beam_tree, grass_patch, identity, rot, small_tree, twig_tree
from treeanim.model.geometry import unit as _unit
from treeanim.model.tree import curve_bands
from treeanim.render.camera import OrbitCamera
from treeanim.render.collars import tube_radius
from treeanim.render.mesh import (
    BLADE_CLUMP,
    MATERIAL_BARK,
    MATERIAL_LAMINA,
    MATERIAL_PETIOLE,
    VERTEX_ATTRIBUTES,
    VERTEX_DTYPE,
    VERTEX_FORMAT,
    build_mesh,
    drawn_triangles,
    lamina_frames,
)
from treeanim.render.picking import Picker, pick
from treeanim.render.shaders import shader_source
from treeanim.render.skinning import hermite


@pytest.fixture(scope="module", params=["tree", "grass", "beam"])
def any_tree(request):
    return {"tree": small_tree, "grass": grass_patch, "beam": beam_tree}[request.param]()


# ------------------------------------------------------------------------------ mesh
def test_triangle_counts_equal_tree_counts(any_tree):
    mesh = build_mesh(any_tree)
    assert np.array_equal(mesh.object_triangles, drawn_triangles(any_tree))
    assert mesh.triangle_count == int(drawn_triangles(any_tree).sum()) == len(mesh.indices)
    assert mesh.indices.dtype == np.uint32 and mesh.indices.max() < mesh.vertex_count
    # Every triangle belongs to one object (its three vertices share the object index), and
    # triangles come grouped by object, in object order.
    obj = mesh.object[mesh.indices]
    assert np.all(obj == obj[:, :1])
    expect = np.repeat(np.arange(any_tree.n_objects), mesh.object_triangles)
    assert np.array_equal(obj[:, 0], expect)
    assert np.array_equal(mesh.object_triangle_start[1:], np.cumsum(mesh.object_triangles)[:-1])


def test_a_blade_clump_casts_only_its_simulated_blades_shadow():
    """The copies of a clump are drawn, not shadowed: the shadow pass holds the simulated blades'
    strips and tips, whose vertices come first (a pair a node, then the apexes)."""
    from treeanim.render.shadow import shadow_indices

    grass = grass_patch()
    mesh = build_mesh(grass)
    tris = shadow_indices(mesh, grass)
    assert BLADE_CLUMP > 1 and mesh.triangle_count == BLADE_CLUMP * len(tris)
    assert len(tris) == grass.triangles_per_object().sum()
    assert tris.max() < 2 * grass.n_nodes + grass.n_objects


def test_per_kind_triangles_follow_the_papers_rule():
    tree = small_tree()
    mesh = build_mesh(tree)
    n = tree.object_count
    branch = tree.kind == "branch"
    leaf = tree.kind == "leaf"
    # Branch tubes: 2 x 16 triangles a band, at least four bands (a twig of one or two
    # segments is split along its curve; a crooked one in more, tests/test_model.py), plus two
    # 16-triangle end fans, but none where a fork's leader runs on from its parent.
    segments = n[branch] - 1
    bands = segments * curve_bands(n[branch], tree.joint_turn()[branch])
    assert np.all(bands >= np.minimum(4, segments * np.ceil(4 / segments)))
    lead = tree.fork_leaders()[0]
    fans = 2 - np.isin(np.arange(tree.n_objects), lead) - np.isin(np.arange(tree.n_objects), tree.parent[lead])
    assert len(lead) and np.all(mesh.object_triangles[branch] == 32 * bands + 16 * fans[branch])
    lam = len(tree.lamina.triangles)
    assert np.all(mesh.object_triangles[leaf] == 2 * tree.petiole_sides * (n[leaf] - 1) + lam)
    grass = grass_patch()
    gm = build_mesh(grass)
    # A blade: a strip with a tip triangle, drawn as a clump of BLADE_CLUMP (the paper counts one).
    assert np.all(gm.object_triangles == BLADE_CLUMP * (2 * (grass.object_count - 1) + 1))
    assert np.all(grass.triangles_per_object() == 2 * (grass.object_count - 1) + 1)


def test_vertex_layout():
    # The moderngl format, the attribute names, the numpy vertex and the vertex shader's inputs
    # describe the same interleaved layout, field by field, with no padding.
    groups = VERTEX_FORMAT.split()
    names = VERTEX_DTYPE.names
    assert len(groups) == len(VERTEX_ATTRIBUTES) == len(names)
    shader_inputs = dict((n, t) for t, n in re.findall(r"^\s*in\s+(\w+)\s+(\w+)\s*;", shader_source("tree.vert"),
                                                         re.M))
    offset = 0
    for group, attr, name in zip(groups, VERTEX_ATTRIBUTES, names):
        count, kind = int(group[:-1]), group[-1]
        dt, field_offset = VERTEX_DTYPE.fields[name]
        assert field_offset == offset, name
        assert dt.shape == (count,) and dt.base.itemsize == 4, name
        assert dt.base.kind == {"i": "i", "f": "f"}[kind], name
        assert attr == f"in_{name}"
        assert shader_inputs[attr] == {1: "", 2: "vec2", 3: "vec3", 4: "vec4"}[count].replace(
            "vec", "ivec" if kind == "i" else "vec"), attr
        offset += 4 * count
    assert VERTEX_DTYPE.itemsize == offset
    mesh = build_mesh(small_tree())
    v = mesh.vertices
    assert set(np.unique(mesh.material)) == {MATERIAL_BARK, MATERIAL_PETIOLE, MATERIAL_LAMINA}
    assert np.all(np.isin(v["extra"][:, 0], [0.0, 0.5, 1.0]))
    t, end = v["curve"][:, 0], v["curve"][:, 1]
    assert np.all((t >= 0) & (t <= 1)) and np.all(np.isin(end, [0.0, 1.0]))
    assert np.all((t == 0) | (mesh.material == MATERIAL_BARK))  # only branches curve
    assert np.all((end == 0) | (mesh.material == MATERIAL_BARK))
    assert np.all((v["extra"][:, 1] >= 0) & (v["extra"][:, 1] < 1))
    assert np.all((v["extra"][:, 2] > 0) & (v["extra"][:, 2] <= 1))
    assert np.allclose(np.linalg.norm(v["normal"], axis=1), 1, atol=1e-5)
    # All vertices of one object share its jitter (per-leaf colour).
    jit = v["extra"][:, 1]
    first = np.zeros(small_tree().n_objects)
    first[mesh.object] = jit
    assert np.array_equal(first[mesh.object], jit)


def test_mesh_is_deterministic():
    a, b = build_mesh(small_tree()), build_mesh(small_tree())
    assert a.vertices.tobytes() == b.vertices.tobytes()
    assert a.indices.tobytes() == b.indices.tobytes()


def test_rest_geometry():
    tree = small_tree()
    mesh = build_mesh(tree)
    pts, normals = mesh.skin(tree.rest_positions, identity(tree))
    node = mesh.node
    # Tube rings lie on the segments' rest curves at the tapering radius (the end fans' centres,
    # on the axis, are left out): one ring at every band's ends, but where a child's base ring
    # is its collar (tests/test_junctions.py; a fork's leader has none, tests/test_wood.py).
    P, r = tree.rest_positions, tube_radius(tree)  # a leader starts at its parent's end radius
    t = mesh.vertices["curve"][:, 0]
    obj = mesh.object
    lead = tree.fork_leaders()[0]
    assert len(lead)
    collar = (tree.parent[obj] >= 0) & ~np.isin(obj, lead) & (node == tree.object_start[obj]) & (t == 0)
    bark = np.flatnonzero((mesh.material == MATERIAL_BARK) & ~collar)
    j = node[bark]
    axis = P[np.minimum(j + 1, len(P) - 1)] - P[j]
    curve, tangent = hermite(t[bark], axis, mesh.vertices["tangent0"][bark], mesh.vertices["tangent1"][bark])
    centre = P[j] + curve
    axis = np.where(t[bark, None] > 0, tangent, axis)
    dist = np.linalg.norm(pts[bark] - centre, axis=1)
    ring = np.linalg.norm(np.cross(pts[bark] - centre, _unit(axis)), axis=1) > 1e-6
    branch = tree.kind == "branch"
    n = tree.object_count[branch]
    children = np.sum(branch & (tree.parent >= 0)) - len(lead)
    assert ring.sum() == 16 * (np.sum((n - 1) * curve_bands(n, tree.joint_turn()[branch]) + 1) - children)
    assert np.sum(collar & (mesh.material == MATERIAL_BARK)) == 2 * 16 * children  # rim and sunk apex
    radius = (1 - t[bark]) * r[j] + t[bark] * r[np.minimum(j + 1, len(P) - 1)]
    assert np.allclose(dist[ring], radius[ring], rtol=1e-5)
    inside = ring & (t[bark] > 0)  # rings inside a segment stand square to its curve
    assert inside.any() and np.allclose(np.sum((pts[bark] - centre)[inside] * axis[inside], axis=1), 0, atol=1e-7)
    # The lamina's tip (0, 1) sits one lamina length along the petiole's last segment.
    leaves = np.flatnonzero(tree.kind == "leaf")
    tipn, u, v, w = lamina_frames(tree, leaves)
    k_tip = int(np.flatnonzero(np.all(tree.lamina.outline == [0.0, 1.0], axis=1))[0])
    lam = mesh.material == MATERIAL_LAMINA
    K = len(tree.lamina.outline)
    lam_pts = pts[lam].reshape(len(leaves), K, 3)
    expect = tree.rest_positions[tipn] + tree.lamina_length[leaves, None] * v
    assert np.allclose(lam_pts[:, k_tip], expect, atol=1e-6)
    # The lamina's normal is the leaf's w at its midrib.
    lam_n = normals[lam].reshape(len(leaves), K, 3)
    assert np.allclose(lam_n[:, k_tip], w, atol=1e-5)
    # Blades: width = node diameter, across the blade's w axis.
    grass = grass_patch()
    gm = build_mesh(grass)
    gp, _ = gm.skin(grass.rest_positions, identity(grass))
    pairs = gp[: 2 * grass.n_nodes].reshape(-1, 2, 3)
    assert np.allclose(np.linalg.norm(pairs[:, 1] - pairs[:, 0], axis=1), grass.node_diameter, rtol=1e-5)


def test_rigid_motion_is_skinned_exactly():
    """Turn every node rigidly: every vertex turns with it, but the trunk's base, which the
    ground holds (its first segment curves away from the ground's frame)."""
    tree = small_tree()
    mesh = build_mesh(tree)
    rest_pts, rest_n = mesh.skin(tree.rest_positions, identity(tree))
    R = rot((0.3, 1.0, -0.2), 0.9)
    t = np.array([0.4, -0.1, 2.0])
    pts, normals = mesh.skin(tree.rest_positions @ R.T + t, np.broadcast_to(R, (tree.n_nodes, 3, 3)))
    ground = mesh.vertices["ids"][:, 1] == -1
    assert ground.any() and np.all(tree.parent[mesh.object[ground]] == -1)
    assert np.allclose(pts[~ground], rest_pts[~ground] @ R.T + t, atol=1e-6)
    assert np.allclose(normals[~ground], rest_n[~ground] @ R.T, atol=1e-6)
    held = ground & (mesh.vertices["curve"][:, 0] == 0)
    base = mesh.node[held]
    assert np.allclose(pts[held] - (tree.rest_positions[base] @ R.T + t), rest_pts[held] - tree.rest_positions[base])


def test_joint_rings_follow_both_segments():
    """Bend the beam at one inner node: the ring there turns half way, and keeps its radius."""
    tree = beam_tree()
    mesh = build_mesh(tree)
    P = tree.rest_positions
    j = 4
    R = rot((0, 0, 1), 0.6)
    positions = P.copy()
    positions[j + 1:] = P[j] + (P[j + 1:] - P[j]) @ R.T
    rotations = np.array(identity(tree))
    rotations[j:] = R
    pts, _ = mesh.skin(positions, rotations)
    ring = (mesh.node == j) & (mesh.material == MATERIAL_BARK)
    assert ring.sum() == 16
    offs = pts[ring] - positions[j]
    assert np.allclose(np.linalg.norm(offs, axis=1), 0.5 * tree.node_diameter[j], rtol=1e-5)
    half = rot((0, 0, 1), 0.3)
    assert np.allclose(offs, mesh.vertices["offset"][ring] @ half.T, atol=1e-6)
    # Rings away from the joint follow their own segment rigidly.
    after = (mesh.node == j + 2) & (mesh.material == MATERIAL_BARK)
    assert np.allclose(pts[after] - positions[j + 2], mesh.vertices["offset"][after] @ R.T, atol=1e-6)


def test_a_pulled_one_segment_twig_bends_as_a_rod():
    """Turn a one-segment twig's segment down by θ about its base (a pull at its tip): its tube
    leaves the trunk along the trunk's frame, sags t²(3 − t)/2 of the tip's drop at t (a
    cantilever under a tip load) and ends turned 1.5 θ, where a straight stick would hinge."""
    tree = twig_tree()
    mesh = build_mesh(tree)
    theta, L = 0.05, 0.6
    R = rot((0, 0, 1), -theta)
    P = tree.rest_positions.copy()
    rotations = np.array(identity(tree))
    base, tip = tree.object_start[1], tree.object_start[1] + 1
    P[tip] = P[base] + (P[tip] - P[base]) @ R.T
    rotations[base:] = R
    pts, normals = mesh.skin(P, rotations)
    twig = (mesh.object == 1) & (np.linalg.norm(np.cross(mesh.vertices["offset"], [1.0, 0, 0]), axis=1) > 1e-6)
    t = mesh.vertices["curve"][twig, 0]
    rings = np.unique(t)
    assert len(rings) == 5  # four bands (at t = 0 the collar, welded to the trunk)
    centre = np.array([P[base]] + [pts[twig][t == ti].mean(axis=0) for ti in rings[1:]])
    drop = centre[:, 1] - P[base, 1]
    assert np.allclose(drop, -L * np.sin(theta) * rings ** 2 * (3 - rings) / 2, atol=0.03 * L * theta)
    assert np.allclose(centre[:, 0] - P[base, 0], L * rings, atol=0.01 * L)
    # A straight stick's middle would sit at half the drop; the rod's sits at 5/16 of it.
    assert drop[2] == pytest.approx(-L * np.sin(theta) * 5 / 16, rel=0.03)

    def ring_axis(ti):  # the normal of the ring's plane, from its vertices' spread
        q = pts[twig][t == ti]
        return np.linalg.svd(q - q.mean(axis=0))[2][-1]

    collar = pts[twig][t == 0]  # welded to the trunk's frame, which has not turned
    rest, _ = mesh.skin(tree.rest_positions, identity(tree))
    assert np.allclose(collar, rest[twig][t == 0], atol=1e-12)
    tip_axis = ring_axis(1.0)
    assert np.degrees(np.arccos(abs(tip_axis @ [1.0, 0, 0]))) == pytest.approx(np.degrees(1.5 * theta), rel=0.02)


def test_mesh_of_a_leafy_tree():
    """The mesh of a tree with hundreds of leaves is complete (its build time is measured in
    benchmarks/bench_mesh.py, not asserted here)."""
    tree = small_tree(leaves_per_twig=60)
    assert (tree.kind == "leaf").sum() == 15 * 60
    mesh = build_mesh(tree)
    assert np.array_equal(mesh.object_triangles, tree.triangles_per_object())
    assert mesh.triangle_count == int(tree.triangles_per_object().sum()) == len(mesh.indices)
    assert mesh.indices.max() < mesh.vertex_count
    obj = mesh.object[mesh.indices]
    assert np.all(obj == obj[:, :1])
    assert np.array_equal(np.bincount(obj[:, 0], minlength=tree.n_objects), mesh.object_triangles)


# ------------------------------------------------------------------------------ camera
def test_camera_ray_passes_through_projected_point():
    cam = OrbitCamera(target=(0.2, 1.0, -0.1), distance=4.0, azimuth=35, elevation=20)
    rng = np.random.default_rng(0)
    for p in rng.uniform(-1, 2, size=(10, 3)):
        x, y, depth = cam.project(p, 320, 200)[0]
        o, d = cam.ray(x, y, 320, 200)
        assert np.isclose(np.linalg.norm(d), 1.0)
        off = (p - o) - ((p - o) @ d) * d
        assert np.linalg.norm(off) < 1e-6
    # The target projects to the centre.
    x, y, _ = cam.project(cam.target, 320, 200)[0]
    assert np.allclose([x, y], [160, 100], atol=1e-6)


def test_camera_frame_orbit_pan_zoom():
    cam = OrbitCamera(azimuth=-30, elevation=15)
    lo, hi = np.array([-1.0, 0.0, -0.5]), np.array([1.5, 3.0, 0.8])
    cam.frame((lo, hi), aspect=4 / 3)
    mid, half = 0.5 * (lo + hi), 0.5 * (hi - lo)
    a = np.linspace(0, 2 * np.pi, 7)
    ring = mid + np.stack([half[0] * np.cos(a), 0 * a, half[2] * np.sin(a)], 1)
    rim = np.concatenate([ring - [0, half[1], 0], ring + [0, half[1], 0]])  # on the inscribed cylinder
    xy = cam.project(rim, 400, 300)[:, :2]
    assert np.all((xy >= -1e-6) & (xy <= [400 + 1e-6, 300 + 1e-6]))
    assert (xy[:, 0].max() - xy[:, 0].min() > 0.8 * 400) or (xy[:, 1].max() - xy[:, 1].min() > 0.8 * 300)
    eye = cam.eye.copy()
    cam.orbit(90, 200)
    assert cam.elevation == 89.0 and np.isclose(np.linalg.norm(cam.eye - cam.target), cam.distance)
    assert np.linalg.norm(cam.eye - eye) > 0.5 * cam.distance  # the eye went over the top
    cam.orbit(0, -200)
    assert cam.elevation == -89.0
    d = cam.distance
    cam.zoom(0.5)
    assert np.isclose(cam.distance, 0.5 * d)
    cam = OrbitCamera(distance=5.0)
    p = cam.target + 0.3 * cam.right
    x0 = cam.project(p, 200, 100)[0, 0]
    cam.pan(10, 0, 100)
    assert np.isclose(cam.project(p, 200, 100)[0, 0] - x0, 10.0, atol=1e-3)


# ------------------------------------------------------------------------------ picking
def test_pick_hits_the_object_under_the_ray_and_misses_sky():
    tree = small_tree()
    P = tree.rest_positions
    picker = Picker(tree)
    cam = OrbitCamera(azimuth=10, elevation=5)
    cam.frame((P.min(0), P.max(0)), aspect=1.0)
    W = H = 400
    R = identity(tree)
    for i in range(0, tree.n_objects, 7):
        if tree.kind[i] != "branch":
            continue
        nodes = tree.object_nodes(i)
        mid = 0.5 * (P[nodes[len(nodes) // 2 - 1]] + P[nodes[len(nodes) // 2]])
        x, y, _ = cam.project(mid, W, H)[0]
        o, d = cam.ray(x, y, W, H)
        hit = picker.pick(P, R, o, d, pixel_angle=cam.pixel_angle(H), min_pixels=1.0)
        assert hit is not None
        # Whatever is hit is at or in front of the branch, and a branch hit is this one or
        # something nearer to the eye.
        assert hit.distance <= np.linalg.norm(mid - o) + 0.5 * tree.node_diameter.max() + 1e-6
        if hit.object != i:
            assert hit.distance < np.linalg.norm(mid - o)
    o, d = cam.ray(W / 2, 2, W, H)  # top centre: sky above the tree
    assert picker.pick(P, R, o, d + np.array([0, 1.0, 0]), pixel_angle=cam.pixel_angle(H)) is None


def test_pick_lamina_follows_pose_and_present_mask():
    tree = small_tree()
    P = tree.rest_positions
    leaf = int(np.flatnonzero(tree.kind == "leaf")[5])
    tipn, u, v, w = lamina_frames(tree, np.array([leaf]))
    centre = P[tipn[0]] + 0.5 * tree.lamina_length[leaf] * v[0]
    o = centre + 2.0 * w[0]
    d = -w[0]  # straight through the lamina
    R = identity(tree)
    hit = pick(tree, P, R, o, d)
    assert hit is not None and hit.object == leaf
    assert np.isclose(hit.distance, 2.0, atol=0.05)
    present = np.ones(tree.n_objects, bool)
    present[leaf] = False
    other = pick(tree, P, R, o, d, present=present)
    assert other is None or other.object != leaf
    # Move the whole tree: the same world ray misses, the moved one hits.
    shift = np.array([0.0, 0.0, 3.0])
    assert getattr(pick(tree, P + shift, R, o, d), "object", None) != leaf
    assert pick(tree, P + shift, R, o + shift, d).object == leaf


def test_pick_axis_runs_through_the_rings_the_mesh_draws():
    """The picker's axis points inside a segment are the centres of the mesh's rings there,
    skinned: on the curve the shader draws, not on the chord."""
    from treeanim.model.tree import BRANCH_SIDES
    from treeanim.physics.simulation import Simulation

    tree = small_tree()
    twig = int(np.flatnonzero(tree.level == tree.level.max())[0])
    sim = Simulation(tree)
    tip = tree.object_start[twig] + tree.object_count[twig] - 1
    sim.drag(twig, tree.rest_positions[tip] + (0.0, -0.3, 0.15))  # a hard bend
    for _ in range(60):
        sim.step(1 / 60)
    P, R = sim.positions, sim.rotations
    picker = Picker(tree)
    axis = picker.axis_points(P, R)
    mesh = build_mesh(tree)
    pts, _ = mesh.skin(P, R)
    bark = mesh.material == MATERIAL_BARK
    t_mesh = mesh.vertices["curve"][:, 0]
    inside = np.flatnonzero(picker.t > 0)
    assert len(inside) > 20
    r = tube_radius(tree)
    for q in inside:
        j, t = picker.node[q], picker.t[q]
        ring = pts[bark & (mesh.node == j) & np.isclose(t_mesh, t)]
        radius = (1 - t) * r[j] + t * r[j + 1]
        on_ring = np.isclose(np.linalg.norm(ring - axis[q], axis=1), radius, rtol=1e-4, atol=1e-6)
        assert on_ring.sum() == BRANCH_SIDES, (j, t)
    # ... which lie off the chords in this pose.
    j, t = picker.node[inside], picker.t[inside, None]
    off = np.linalg.norm(axis[inside] - ((1 - t) * P[j] + t * P[j + 1]), axis=1)
    assert off.max() > 0.002, off.max()  # millimetres: the control that this pose bends off the chords


def test_pick_thin_twigs_as_drawn_a_pixel_wider_and_behind_solid_surfaces():
    """A twig thinner than ``thin_pixels`` is drawn a pixel wider each side, behind every solid
    surface (shaders/tree.vert, DEPTH_THIN); a ray through a drawn surface picks it before one
    that only passes within ``min_pixels`` of something nearer."""
    from treeanim.model.build import ObjectSpec, assemble

    x = np.linspace(-1.0, 1.0, 5)[:, None]
    trunk = ObjectSpec(np.array([[0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 2.0, 0.0]]), np.full(3, 0.2))
    thin = ObjectSpec(np.hstack([x, np.ones_like(x), np.full_like(x, 0.5)]), np.full(5, 0.004))
    tree = assemble([trunk, thin], name="crossing")
    picker = Picker(tree)
    P, R = tree.rest_positions, identity(tree)
    eye, d = np.array([0.0, 1.0, 5.0]), np.array([0.0, 0.0, -1.0])
    angle = 1e-3  # a pixel: 4.5 mm at the twig (radius 2 mm, under 1.5 px), 5 mm at the trunk

    def hit(at, **kw):
        h = picker.pick(P, R, eye + at, d, pixel_angle=angle, **kw)
        return None if h is None else h.object

    assert hit([0.0, 0.0, 0.0]) == 1  # the nearest surface
    assert hit([0.0, 0.0, 0.0], thin_pixels=1.5) == 0  # the thin twig is drawn behind the trunk
    assert hit([0.5, 0.0, 0.0], thin_pixels=1.5) == 1  # over the sky it shows
    # Drawn a pixel wider each side: 2 mm + 1 px (4.5 mm) from its axis.
    assert hit([0.5, 0.006, 0.0], thin_pixels=1.5, min_pixels=0.0) == 1
    assert hit([0.5, 0.006, 0.0], min_pixels=0.0) is None
    assert hit([0.5, 0.009, 0.0], thin_pixels=1.5, min_pixels=0.0) is None
    # 3 px beside the twig (within its 4 px reach) the trunk behind it is drawn: it is picked;
    # over the sky, the twig.
    assert hit([0.0, 0.0135, 0.0]) == 0
    assert hit([0.5, 0.0135, 0.0]) == 1


def test_pick_reaches_a_blades_apex():
    """A blade ends in a triangle to an apex half its last segment beyond its tip."""
    tree = grass_patch()
    picker = Picker(tree)
    P, R = tree.rest_positions, identity(tree)
    blade = 7
    tip = tree.object_start[blade] + tree.object_count[blade] - 1
    point = P[tip] + 0.3 * (P[tip] - P[tip - 1])  # 0.6 of the way to the apex
    w = tree.rest_w[blade]
    present = np.arange(tree.n_objects) == blade
    hit = picker.pick(P, R, point + w, -w, present=present, min_pixels=0.0)
    assert hit is not None and hit.object == blade
    assert picker.pick(P, R, point + w + 0.02 * _unit(P[tip] - P[tip - 1]), -w, present=present,
                       min_pixels=0.0) is None


# ------------------------------------------------------------------------------ small pieces
def test_pull_trace_ring_buffer_keeps_the_newest_in_order():
    from treeanim.render.overlays import PullTrace

    tr = PullTrace(capacity=5)
    assert tr.lines(small_tree()) is None
    tr.push((0.0, 0.0, 0.0))
    tr.extend(np.arange(1, 8)[:, None] * np.ones(3))
    assert len(tr) == 5
    assert np.array_equal(tr.points[:, 0], [3, 4, 5, 6, 7])
    ls = tr.lines(small_tree())
    assert len(ls.points) == 8 and np.all(np.diff(ls.colors[:, 3]) >= 0)  # fading with age
    tr.clear()
    assert len(tr) == 0


def test_render_package_exports_lazily():
    import treeanim.render as render

    for name in render.__all__:
        assert getattr(render, name) is not None


def test_the_mesh_parts_hold_every_triangle_once(any_tree):
    """The renderer draws the mesh part by part (mesh.PARTS, a program each): every triangle is
    in exactly one part, the part of its material."""
    from treeanim.render.mesh import PARTS

    mesh = build_mesh(any_tree)
    parts = [mesh.part_indices(name) for name in PARTS]
    assert sum(len(p) for p in parts) == mesh.triangle_count
    together = np.concatenate(parts)
    assert np.array_equal(np.unique(together, axis=0), np.unique(mesh.indices, axis=0))
    for name, p in zip(PARTS, parts):
        assert np.isin(mesh.material[p], PARTS[name]).all()
