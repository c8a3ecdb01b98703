"""Smooth wood (issue 30): a branch's axis has one tangent at each inner node, at rest and
bent (the CPU mirror of the GPU skinning), its rings turn evenly through a joint, a fork's
leaders grow out of its parent's end ring without a seam, and a twig thinning into a line runs
on without a gap (real renders through EGL)."""

from __future__ import annotations

import numpy as np
import pytest

import treeanim as ta
from conftest import identity, rot
from treeanim.model.build import ObjectSpec, assemble
from treeanim.model.look import Bark
from treeanim.render.camera import OrbitCamera
from treeanim.render.mesh import MATERIAL_BARK, build_mesh
from treeanim.render.scene import Scene
from treeanim.render.skinning import hermite, skin_points

TURN = 22.5  # degrees at each inner node, as the small cherry's limbs at rest


def crooked_limb():
    """A root limb of three 0.5 m segments turning TURN degrees at each inner node."""
    heading = np.radians(TURN) * np.arange(3)
    steps = 0.5 * np.stack([np.sin(heading), np.cos(heading), np.zeros(3)], 1)
    pts = np.concatenate([[[0.0, 0.0, 0.0]], np.cumsum(steps, axis=0)])
    return assemble([ObjectSpec(pts, np.array([0.08, 0.07, 0.06, 0.05]), "branch", 1)], name="crooked")


def bent_pose(tree, angle):
    """Every segment turned a further ``angle`` about z (and a little about x) from the one
    before: positions follow the segments' rotations."""
    P = tree.rest_positions
    R = np.array([rot((0.2, 0.0, 1.0), angle * (j + 1)) for j in range(tree.n_nodes)])
    pos = np.concatenate([P[:1], P[:1] + np.cumsum(np.einsum("jab,jb->ja", R[:-1], np.diff(P, axis=0)), axis=0)])
    return pos, R


def axis_tangents_at_inner_nodes(tree, mesh, positions, rotations, eps=1e-4):
    """The skinned axis's directions just before and just after each inner node."""
    v = mesh.vertices
    out = []
    for j in range(1, tree.n_nodes - 1):
        pair = []
        for node, t in ((j - 1, 1.0 - eps), (j, eps)):
            q = np.flatnonzero((mesh.node == node) & (v["curve"][:, 0] > 0) & (mesh.material == MATERIAL_BARK))[0]
            chord = tree.rest_positions[node + 1] - tree.rest_positions[node]
            rest = hermite(np.array([t]), chord[None], v["tangent0"][q:q + 1], v["tangent1"][q:q + 1])[0]
            pair.append(skin_points(positions, rotations, [node], [v["ids"][q, 1]], [v["extra"][q, 0]], [t],
                                    [v["curve"][q, 1] > 0.5], rest, v["tangent0"][q:q + 1],
                                    v["tangent1"][q:q + 1])[0][0])
        out.append((positions[j] - pair[0], pair[1] - positions[j]))
    return np.array(out)


def angles(a, b):
    cos = np.sum(a * b, axis=-1) / (np.linalg.norm(a, axis=-1) * np.linalg.norm(b, axis=-1))
    return np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))


def test_the_axis_has_one_tangent_at_each_inner_node_at_rest_and_bent():
    tree = crooked_limb()
    mesh = build_mesh(tree)
    for positions, rotations in ((tree.rest_positions, identity(tree)), bent_pose(tree, 0.35)):
        d = axis_tangents_at_inner_nodes(tree, mesh, positions, rotations)
        assert np.all(angles(d[:, 0], d[:, 1]) < 0.1), angles(d[:, 0], d[:, 1])


def test_the_rings_turn_evenly_through_a_joint():
    """The polyline through the tube's ring centres at rest turns less than 5° at every ring,
    the joints' 22.5° shared out between them (straight segments put all of it at the node)."""
    tree = crooked_limb()
    mesh = build_mesh(tree)
    pts, _ = mesh.skin(tree.rest_positions, identity(tree))
    bark = np.flatnonzero(mesh.material == MATERIAL_BARK)
    key = mesh.node[bark] + mesh.vertices["curve"][bark, 0]
    rings, inv, count = np.unique(key, return_inverse=True, return_counts=True)
    centres = np.stack([np.bincount(inv.ravel(), pts[bark, i]) for i in range(3)], 1) / count[:, None]
    centres = centres[count == 16]  # the end fans' centres are left out
    d = np.diff(centres, axis=0)
    corners = angles(d[1:], d[:-1])
    assert len(corners) >= 3 * 4 and corners.max() < 5.0, corners


def fork_rings(tree, mesh, leader):
    """Bark vertices of each leader's parent's end ring (its last segment at t = 1, with the tip
    fan's apex where there is one) and of the leader's first ring (its base node at t = 0, with
    the base fan's apex)."""
    t, bark = mesh.vertices["curve"][:, 0], mesh.material == MATERIAL_BARK
    for c in leader:
        p = tree.parent[c]
        yield (np.flatnonzero(bark & (mesh.object == p) & (mesh.node == tree.attach_node[c] - 1) & (t == 1)),
               np.flatnonzero(bark & (mesh.object == c) & (mesh.node == tree.object_start[c]) & (t == 0)))


def fork_seams(tree, children):
    """For branches on their parents' tips: how far each one's first ring lies from its
    parent's end ring (the largest distance from a vertex of the end ring to the nearest of the
    first ring's, over the parent's radius; at rest and after 0.5 s in a 25 m/s wind), the
    angle between the rings' planes and between the rest axis's tangents there (degrees), and
    the triangles lying within the two rings (caps: a tip fan, a base fan)."""
    mesh = build_mesh(tree)
    sim = ta.Simulation(tree, wind=ta.WindField(speed=25.0), model="paper")
    for _ in range(30):
        sim.step(1 / 60)
    rest, _ = mesh.skin(tree.rest_positions, identity(tree))
    posed, _ = mesh.skin(sim.positions, sim.rotations)
    tan = mesh.vertices["tangent1"], mesh.vertices["tangent0"]
    uses = np.bincount(mesh.indices.ravel(), minlength=mesh.vertex_count)

    def ring_of(v):  # without a fan's apex
        d = np.linalg.norm(rest[v] - rest[v].mean(axis=0), axis=1)
        return v[(uses[v] > 1) & (d > 0.5 * d.max())]

    seams, tilts, turns, caps = [], [], [], 0
    for end, first in fork_rings(tree, mesh, children):
        ring = [ring_of(v) for v in (end, first)]
        R = np.max(np.linalg.norm(rest[ring[0]] - rest[ring[0]].mean(axis=0), axis=1))
        for pts in (rest, posed):
            gap = np.linalg.norm(pts[ring[0]][:, None] - pts[ring[1]][None], axis=2)
            seams.append(np.max(np.min(gap, axis=1)) / R)
        normals = [np.linalg.svd(rest[v] - rest[v].mean(axis=0))[2][2] for v in ring]
        tilts.append(angles(normals[0], normals[1]) if normals[0] @ normals[1] > 0 else angles(normals[0], -normals[1]))
        turns.append(angles(tan[0][end[0]], tan[1][first[0]]))
        inside = np.zeros(mesh.vertex_count, bool)
        inside[np.r_[end, first]] = True
        caps += int(inside[mesh.indices].all(axis=1).sum())
    return max(seams), max(tilts), max(turns), caps


@pytest.mark.parametrize("name", ["small_cherry", "large_cherry"])
def test_a_forks_leader_grows_out_of_its_parent_without_a_seam(name):
    """Of the branches on a limb's tip, those turning at most 75° (Tree.fork_leaders) continue
    the limb's tube: each one's first ring is the limb's end ring, vertex for vertex, at rest
    and in a 25 m/s wind; the rings' planes agree within 0.5° (before: a collar tilted on the end ring), the
    rest axis's tangent runs on through the fork, and no cap lies between them."""
    tree = ta.load_preset(name)
    leader = tree.fork_leaders()[0]
    assert len(leader) >= 10
    seam, tilt, turn, caps = fork_seams(tree, leader)
    assert seam < 1e-3 and tilt < 0.5 and turn < 0.1 and caps == 0, (seam, tilt, turn, caps)


@pytest.mark.parametrize("name", ["small_cherry", "tulip_poplar"])
def test_an_even_forks_branches_grow_out_of_one_crotch(name):
    """Where two or more branches leave a limb's tip turning alike (within 20°, each by at most
    60°: no clear leader), every one of them continues the limb's tube from its end ring, so
    the fork is one crotch where their tubes part: no collar ring standing on the end ring, no
    cap between them (before: each kept a collar and the limb's end ring and tip fan showed)."""
    tree = ta.load_preset(name)
    chord = tree._chords()
    child = np.flatnonzero((tree.kind == "branch") & (tree.parent >= 0))
    tip = tree.object_start[tree.parent[child]] + tree.object_count[tree.parent[child]] - 1
    child, tip = child[tree.attach_node[child] == tip], tip[tree.attach_node[child] == tip]
    turn = np.degrees(np.arccos(np.clip(np.sum(chord[tip - 1] * chord[tree.object_start[child]], axis=1), -1, 1)))
    even = [child[tip == k] for k in np.unique(tip) if np.sum(tip == k) > 1
            and turn[tip == k].max() <= 60.0 and np.ptp(turn[tip == k]) <= 20.0]
    assert len(even) >= 5
    seam, tilt, turn, caps = fork_seams(tree, np.concatenate(even))
    assert seam < 1e-3 and tilt < 0.5 and turn < 0.1 and caps == 0, (seam, tilt, turn, caps)


def test_a_tube_thinning_into_a_line_runs_on_without_a_gap_in_the_woods_colour(offscreen):
    """A limb tapering from 8 px to a tenth of a pixel, side on against the sky, no MSAA: how
    much it darkens each column falls along it and never dips below the thinner columns after
    it (a flat cap and a gap showed where the tube handed over to the line); and the line,
    unblended from the sky by its true width, has the tube's colour (its mean across it)."""
    x = np.linspace(-1.5, 1.5, 7)
    pts = np.stack([x, np.full(7, 1.2), np.zeros(7)], 1)
    bark = Bark(color=(0.5, 0.47, 0.42), furrows=14.0, depth=0.55, interlace=0.9)  # the tulip poplar's
    tree = assemble([ObjectSpec(pts, np.geomspace(0.25, 0.003, 7), "branch", 1)], name="taper", bark=bark)
    cam = OrbitCamera(target=(0.0, 1.2, 0.0), distance=6.0, elevation=0.0)
    W, H = 200, 150
    off = type(offscreen)(W, H, samples=0, ctx=offscreen.ctx)
    try:
        off.load(tree, scene=Scene(shadow=False))
        R = identity(tree)
        off.update(tree.rest_positions, R, present=np.zeros(1, bool))
        sky = off.render(cam).astype(float)
        off.update(tree.rest_positions, R)
        img = off.render(cam).astype(float)
    finally:
        off.release()
    ends = cam.project(pts[[0, -1]], W, H)[:, 0]
    cols = np.arange(int(np.ceil(ends.min())) + 2, int(ends.max()) - 2)
    diff = (img - sky)[:, cols]
    cover = np.clip(-diff @ [0.2126, 0.7152, 0.0722], 0.0, None).sum(axis=0)
    assert len(cols) > 90 and np.all(cover > 2.0)
    later = np.array([cover[i + 1:i + 8].max() for i in range(len(cover) - 2)])
    assert np.all(cover[:-2] > 0.6 * later), np.flatnonzero(cover[:-2] <= 0.6 * later)
    # The colour: the tube's inner rows where it is over 5 px wide; the line's sum over each
    # column (its coverage there sums to its true width) where it is under a pixel.
    x = np.interp(cols, ends, pts[[0, -1], 0])
    d = np.interp(x, pts[:, 0], tree.node_diameter)
    width = np.abs(np.diff([cam.project(np.stack([x, 1.2 + s * d, 0 * x], 1), W, H)[:, 1] for s in (0.5, -0.5)],
                           axis=0)[0])
    tube = np.concatenate([img[np.flatnonzero(np.abs(diff[:, i]).max(axis=1) > 2)[1:-1], c]
                           for i, c in enumerate(cols) if width[i] > 5])
    line = sky[H // 2, cols] + diff.sum(axis=0) / width[:, None]
    assert len(tube) > 50 and np.sum(width < 1) > 30
    assert np.all(np.abs(line[width < 1].mean(axis=0) - tube.mean(axis=0)) < 8), (line[width < 1].mean(0), tube.mean(0))
