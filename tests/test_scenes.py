"""Scenes (issue 28): trees placed at a position, heading and scale, each grown from its own seed,
joined into one Tree that one Simulation steps in one call; scene files and their one-line
refusals; the shipped scenes load and step finitely in a gale. Drawing them: test_scenes_gl."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

import treeanim as ta
from conftest import Uniform, grass_patch, small_tree
from treeanim import cli
from treeanim.errors import SceneError
from treeanim.model.load import load_named
from treeanim.model.presets import read_spec
from treeanim.model.qsm.leaves import LEAVES_FOR_QSM_ONLY
from treeanim.model.scene import MergeError, heading_matrix, make_scene, merge_trees, place_tree
from treeanim.model.scene_file import MAX_TREES, scene_summary

ROOT = Path(__file__).resolve().parents[1]
QSM = ROOT / "assets" / "qsm" / "synthetic_broadleaf.txt"


@pytest.fixture(scope="module")
def cherry():
    return ta.load_preset("small_cherry")


def write(tmp_path, text: str, name: str = "scene.toml") -> Path:
    path = tmp_path / name
    path.write_text('name = "test"\ntype = "scene"\n' + text, encoding="utf-8")
    return path


# ---------------------------------------------------------------------------- the API
def test_a_placed_tree_moves_exactly_by_its_position_heading_and_scale():
    tree = small_tree()
    placed = place_tree(tree, position=(12.5, 0.0, -7.25), heading=30.0, scale=1.3)
    c, s = np.cos(np.radians(30.0)), np.sin(np.radians(30.0))
    R = np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])
    expect = (1.3 * tree.rest_positions) @ R.T + (12.5, 0.0, -7.25)
    assert np.allclose(placed.rest_positions, expect, rtol=0, atol=1e-12)
    assert np.allclose(placed.rest_w, tree.rest_w @ R.T, atol=1e-15)
    assert np.array_equal(placed.node_diameter, 1.3 * tree.node_diameter)
    assert np.array_equal(placed.lamina_length, 1.3 * tree.lamina_length)
    # +x turns toward -z at a quarter turn (counter-clockwise seen from above); the input is kept
    assert np.allclose(heading_matrix(90.0) @ [1.0, 0.0, 0.0], [0.0, 0.0, -1.0], atol=1e-15)
    assert np.array_equal(tree.rest_positions, small_tree().rest_positions)
    # placed alone in a scene: the same rest positions, its nodes in its own order
    scene = make_scene([tree], [(12.5, 0.0, -7.25)], [30.0], [1.3])
    assert scene.n_trees == 1 and np.array_equal(scene.tree_nodes(0), np.arange(tree.n_nodes))
    assert np.allclose(scene.rest_positions, expect, rtol=0, atol=1e-12)
    assert scene.placements[0].position == (12.5, 0.0, -7.25) and scene.placements[0].heading == 30.0


def test_tree_nodes_and_objects_are_each_trees_own(cherry):
    grass = grass_patch()
    trees = [cherry, grass, small_tree(leaves_per_twig=0)]  # (a scene's leaves share one lamina)
    where = [(0.0, 0.0, 0.0), (6.0, 0.0, 0.0), (-5.0, 0.0, 4.0)]
    scene = make_scene(trees, where, [0.0, 45.0, 200.0], [1.0, 2.0, 0.7], name="three")
    assert isinstance(scene, ta.Scene) and isinstance(scene, ta.Tree)
    assert scene.n_trees == 3 and scene.n_nodes == sum(t.n_nodes for t in trees)
    assert np.all(np.diff(scene.level) >= 0)  # one level a slice, over the whole scene
    seen = []
    for k, (t, p, h, s) in enumerate(zip(trees, where, [0.0, 45.0, 200.0], [1.0, 2.0, 0.7])):
        nodes, objs = scene.tree_nodes(k), scene.tree_objects(k)
        assert len(nodes) == t.n_nodes and len(objs) == t.n_objects
        assert np.allclose(scene.rest_positions[nodes], place_tree(t, p, h, s).rest_positions, atol=1e-12)
        assert list(scene.kind[objs]) == list(t.kind)
        inner = scene.parent[objs] >= 0
        assert np.all(np.isin(scene.parent[objs][inner], objs))  # parents within the tree
        assert np.array_equal(scene.object_count[objs], t.object_count)
        seen.append(nodes)
    assert np.array_equal(np.sort(np.concatenate(seen)), np.arange(scene.n_nodes))
    for bad in (3, -1, 1.0, True):
        with pytest.raises(ValueError, match="tree index"):
            scene.tree_nodes(bad)


def test_tree_nodes_are_the_nodes_of_the_trees_objects_and_one_kind_order_sorts_both(cherry):
    """tree_nodes (which leaf_clusters uses for each tree's crown) from the tree's objects is the
    node_tree definition; a scene sorts kinds by the order assemble sorts one tree by."""
    from treeanim.model import build
    from treeanim.model import scene as scene_module

    trees = [cherry, grass_patch(), small_tree(leaves_per_twig=0), cherry]
    scene = make_scene(trees, [(0, 0, 0), (6, 0, 0), (-5, 0, 4), (0, 0, 9)], [0, 45, 200, 10])
    for k in range(scene.n_trees):
        nodes = scene.tree_nodes(k)
        assert nodes.dtype == np.int64 and np.array_equal(nodes, np.flatnonzero(scene.node_tree == k))
    assert scene_module.KIND_ORDER is build.KIND_ORDER
    key = scene.level * 3 + np.array([build.KIND_ORDER[kind] for kind in scene.kind])
    assert np.all(np.diff(key) >= 0)


def test_trees_of_their_own_seeds_differ_and_of_one_seed_are_alike():
    spec = read_spec(ROOT / "assets" / "presets" / "small_cherry.toml")
    from treeanim.model.generate import generate

    a, b, a2 = (generate(dataclasses.replace(spec, seed=s)) for s in (1, 2, 1))
    assert np.array_equal(a.rest_positions, a2.rest_positions)
    assert a.n_nodes != b.n_nodes or not np.allclose(a.rest_positions, b.rest_positions, atol=0.05)
    scene = make_scene([a, b], [(0, 0, 0), (5, 0, 0)])
    x0 = scene.rest_positions[scene.tree_nodes(0)]
    x1 = scene.rest_positions[scene.tree_nodes(1)] - (5, 0, 0)
    assert len(x0) != len(x1) or not np.allclose(x0, x1, atol=0.05)


def test_two_trees_20_m_apart_across_the_wind_sway_each_their_own_way(cherry):
    """Three small cherries in one 8 m/s turbulent wind, the second 20 m and the third 1 m across
    it from the first: over 90 s their tops' downwind sway correlates at 0.03 at 20 m (held below 0.2;
    the issue asks below 0.5), and at 0.41 at 1 m, where the wind is still partly coherent: the
    measurement sees shared wind where there is some."""
    scene = make_scene([cherry] * 3, positions=[(0.0, 0.0, 0.0), (0.0, 0.0, 20.0), (0.0, 0.0, 1.0)])
    sim = ta.Simulation(scene, wind=ta.WindField(speed=8.0, seed=3), seed=0)
    tops = [n[np.argmax(scene.rest_positions[n, 1])] for n in map(scene.tree_nodes, range(3))]
    x = []
    for _ in range(900):  # 90 s sampled at 10 Hz
        for _ in range(6):
            sim.step(1 / 60)
        x.append(sim.positions[tops, 0])
    x = np.array(x) - np.mean(x, axis=0)
    r = np.corrcoef(x.T)
    assert abs(r[0, 1]) < 0.2, r
    assert r[0, 2] > abs(r[0, 1]) + 0.2, r


def test_one_step_moves_every_tree_and_a_pull_only_its_own(cherry):
    scene = make_scene([cherry, cherry, grass_patch()], [(0, 0, 0), (8, 0, 0), (0, 0, 6)], [0, 120, 0])
    assert sum(len(scene.tree_nodes(k)) for k in range(3)) == scene.n_nodes
    sim = ta.Simulation(scene)  # calm: a pull on tree 1's trunk moves tree 1 alone
    trunk1 = scene.tree_objects(1)[0]
    sim.pull(trunk1, (0.0, 0.0, 400.0))
    for _ in range(30):
        sim.step(1 / 60)
    moved = np.linalg.norm(sim.positions - scene.rest_positions, axis=1)
    assert moved[scene.tree_nodes(1)].max() > 1e-3
    assert moved[scene.tree_nodes(0)].max() == 0.0 and moved[scene.tree_nodes(2)].max() == 0.0
    sim.release()
    sim.wind = Uniform((20.0, 0.0, 0.0))  # a 20 m/s wind moves them all, in one step call
    for _ in range(30):
        sim.step(1 / 60)
    moved = np.linalg.norm(sim.positions - scene.rest_positions, axis=1)
    assert np.all(np.isfinite(sim.positions))
    assert all(moved[scene.tree_nodes(k)].max() > 0.005 for k in range(3))


def test_each_trees_leaves_stand_for_clusters_of_its_own_crown(cherry):
    """The leaf-area rule counts each tree's crown, not the hull of the whole scene."""
    alone = ta.Simulation(cherry).structure.leaf_mass
    scene = make_scene([cherry, cherry], [(0, 0, 0), (30, 0, 0)], [0, 77])
    pair = ta.Simulation(scene).structure.leaf_mass
    leaves = np.flatnonzero(scene.kind == "leaf")
    for k in range(2):
        mine = np.isin(leaves, scene.tree_objects(k))
        assert np.allclose(np.sort(pair[mine]), np.sort(alone), rtol=1e-9)


def test_leaves_fall_from_every_tree_alike(cherry):
    other = ta.load_preset("large_cherry")  # the cherry's leaves, five times as many
    scene = make_scene([cherry, other], [(0, 0, 0), (8, 0, 0)])
    assert scene.winter_leaves == cherry.winter_leaves + other.winter_leaves
    present = scene.leaves_present(0.5)
    for k, t in enumerate((cherry, other)):
        objs = scene.tree_objects(k)
        kept = np.count_nonzero(present[objs] & (scene.kind[objs] == "leaf"))
        assert kept == pytest.approx(np.count_nonzero(t.leaves_present(0.5)[t.kind == "leaf"]), abs=2)


def test_the_papers_model_takes_one_tree_and_says_so(cherry):
    scene = make_scene([cherry, cherry], [(0, 0, 0), (5, 0, 0)], name="pair")
    with pytest.raises(ValueError, match=r"^the paper's model takes one tree .* 'pair' has 2: use the tree model$"):
        ta.Simulation(scene, model="paper")
    sim = ta.Simulation(scene)
    with pytest.raises(ValueError, match="paper's model takes one tree"):
        sim.model = "paper"
    assert sim.model == "tree"
    one = make_scene([cherry], [(3, 0, 3)], [40])
    ta.Simulation(one, model="paper").step(1 / 60)


def test_merging_refuses_what_it_cannot_hold(cherry):
    with pytest.raises(ValueError, match="another shape"):
        merge_trees([cherry, ta.load_preset("tulip_poplar")])
    with pytest.raises(ValueError, match="at least one tree"):
        merge_trees([])
    scene = make_scene([cherry], [(0, 0, 0)])
    with pytest.raises(ValueError, match="not a scene"):
        merge_trees([scene])
    for kw, what in (({"position": (np.nan, 0, 0)}, "position"), ({"scale": -1.0}, "scale"),
                     ({"heading": np.inf}, "heading"), ({"position": (2e4, 0, 0)}, "position")):
        with pytest.raises(ValueError, match=what):
            place_tree(cherry, **kw)
    with pytest.raises(ValueError, match="positions, headings and scales"):
        make_scene([cherry, cherry], [(0, 0, 0)])


def test_leaves_of_another_outline_are_refused_once_naming_the_trees_table(tmp_path, cherry):
    """merge_trees alone checks the shared leaf outline; it says which tree, and a scene file's
    reader names that tree's table."""
    sapling = ROOT / "assets" / "presets" / "scenes" / "plants" / "sapling.toml"
    light = ta.load_tree(sapling)
    with pytest.raises(MergeError) as e:
        merge_trees([grass_patch(), cherry, light])
    assert e.value.index == 2 and str(e.value).startswith("tree 2 (") and "another shape" in str(e.value)
    assert "than tree 1 (small_cherry: " in str(e.value)
    path = write(tmp_path, f'[[trees]]\ntree = "small_cherry"\nposition = [0.0, 0.0, 0.0]\n[[scatter]]\n'
                           f'tree = "{sapling}"\ncount = 2\narea = [10.0, 10.0]\ncentre = [0.0, 20.0]\n')
    with pytest.raises(SceneError) as e:
        ta.load_scene(path)
    assert str(e.value).startswith(f"{path}: key 'scatter[0].tree': scatter[0] tree 0 ({sapling}) has leaves of "
                                   f"another shape ('{light.lamina.shape}') than trees[0] (small_cherry: ")


# ---------------------------------------------------------------------------- scene files
@pytest.mark.parametrize("name", ["orchard", "woodland"])
def test_each_shipped_scene_loads_and_steps_finitely_in_a_gale(name):
    scene = ta.load_scene(name)
    n, per, about = scene_summary(scene.source)
    assert scene.n_trees == n and about and scene.description == about
    assert n == (48 if name == "orchard" else 1000)
    # every tree grown from its own seed
    assert len({p.seed for p in scene.placements}) == scene.n_trees
    sim = ta.Simulation(scene, wind=ta.WindField(speed=20.0))
    for _ in range(6):
        sim.step(1 / 60)
    assert np.all(np.isfinite(sim.positions)) and np.all(np.isfinite(sim.rotations))
    moved = np.linalg.norm(sim.positions - scene.rest_positions, axis=1)
    assert np.median([moved[scene.tree_nodes(k)].max() for k in range(0, n, max(1, n // 20))]) > 1e-3


def test_a_scene_file_places_and_scatters_trees(tmp_path):
    (tmp_path / "trees").mkdir()
    (tmp_path / "trees" / "beam.toml").write_text((ROOT / "assets" / "presets" / "beam.toml").read_text())
    path = write(tmp_path, f'''seed = 4
[[trees]]
tree = "small_cherry"
position = [1.0, 0.0, 2.0]
heading = 90.0
scale = 0.5
[[trees]]
tree = "small_cherry"
position = [-4.0, 0.0, 0.0]
seed = 12
[[trees]]
tree = "{QSM}"
position = [20.0, 0.0, 0.0]
leaves = "cherry"
seed = 3
[[scatter]]
tree = "trees/beam.toml"
count = 30
area = [40.0, 10.0]
centre = [0.0, -30.0]
spacing = 1.5
scale = [0.5, 0.8]
[[scatter]]
tree = "grassland"
count = 6
pattern = "grid"
area = [10.0, 5.0]
centre = [0.0, 30.0]
spacing = 5.0
''')
    scene = ta.load_tree(path)  # the general reader knows a scene by its type
    assert isinstance(scene, ta.Scene) and scene.n_trees == 3 + 30 + 6 and scene.name == "test"
    cherry = ta.load_preset("small_cherry")
    assert scene.placements[0].seed == cherry.seed and scene.placements[1].seed == 12
    assert len({p.seed for p in scene.placements[3:]}) == 36  # a scatter's trees: each its own seed
    assert np.allclose(scene.rest_positions[scene.tree_nodes(0)], place_tree(cherry, (1, 0, 2), 90, 0.5).rest_positions)
    qsm = ta.load_qsm(QSM, leaves="cherry", seed=3)
    assert np.allclose(scene.rest_positions[scene.tree_nodes(2)], qsm.rest_positions + (20, 0, 0))
    beams = np.array([p.position for p in scene.placements[3:33]])
    assert np.all(np.abs(beams[:, 0]) <= 20) and np.all(np.abs(beams[:, 2] + 30) <= 5) and np.all(beams[:, 1] == 0)
    gaps = np.linalg.norm(beams[:, None, [0, 2]] - beams[None, :, [0, 2]], axis=2) + 1e9 * np.eye(30)
    assert gaps.min() >= 1.5
    assert all(0.5 <= p.scale <= 0.8 for p in scene.placements[3:33])
    grid = np.array([p.position for p in scene.placements[33:]])
    assert sorted(map(tuple, grid[:, [0, 2]].round(9))) == sorted((x, z) for x in (-5.0, 0.0, 5.0) for z in (27.5, 32.5))
    again = ta.load_scene(path)
    assert np.array_equal(again.rest_positions, scene.rest_positions)
    # the command line's reader takes it by path, and the shipped ones by name
    assert load_named(str(path)).n_nodes == scene.n_nodes
    with pytest.raises(ta.PresetError, match="unknown preset or scene 'meadow'.*scenes: orchard, woodland"):
        load_named("meadow")


def test_info_prints_a_scenes_trees(tmp_path, capsys):
    path = write(tmp_path, '[[trees]]\ntree = "beam"\nposition = [0.0, 0.0, 0.0]\n'
                           '[[scatter]]\ntree = "grassland"\ncount = 2\narea = [20.0, 1.0]\nspacing = 4.0\n')
    assert cli.main(["info", str(path)]) == 0
    out = capsys.readouterr().out
    assert "a scene of 3 trees" in out and "1 beam, 2 grassland" in out and "10,000" in out
    assert cli.main(["list"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert [line.split()[0] for line in lines] == ta.list_presets() + ta.list_scenes()
    assert "scene of 48 trees (48 small_cherry)" in lines[-2] and "1,000 trees" in lines[-1]


def test_one_loader_reads_every_tree_file_and_refuses_leaves_in_one_message(tmp_path, capsys):
    """ta.load_tree, the command line and the viewer's Open read through one function, which
    refuses leaves for a preset or a scene in the words a scene file's ``leaves`` key is
    refused in (they were four messages in four places)."""
    from treeanim.app.actions import ViewerActions
    from treeanim.model import load, qsm

    assert ta.load_tree is load.load_tree and not hasattr(qsm, "load_tree")
    beam = ROOT / "assets" / "presets" / "beam.toml"
    scene = write(tmp_path, '[[trees]]\ntree = "beam"\nposition = [0.0, 0.0, 0.0]\n')
    said = []
    for call in (lambda: ta.load_tree(beam, leaves="cherry"), lambda: ta.load_tree(scene, leaves="cherry"),
                 lambda: load_named("beam", leaves="cherry"), lambda: load_named("orchard", leaves="cherry")):
        with pytest.raises(ta.PresetError) as e:
            call()
        said.append(str(e.value))
    bad = write(tmp_path, '[[trees]]\ntree = "beam"\nposition = [0.0, 0.0, 0.0]\nleaves = "cherry"\n', "bad.toml")
    with pytest.raises(SceneError) as e:
        ta.load_scene(bad)
    said.append(str(e.value))
    assert cli.main(["info", "beam", "--leaves", "cherry"]) == 2
    said.append(capsys.readouterr().err.strip())
    assert all(m.endswith(LEAVES_FOR_QSM_ONLY) and "\n" not in m for m in said), said
    assert said[0].startswith(f"{beam}: ") and said[2] == f"beam: {LEAVES_FOR_QSM_ONLY}"
    assert load_named("beam", leaves="none").n_objects == 1  # 'none' is no leaves: nothing to refuse

    class Panel:  # the viewer's Open, without a window: what it loads and says
        preset_path, messages, loaded = None, [], []
        say, load_tree = messages.append, loaded.append

    panel = Panel()
    assert ViewerActions.open_file(panel, scene) and isinstance(panel.loaded[-1], ta.Scene)
    assert ViewerActions.open_file(panel, str(QSM)) and panel.loaded[-1].name == "synthetic_broadleaf"
    assert not ViewerActions.open_file(panel, bad) and LEAVES_FOR_QSM_ONLY in panel.messages[-1]


# ---------------------------------------------------------------------------- bad scene files
BAD = [
    ('[[trees]]\ntree = "oak"\nposition = [0.0, 0.0, 0.0]\n', "trees[0].tree", "unknown preset 'oak'"),
    ('[[trees]]\ntree = "beam"\nposition = [nan, 0.0, 0.0]\n', "trees[0].position", "got [nan, 0.0, 0.0]"),
    ('[[trees]]\ntree = "beam"\nposition = [0.0, 0.0]\n', "trees[0].position", "a position [x, y, z]"),
    # the ground is flat at y = 0 (and the contact floor absolute): a tree stands on it
    ('[[trees]]\ntree = "beam"\nposition = [0.0, 2.5, 0.0]\n', "trees[0].position", "expected y = 0"),
    ('[[trees]]\ntree = "beam"\nposition = [0.0, -0.1, 0.0]\n', "trees[0].position", "got [0.0, -0.1, 0.0]"),
    ('[[trees]]\ntree = "beam"\nposition = [0.0, 0.0, 0.0]\nscale = -1.0\n', "trees[0].scale", "got -1.0"),
    ('[[trees]]\ntree = "beam"\nposition = [0.0, 0.0, 0.0]\nheading = inf\n', "trees[0].heading", "got inf"),
    ('[[trees]]\ntree = "beam"\nposition = [0.0, 0.0, 0.0]\nsize = 2\n', "trees[0].size", "unknown key"),
    ('[[trees]]\ntree = "beam"\n', "trees[0].position", "missing"),
    ('[[trees]]\ntree = "beam"\nposition = [0.0, 0.0, 0.0]\nleaves = "cherry"\n', "trees[0].leaves",
     LEAVES_FOR_QSM_ONLY),
    ('', "trees", "at least one tree"),
    ('trees = 3\n', "trees", "array of tables"),
    ('colour = 1\n', "colour", "unknown key"),
    (f'[[scatter]]\ntree = "beam"\ncount = {MAX_TREES + 1}\narea = [10.0, 10.0]\n', "scatter[0].count",
     "expected an integer in [1, 5000]"),
    ('[[scatter]]\ntree = "beam"\ncount = 3000\narea = [10.0, 10.0]\n[[scatter]]\ntree = "beam"\ncount = 3000\n'
     'area = [10.0, 10.0]\n', "scatter[1].count", "would place 6,000 trees"),
    ('[[scatter]]\ntree = "large_cherry"\ncount = 20\narea = [100.0, 100.0]\n', "scatter[0].count",
     "a scene may build at most 15,000,000"),
    ('[[scatter]]\ntree = "beam"\ncount = 50\narea = [10.0, 10.0]\nspacing = 3.0\n', "scatter[0].count",
     "trees fit 10 × 10 m at spacing 3 m"),
    ('[[scatter]]\ntree = "beam"\ncount = 50\narea = [10.0, 10.0]\nspacing = 3.0\npattern = "grid"\n',
     "scatter[0].count", "do not fit a grid of 4 × 4"),
    ('[[scatter]]\ntree = "beam"\ncount = 5\narea = [10.0, 10.0]\npattern = "hex"\n', "scatter[0].pattern",
     "'random' or 'grid'"),
    ('[[scatter]]\ntree = "beam"\ncount = 5\narea = [10.0, -1.0]\n', "scatter[0].area", "an area [width, depth]"),
    ('[[scatter]]\ntree = "beam"\ncount = 5\narea = [10.0, 10.0]\nscale = [2.0, 1.0]\n', "scatter[0].scale",
     "min <= max"),
    ('[[trees]]\ntree = "small_cherry"\nposition = [0.0, 0.0, 0.0]\n[[trees]]\ntree = "small_cherry"\n'
     'position = [0.05, 0.0, 0.0]\n', "trees[0]", "its trunk overlaps that of trees[1]"),
    ('[[trees]]\ntree = "small_cherry"\nposition = [0.0, 0.0, 0.0]\n[[trees]]\ntree = "tulip_poplar"\n'
     'position = [9.0, 0.0, 0.0]\n', "trees[1].tree", "a scene's leaves share one outline"),
    ('[[trees]]\ntree = "other.toml"\nposition = [0.0, 0.0, 0.0]\n', "trees[0].tree", "is a scene; a scene places"),
    ('[[trees]]\ntree = "missing.toml"\nposition = [0.0, 0.0, 0.0]\n', "trees[0].tree", "cannot read preset file"),
    # an integer of hundreds of digits is no float (isfinite raised OverflowError)
    ('seed = ' + "9" * 400 + '\n[[trees]]\ntree = "beam"\nposition = [0.0, 0.0, 0.0]\n', "seed",
     "expected an integer in [0, "),
    ('[[trees]]\ntree = "beam"\nposition = [0.0, 0.0, 0.0]\nscale = ' + "1" * 400 + '\n', "trees[0].scale",
     "got 1111"),
    # a subnormal spacing made infinitely many grid or hash cells (OverflowError)
    ('[[scatter]]\ntree = "beam"\ncount = 2\narea = [1.0, 1.0]\npattern = "grid"\nspacing = 1e-310\n',
     "scatter[0].spacing", "in [0.05, 1000]"),
    ('[[scatter]]\ntree = "beam"\ncount = 2\narea = [1.0, 1.0]\nspacing = 1e-310\n', "scatter[0].spacing",
     "in [0.05, 1000]"),
    # a grid's jitter past 10 km (place_tree's ValueError was a traceback)
    ('[[scatter]]\ntree = "beam"\ncount = 3\narea = [10.0, 10.0]\ncentre = [9995.0, 0.0]\npattern = "grid"\n'
     'spacing = 5.0\njitter = 100.0\n', "scatter[0].area", "with its jitter of 100 m"),
]


@pytest.mark.parametrize("text, key, words", BAD, ids=[f"{i}:{b[1]}" for i, b in enumerate(BAD)])
def test_a_bad_scene_file_is_one_line_naming_the_key(tmp_path, capsys, text, key, words):
    write(tmp_path, '[[trees]]\ntree = "beam"\nposition = [0.0, 0.0, 0.0]\n', "other.toml")
    path = write(tmp_path, text)
    with pytest.raises(SceneError) as e:
        ta.load_scene(path)
    msg = str(e.value)
    assert "\n" not in msg and msg.startswith(f"{path}: key '{key}': ") and words in msg, msg
    assert cli.main(["info", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("treeanim: error: ") and words in err and "Traceback" not in err


def test_not_a_scene_is_one_line_too(tmp_path):
    path = tmp_path / "x.toml"
    path.write_text('name = "x"\ntype = "scene"\n[[trees]\n')
    with pytest.raises(SceneError, match=r"not valid TOML"):
        ta.load_scene(path)
    with pytest.raises(SceneError, match=r"not valid TOML"):  # as its docstring says (it was a PresetError)
        scene_summary(path)
    with pytest.raises(SceneError, match="unknown scene 'forest'; known scenes: orchard, woodland"):
        ta.load_scene("forest")
    with pytest.raises(ta.PresetError, match=r"got 'scene' \(a scene file: treeanim.load_scene reads it\)"):
        read_spec(write(tmp_path, '[[trees]]\ntree = "beam"\nposition = [0.0, 0.0, 0.0]\n'))


def test_what_placing_refuses_is_one_line_naming_the_table(tmp_path, monkeypatch):
    """A guard: the checks leave place_tree nothing to refuse, but should it refuse, the scene's
    reader says so in one line with the tree's table."""
    from treeanim.model import scene_file

    def refuse(tree, position, heading, scale):
        raise ValueError("position must lie within 10000 m of the origin")

    monkeypatch.setattr(scene_file, "place_tree", refuse)
    path = write(tmp_path, '[[scatter]]\ntree = "beam"\ncount = 2\narea = [4.0, 4.0]\n')
    with pytest.raises(SceneError) as e:
        ta.load_scene(path)
    assert str(e.value) == f"{path}: key 'scatter[0]': scatter[0] tree 0: position must lie within 10000 m of the origin"
