"""glTF export: the Khronos validator accepts the files (no errors, no warnings), and they play back the
simulation."""

import io
import json
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

import treeanim as ta
from gltf_readback import attribute, clip, joint_world_positions, load, play, skinned_vertices, triangles
from treeanim import scripted
from treeanim.export import local_rotations, skeleton

ROOT = Path(__file__).resolve().parents[1]
NODE_MODULES = Path(os.environ.get("TREEANIM_NODE_MODULES", ROOT / ".venv" / "node" / "node_modules"))


def validate(path):
    """Issues reported by the Khronos glTF Validator (installed by scripts/test with npm)."""
    assert (NODE_MODULES / "gltf-validator").is_dir(), f"gltf-validator is not installed in {NODE_MODULES}: run scripts/test"
    res = subprocess.run(["node", str(ROOT / "tests" / "gltf_validate.js"), str(path)], capture_output=True, text=True,
                         env=dict(os.environ, NODE_PATH=str(NODE_MODULES)), timeout=600)
    assert res.returncode == 0, res.stderr
    return json.loads(res.stdout)


def three(path, times):
    """The file played by three.js (tests/gltf_three.mjs, in Node): the clip's duration and every
    skinned vertex (V, 3) at each of ``times``."""
    assert (NODE_MODULES / "three").is_dir(), f"three is not installed in {NODE_MODULES}: run scripts/test"
    res = subprocess.run(["node", str(ROOT / "tests" / "gltf_three.mjs"), str(path), *map(str, times)], capture_output=True,
                         text=True, env=dict(os.environ, NODE_PATH=str(NODE_MODULES.resolve())), timeout=600)
    assert res.returncode == 0, res.stderr
    out = json.loads(res.stdout)
    return out["duration"], [np.reshape(out["vertices"][str(t)], (-1, 3)) for t in times]


def export(*args):
    res = subprocess.run([sys.executable, "-m", "treeanim", "export", *args, "--quiet"], capture_output=True, text=True,
                         timeout=900)
    return res


def simulate(preset, seconds, fps, wind, pulls=(), season=0.0):
    """The node positions the exporter should have baked, frame by frame: the frames at
    0, 1/fps, ..., ``seconds`` (both ends included)."""
    tree = ta.load_preset(preset)
    sim = ta.Simulation(tree, wind=ta.WindField(speed=wind) if wind else None, season=season)
    frames = scripted.frames(sim, int(round(seconds * fps)) + 1, fps, [scripted.parse_pull(p) for p in pulls])
    return tree, [sim.positions.copy() for _ in frames]


CASES = [
    # preset, file, seconds, fps, wind, pulls
    ("small_cherry", "small.glb", 2.0, 15, 8.0, ["3:0,0,150@0.2-0.8"]),
    ("large_cherry", "large.gltf", 0.5, 10, 12.0, []),
    ("grassland", "grass.glb", 1.0, 10, 10.0, []),
]


@pytest.mark.parametrize("preset,name,seconds,fps,wind,pulls", CASES, ids=[c[0] for c in CASES])
def test_export_validates_and_plays_back(tmp_path, preset, name, seconds, fps, wind, pulls):
    out = tmp_path / name
    pull_args = [a for p in pulls for a in ("--pull", p)]
    res = export(preset, "--seconds", str(seconds), "--fps", str(fps), "--wind", str(wind), *pull_args, "--out", str(out))
    assert res.returncode == 0, res.stderr
    report = validate(out)
    assert (report["numErrors"], report["numWarnings"]) == (0, 0), report["messages"][:5]

    doc, blob = load(out)
    tree, frames = simulate(preset, seconds, fps, wind, pulls)
    skel = skeleton(tree)
    n = int(round(seconds * fps))
    assert len(doc.skins[0].joints) == skel.count
    times = clip(doc, blob)[0]  # the longest of the channels' inputs: thinned ones hold fewer keys
    assert len(times) == n + 1 == len(frames), "n frames: keys at 0, 1/fps, ..., seconds"
    assert times[-1] == np.float32(seconds), "the clip lasts exactly --seconds"
    assert np.allclose(np.diff(times), 1 / fps, rtol=1e-5)
    assert len(doc.animations[0].channels) == skel.count - 1
    for k in (n // 2, n):
        baked = joint_world_positions(doc, blob, k)[1:]
        truth = frames[k][skel.joint_node[1:]]
        assert np.max(np.linalg.norm(baked - truth, axis=1)) < 1e-3, f"frame {k} joints off by more than 1 mm"
    # The tree really moves in the file: the wind displaced joints by centimetres at least
    # (millimetres for the stiff blades, in the canopy's weaker wind).
    moved = np.max(np.linalg.norm(frames[-1] - tree.rest_positions, axis=1))
    assert moved > (0.002 if preset == "grassland" else 0.01)


def card_triangles(tree, season=0.0):
    """The triangles a glTF file draws: the tree's, each present leaf's lamina a 4-triangle card."""
    leaves = np.sum((tree.kind == "leaf") & tree.leaves_present(season))
    return tree.stats(season)["triangles"] - leaves * (len(tree.lamina.triangles) - 4)


def test_export_mesh_matches_tree(tmp_path):
    """... its leaves cards cut to the leaf's shape by a texture's alpha: the texture covers as
    much of the card as the lamina does (within 1 %), the material cuts at half coverage."""
    out = tmp_path / "cherry.glb"
    assert export("small_cherry", "--seconds", "0.2", "--fps", "10", "--out", str(out)).returncode == 0
    doc, blob = load(out)
    tree = ta.load_preset("small_cherry")
    assert triangles(doc) == card_triangles(tree)
    leaf = doc.materials[1]
    assert (leaf.alphaMode, leaf.alphaCutoff) == ("MASK", 0.5)
    image = doc.images[doc.textures[leaf.pbrMetallicRoughness.baseColorTexture.index].source]
    view = doc.bufferViews[image.bufferView]
    alpha = np.asarray(Image.open(io.BytesIO(blob[view.byteOffset:view.byteOffset + view.byteLength])))[..., 3]
    box = np.prod(np.ptp(tree.lamina.outline, axis=0))
    assert np.mean(alpha / 255.0) * box == pytest.approx(tree.lamina.area, rel=0.01)
    assert np.mean(alpha >= 128) * box == pytest.approx(tree.lamina.area, rel=0.01)
    pos = skinned_vertices(doc, blob)
    lo, hi = tree.rest_positions.min(axis=0), tree.rest_positions.max(axis=0)
    assert np.all(pos.min(axis=0) > lo - 0.2) and np.all(pos.max(axis=0) < hi + 0.2)
    w = attribute(doc, blob, "WEIGHTS_0")
    assert np.allclose(w.sum(axis=1), 1.0, atol=1e-6)


def test_winter_export_drops_leaves(tmp_path):
    """Fallen leaves leave the file: their triangles and their joints (a winter small cherry
    keeps 230 of 2,522 joints: 2,292 were the fallen leaves')."""
    summer, winter = tmp_path / "s.glb", tmp_path / "w.glb"
    for path, season in ((summer, "0"), (winter, "1")):
        assert export("small_cherry", "--seconds", "0.4", "--fps", "5", "--wind", "6", "--season", season,
                      "--out", str(path)).returncode == 0
    tree = ta.load_preset("small_cherry")
    tris, joints = [], []
    for path, season in ((summer, 0.0), (winter, 1.0)):
        doc, blob = load(path)
        tris.append(triangles(doc))
        joints.append(len(doc.skins[0].joints))
        present = tree.leaves_present(season)
        segments = tree.object_count - 1  # one joint per segment, plus the root joint
        assert joints[-1] == 1 + segments[present].sum()
        assert len(doc.animations[0].channels) == joints[-1] - 1
        used = np.unique(attribute(doc, blob, "JOINTS_0"))
        assert used.max() < joints[-1]
    assert tris == [card_triangles(tree, 0.0), card_triangles(tree, 1.0)]
    assert joints[1] < joints[0] // 5, "a winter tree is mostly bare"
    report = validate(winter)
    assert (report["numErrors"], report["numWarnings"]) == (0, 0), report["messages"][:5]

    # What is left still plays back the simulation of the bare tree.
    doc, blob = load(winter)
    _, frames = simulate("small_cherry", 0.4, 5, 6.0, season=1.0)
    skel = skeleton(tree, tree.leaves_present(1.0))
    baked = joint_world_positions(doc, blob, 2)[1:]
    assert np.max(np.linalg.norm(baked - frames[2][skel.joint_node[1:]], axis=1)) < 1e-3


def _angles(a, b):
    """Degrees between the rotations of unit quaternions (..., 4)."""
    d = np.abs(np.sum(np.asarray(a, float) * np.asarray(b, float), axis=-1))
    return np.degrees(2 * np.arccos(np.clip(d, 0, 1)))


def _largest_elsewhere(steps):
    """(K,) for each step k, how many joints step further there than at every other step."""
    return np.array([np.sum(steps[k] > np.delete(steps, k, axis=0).max(axis=0) + 1e-3) for k in range(len(steps))])


def test_loop_closes_at_exactly_the_asked_length_without_a_seam(tmp_path):
    """--loop: played as a client plays a looping clip (the time modulo the clip's length,
    sampled at the key rate), the step across the loop point is as ordinary as any other
    frame's; the key at T repeats the first, and T is --seconds. The cross-fade over the
    clip's start adds less to a frame's step than any joint's typical (median) step."""
    fps, seconds, fade = 20, 3.0, 20
    n = int(seconds * fps)
    out = tmp_path / "loop.glb"
    res = export("small_cherry", "--seconds", str(seconds), "--fps", str(fps), "--wind", "12", "--loop", "1",
                 "--out", str(out))
    assert res.returncode == 0, res.stderr
    assert "loop seam:" in res.stdout
    report = validate(out)
    assert (report["numErrors"], report["numWarnings"]) == (0, 0), report["messages"][:5]
    times, keys = clip(*load(out))
    assert times[-1] == np.float32(seconds), "the loop lasts exactly --seconds"
    assert np.array_equal(keys[-1], keys[0]), "the key at T repeats the first"

    played = play(times, keys, np.arange(n + 1) / fps)  # one loop, the loop point included
    steps = _angles(played[:-1], played[1:])
    wrap = int(np.searchsorted(np.arange(n + 1) / fps, times[-1], side="left")) - 1  # the step that crosses T
    counts = _largest_elsewhere(steps)
    assert counts[wrap] <= np.delete(counts, wrap).max(), (counts[wrap], np.delete(counts, wrap).max())

    # The key at T is the simulation's frame at T, and frames fade .. n - 1 are its own.
    doc, blob = load(out)
    tree, frames = simulate("small_cherry", seconds + fade / fps, fps, 12.0)
    skel = skeleton(tree)
    for k in (fade, n - 1, n):
        baked = joint_world_positions(doc, blob, k)[1:]
        assert np.max(np.linalg.norm(baked - frames[k][skel.joint_node[1:]], axis=1)) < 1e-3, k

    # Over the fade the clip blends the motion after T into its own start: each frame's step
    # is at most what either motion steps, plus less than the joint's median step.
    tree = ta.load_preset("small_cherry")
    sim = ta.Simulation(tree, wind=ta.WindField(speed=12.0))
    raw = np.array([local_rotations(skel, sim.rotations)[1:] for _ in scripted.frames(sim, int(round(seconds * fps)) + fade + 1, fps)])
    own = np.maximum(_angles(raw[:fade], raw[1:fade + 1]), _angles(raw[n:n + fade], raw[n + 1:n + fade + 1]))
    added = np.max(steps[:fade] - own, axis=0)
    median = np.median(steps, axis=0)
    assert np.all(added <= median + 1e-3), np.max(added - median)


def _bytes(doc, accessors):
    """Bytes of the buffer views behind ``accessors``, each view counted once."""
    return sum(doc.bufferViews[v].byteLength for v in {doc.accessors[a].bufferView for a in accessors})


def test_compact_file_is_smaller_by_its_layout_and_moves_within_a_millimetre(tmp_path):
    """--precision compact (the default) against full: 28 bytes a vertex, not 40 (positions 8,
    normals 4), 2 bytes a triangle index, not 4, 8 bytes a rotation key, not 16, and fewer keys
    where a joint's motion allows (a pulled shoot in still air: the other joints hardly move).
    Skinned as a client skins each file, at every key, the two meshes lie within 1 mm, and the
    command reports that error. Both validate."""
    args = ("small_cherry", "--seconds", "2", "--fps", "15", "--wind", "0", "--pull", "3:0,0,150@0.2-0.8")
    files, reports = {}, {}
    for precision in ("full", "compact"):
        files[precision] = tmp_path / f"{precision}.glb"
        res = export(*args, "--precision", precision, "--out", str(files[precision]))
        assert res.returncode == 0, res.stderr
        reports[precision] = res.stdout
        report = validate(files[precision])
        assert (report["numErrors"], report["numWarnings"]) == (0, 0), report["messages"][:5]
    full, compact = load(files["full"]), load(files["compact"])
    V, T, F = len(attribute(*full, "POSITION")), triangles(full[0]), 31
    J = len(full[0].skins[0].joints)
    layout = {}
    for name, (doc, _) in (("full", full), ("compact", compact)):
        prims, anim = doc.meshes[0].primitives, doc.animations[0]
        layout[name] = (_bytes(doc, [getattr(p.attributes, a) for p in prims for a in ("POSITION", "NORMAL", "COLOR_0",
                                                                                           "JOINTS_0", "WEIGHTS_0")]),
                        _bytes(doc, [p.indices for p in prims]),
                        _bytes(doc, [s.output for s in anim.samplers]),
                        sum(doc.accessors[s.output].count for s in anim.samplers))
    assert layout["full"][:3] == (40 * V, 12 * T, 16 * F * (J - 1))
    assert layout["compact"][:2] == (28 * V, 6 * T)
    keys = layout["compact"][3]
    assert layout["compact"][2] == 8 * keys and keys < F * (J - 1) // 4, "most joints keep a few keys"
    saved = files["full"].stat().st_size - files["compact"].stat().st_size
    assert saved >= 0.95 * (12 * V + 6 * T + (16 * F * (J - 1) - 8 * keys)), (saved, V, T, keys)

    worst = max(float(np.max(np.linalg.norm(skinned_vertices(*full, k) - skinned_vertices(*compact, k), axis=1)))
                for k in range(F))
    assert worst <= 1e-3, f"{worst * 1000:.2f} mm"
    m = re.search(r"compact: .* RMS ([\d.]+) cm, worst ([\d.]+) cm", reports["compact"])
    assert m and "compact:" not in reports["full"], reports
    assert 0 < float(m[1]) <= float(m[2]) <= worst * 100 + 1e-3, (m[0], worst)

    # three.js decodes the compact file (quantised positions and keys, thinned channels, 16-bit
    # primitives) and skins it as the file says; it plays as long as the full one.
    duration, played = three(files["compact"], (0, 9 / 15, 28 / 15))  # at 2 s it loops to 0
    assert duration == pytest.approx(2.0)
    for k, v in zip((0, 9, 28), played):
        assert np.max(np.linalg.norm(v - skinned_vertices(*compact, k), axis=1)) < 1e-5, k


@pytest.mark.parametrize("args,words", [
    (["--out", "tree.obj"], "unknown extension"),
    (["--out", "/nonexistent/dir/tree.glb"], "does not exist"),
    (["--out", "x.glb", "--pull", "99999:1,0,0@0-1"], "objects 0 to"),
    (["--out", "x.glb", "--seconds", "-1"], "positive"),
    (["--out", "x.glb", "--fps", "0"], "positive"),
    (["--out", "x.glb", "--loop", "9"], "shorter"),
    (["--out", "x.glb", "--seconds", "2.05", "--fps", "24"], "whole frames"),
])
def test_export_bad_input(tmp_path, args, words):
    res = subprocess.run([sys.executable, "-m", "treeanim", "export", "small_cherry", *args], capture_output=True,
                         text=True, cwd=tmp_path, timeout=120)
    assert res.returncode == 2
    assert "Traceback" not in res.stderr and words in res.stderr
    assert not list(tmp_path.iterdir()), "no file is left behind"


def test_exported_leaf_colours_turn_with_the_season(tmp_path):
    """The laminas' colours (the leaf material's primitives) turn from green to red-brown."""
    means = []
    for season in ("0", "0.5", "1"):
        out = tmp_path / f"s{season}.glb"
        assert export("small_cherry", "--seconds", "0.2", "--fps", "10", "--season", season, "--out", str(out)).returncode == 0
        doc, blob = load(out)
        col = attribute(doc, blob, "COLOR_0")[:, :3]
        prims = doc.meshes[0].primitives
        lamina = np.concatenate([np.full(doc.accessors[p.attributes.POSITION].count, doc.materials[p.material].name == "leaf")
                                 for p in prims])
        means.append(col[lamina].mean(axis=0))
    (r0, g0, _), (r5, g5, _), (r1, g1, _) = means
    assert g0 > 2 * r0, "summer leaves are green"
    assert r5 > g5 and r1 > g1, "autumn and winter leaves are red-brown"


def test_a_gltf_and_its_buffer_are_replaced_as_a_pair(tmp_path):
    """The buffer is named after its content and percent-encoded in the URI; a second export
    over the first writes a new buffer, points the .gltf at it and removes the old one."""
    out = tmp_path / "my tree.gltf"
    names = []
    for seconds in ("0.2", "0.4"):
        assert export("beam", "--seconds", seconds, "--fps", "10", "--out", str(out)).returncode == 0
        doc, blob = load(out)
        uri = doc.buffers[0].uri
        assert uri.startswith("my%20tree-") and uri.endswith(".bin") and " " not in uri
        assert len(blob) == doc.buffers[0].byteLength
        names.append(sorted(p.name for p in tmp_path.iterdir()))
    assert names[0] != names[1] and len(names[1]) == 2, names  # the first buffer is gone
    report = validate(out)
    assert (report["numErrors"], report["numWarnings"]) == (0, 0), report["messages"][:5]


def test_exported_bark_takes_the_species_colour():
    """The exporter's vertex colours follow the preset's [bark] as the shader does."""
    from treeanim.export import vertex_colours
    from treeanim.render.mesh import MATERIAL_BARK, build_mesh

    for name in ("tulip_poplar", "small_cherry"):
        tree = ta.load_preset(name)
        mesh = build_mesh(tree)
        bark = vertex_colours(tree, mesh, 0.0)[mesh.material == MATERIAL_BARK, :3]
        expected = np.power(np.asarray(tree.bark.color), 2.2)
        ratio = bark / expected
        assert np.all(ratio > 0.91) and np.all(ratio < 1.09)
        assert np.allclose(ratio[:, 0], ratio[:, 2])  # the species' hue, only brighter or darker


def test_more_joints_than_a_skin_indexes_are_refused_in_one_line():
    """glTF's JOINTS_0 holds 16-bit joint indices: a skeleton of more than 65,536 joints (five
    grasslands, 75,001; the orchard's 121,009) was written with the indices wrapped, skinning
    vertices to other trees' joints. Now it is refused."""
    from treeanim import export as ex

    grass = ta.load_preset("grassland")
    scene = ta.make_scene([grass] * 5, positions=[(12.0 * k, 0.0, 0.0) for k in range(5)])
    skel = skeleton(scene)
    assert skel.count > ex.MAX_JOINTS
    with pytest.raises(ValueError, match="at most 65,536") as e:
        ex.bake(ta.Simulation(scene), skel, 2, 10.0)
    assert "\n" not in str(e.value)
    small = skeleton(grass)
    ex.check_joints(small)  # one grassland's 15,001 joints are fine


def test_primitives_are_cut_at_the_materials_and_at_the_vertex_limit():
    """compact.runs: consecutive vertex ranges, no triangle across a cut, a cut at every
    material boundary, none longer than the limit."""
    from treeanim.compact import runs

    tris = np.array([[0, 1, 2], [4, 5, 6], [1, 2, 3], [5, 6, 4], [7, 8, 9]])  # clean cuts: 0, 4, 7, 10
    for limit, ranges in ((None, [(0, 4), (4, 10)]), (6, [(0, 4), (4, 10)]), (5, [(0, 4), (4, 7), (7, 10)])):
        order, cut = runs(tris, limit, cuts=[4])
        assert [(v0, v1) for _, _, v0, v1 in cut] == ranges
        for t0, t1, v0, v1 in cut:
            assert np.all((tris[order[t0:t1]] >= v0) & (tris[order[t0:t1]] < v1))
        assert sorted(order.tolist()) == list(range(len(tris)))
    with pytest.raises(ValueError, match="at most 2 vertices"):
        runs(tris, 2)
