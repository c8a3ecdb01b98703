"""A scene exported for shader wind as instances (EXT_mesh_gpu_instancing) of template trees:
the file validates, places every tree where the scene does, is far smaller than a mesh per tree,
and its instances sway each in its own time in three.js in headless Chromium."""

import shutil

import numpy as np
import pytest

import treeanim as ta
from browser import STILL_MS, frames, serve
from gltf_readback import accessor, load
from test_export import NODE_MODULES, export, validate
from test_shader_wind import ROOT
from treeanim import shader_wind
from treeanim.model.scene import Placement, heading_matrix
from treeanim.offline.export import template_of, template_seeds

#: Three small cherries in a row along the wind (+x), 6 m apart: the outer two alike (one seed,
#: heading and scale), the middle one turned and smaller; a beam far behind, turned and scaled.
SCENE = """name = "row"
type = "scene"
[[trees]]
tree = "small_cherry"
position = [-6.0, 0.0, 0.0]
[[trees]]
tree = "small_cherry"
position = [0.0, 0.0, 0.0]
heading = 45
scale = 0.8
[[trees]]
tree = "small_cherry"
position = [6.0, 0.0, 0.0]
[[trees]]
tree = "beam"
position = [-3.0, 0.0, -8.0]
heading = 30
scale = 1.5
"""


@pytest.fixture(scope="module")
def row(tmp_path_factory):
    web = tmp_path_factory.mktemp("web")
    (web / "row.toml").write_text(SCENE)
    res = export(str(web / "row.toml"), "--motion", "shader", "--instances", "1", "--out", str(web / "row.glb"))
    assert res.returncode == 0, res.stderr
    assert "4 trees as instances of 2" in res.stdout
    return web


def _rotation(q):
    """(3, 3) the rotation of the unit quaternion (x, y, z, w)."""
    x, y, z, w = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def test_a_scene_exports_as_instances_of_its_templates_where_its_trees_stand(row):
    report = validate(row / "row.glb")
    assert (report["numErrors"], report["numWarnings"]) == (0, 0), report["messages"][:5]
    doc, blob = load(row / "row.glb")
    assert doc.extensionsUsed == ["EXT_mesh_gpu_instancing"]
    assert len(doc.meshes) == 1 * 2, "K templates per tree source"
    scene = ta.load_scene(row / "row.toml")
    placed = []
    for node in doc.nodes:
        at = {k: accessor(doc, blob, i) for k, i in node.extensions["EXT_mesh_gpu_instancing"]["attributes"].items()}
        assert {doc.accessors[i].componentType for i in
                node.extensions["EXT_mesh_gpu_instancing"]["attributes"].values()} == {5126}, "floats"
        for t, q, s in zip(at["TRANSLATION"], at["ROTATION"], at["SCALE"]):
            placed.append((doc.meshes[node.mesh].name, t, q, s))
    assert len(placed) == scene.n_trees, "one instance per tree"
    for p in scene.placements:
        mine = [x for x in placed if np.allclose(x[1], p.position, atol=1e-5)]
        assert len(mine) == 1
        name, t, q, s = mine[0]
        assert name == p.tree
        assert np.allclose(_rotation(q), heading_matrix(p.heading), atol=1e-6)
        assert np.allclose(s, p.scale)


def test_the_instanced_file_is_far_smaller_than_a_mesh_per_tree(row):
    """... which the scene's shader-wind glTF without --instances is (its table's values do not
    change its size)."""
    scene = ta.load_scene(row / "row.toml")
    M = scene.n_objects
    table = shader_wind.BranchTable(np.zeros((M, 3)), np.ones((M, 3)), np.ones(M), np.ones(M), np.ones(M), 2.0)
    doc, data = shader_wind.build_shader_gltf(scene, table)
    assert (row / "row.glb").stat().st_size < 0.4 * len(data)


def test_templates_are_chosen_by_seed():
    placements = [Placement("a", seed=5), Placement("a", seed=5), Placement("b", seed=1), Placement("a", seed=8),
                  Placement("a", seed=9), Placement("b", seed=2), Placement("b.txt", seed=3, leaves="cherry")]
    seeds = template_seeds(placements, 2)
    assert seeds == {("a", None): [5, 8], ("b", None): [1, 2], ("b.txt", "cherry"): [3]}
    assert [template_of(seeds[p.tree, p.leaves], p.seed) for p in placements] == [0, 0, 0, 1, 9 % 2, 1, 0]


def test_instances_refused_without_shader_motion_or_for_one_tree(tmp_path):
    for args in (("small_cherry", "--motion", "shader"), (str(tmp_path / "none.toml"),)):
        res = export(*args, "--instances", "2", "--out", str(tmp_path / "x.glb"))
        assert res.returncode == 2
        assert res.stderr.strip().count("\n") == 0 and "--instances" in res.stderr


def _sway(frame, calm, sky):
    """Per third of the frame (the row's outer trees): the shift of its tree pixels' mean x
    from calm (px)."""
    x = np.arange(frame.shape[1])
    out = []
    for a in (frame, calm):
        tree = np.abs(a - sky).sum(axis=2) > 30
        w = tree.shape[1] // 3
        out.append([np.sum(x[s] * tree[:, s]) / max(np.sum(tree[:, s]), 1) for s in (slice(0, w), slice(2 * w, None))])
    return np.subtract(*out)


def test_the_instances_sway_each_in_its_own_time_in_three_js(row, tmp_path):
    shutil.copy(ROOT / "examples" / "shader_wind" / "index.html", row)
    shutil.copy(ROOT / "shaders" / "engine_wind.glsl", row)
    assert (NODE_MODULES / "three").is_dir(), f"three is not installed in {NODE_MODULES}: run scripts/test"
    if not (row / "three").exists():
        (row / "three").symlink_to(NODE_MODULES / "three")
    times = (2.0, 2.5, 3.0, 3.5)
    queries = ["t=0&wind=0", "t=3&wind=20&turbulence=0"] + [f"t={t:g}&wind=20&turbulence=1" for t in times]
    with serve(row) as port:
        calm, steady, *gale = (frames(f"http://127.0.0.1:{port}/index.html?file=row.glb&{q}", tmp_path / f"profile{i}",
                                      STILL_MS)[0] for i, q in enumerate(queries))
    sky = calm[0, 0]
    tree = np.abs(calm - sky).sum(axis=2) > 30
    columns = np.flatnonzero(tree.any(axis=0))
    runs = np.sum(np.diff(columns) > 3) + 1
    assert runs >= 4, "the page draws every cherry of the row (and the beam)"
    # In a steady wind both lean downwind. (In the turbulent wind the swing, 2·turbulence·0.28/√ζ
    # of the mean bend, is as large as the lean: the mean of four frames was a coin toss.)
    assert np.all(_sway(steady, calm, sky) > 0), "both lean downwind"
    sway = np.array([_sway(g, calm, sky) for g in gale])  # (times, 2): the outer trees' shifts (px)
    motion = np.diff(sway, axis=0)
    assert np.max(np.abs(motion[:, 0] - motion[:, 1])) > 0.75 * np.max(np.abs(motion)), \
        "the outer trees, 12 m apart along the wind, do not sway in unison (in unison: within 0.3)"
