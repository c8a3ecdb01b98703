"""The tree model: Table 1 statistics, determinism, invariants, seasons, laminas."""

import dataclasses

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import treeanim as ta
from treeanim.model.generate import LevelSpec, TreeSpec, generate
from treeanim.model.lamina import make_lamina
from treeanim.model.presets import read_spec
from treeanim.model.tree import PLURAL
from treeanim.table1 import ROWS
from treeanim.table1 import TABLE1 as PAPER

# The paper's Table 1: (preset, season) -> {kind: (objects, nodes, triangles)}.
TABLE1 = {ROWS[key]: {kind: counts for kind, *counts in ((r[0], r[1], r[2], r[3]) for r in rows)}
          for key, rows in PAPER.items()}


@pytest.fixture(scope="module")
def trees():
    return {name: ta.load_preset(name) for name in ta.list_presets()}


def test_presets_listed():
    assert set(ta.list_presets()) == {"beam", "small_cherry", "large_cherry", "tulip_poplar", "grassland"}


@pytest.mark.parametrize("key", list(TABLE1), ids=lambda k: f"{k[0]}@{k[1]:g}")
def test_table1_statistics(trees, key):
    name, season = key
    stats = trees[name].stats(season)
    for kind, (objects, nodes, triangles) in TABLE1[key].items():
        assert stats[PLURAL[kind]] == pytest.approx(objects, rel=0.10)
        assert stats[f"{kind}_nodes"] == pytest.approx(nodes, rel=0.10)
        if kind != "branch":  # branch tubes carry their curves' bands: see the next test
            assert stats[f"{kind}_triangles"] == pytest.approx(triangles, rel=0.25)
    assert stats["nodes"] == sum(stats[f"{k}_nodes"] for k in PLURAL)
    assert stats["objects"] == sum(stats[PLURAL[k]] for k in PLURAL)


def test_triangles_counted_from_geometry(trees):
    """Triangle counts follow from the drawn geometry: 16-sided tubes in at least four bands with
    a fan at each end (none where a fork's leader runs on from its parent), petiole tubes plus
    the lamina triangulation, blade strips with a tip."""
    t = trees["small_cherry"]
    stats = t.stats()
    branch = t.kind == "branch"
    segments = t.object_count[branch] - 1
    # At least four bands, and a crooked limb's segments each in enough that its rings turn at
    # most 4° from one to the next (at most 6 a segment).
    crooked = np.minimum(np.ceil(np.degrees(t.joint_turn()[branch]) / 4.0 - 1e-6), 6)
    assert crooked.max() > 1  # the small cherry's limbs turn 22.5° at a joint
    lead = t.fork_leaders()[0]
    joints = len(lead) + len(np.unique(t.parent[lead]))  # the leaders' base fans and their parents' tip fans
    assert joints and stats["branch_triangles"] == 32 * int(
        np.sum(np.maximum(np.ceil(4 / segments), crooked) * segments + 1)) - 16 * joints
    n_leaf = stats["leaves"]
    petiole = 2 * t.petiole_sides * (stats["leaf_nodes"] - n_leaf)
    assert stats["leaf_triangles"] == petiole + n_leaf * len(t.lamina.triangles)
    g = trees["grassland"].stats()
    assert g["blade_triangles"] == 2 * (g["blade_nodes"] - g["blades"]) + g["blades"]


def _arrays(tree):
    return {f.name: getattr(tree, f.name) for f in dataclasses.fields(tree) if isinstance(getattr(tree, f.name), np.ndarray)}


@pytest.mark.parametrize("name", ["small_cherry", "tulip_poplar", "grassland"])
def test_same_seed_bit_identical(name):
    a, b = _arrays(ta.load_preset(name)), _arrays(ta.load_preset(name))
    for key in a:
        assert a[key].tobytes() == b[key].tobytes(), key


def test_other_seed_other_tree():
    spec = read_spec(ta.load_preset("small_cherry").source)
    a = generate(spec)
    b = generate(dataclasses.replace(spec, seed=spec.seed + 1))
    assert a.rest_positions.shape == b.rest_positions.shape
    assert np.abs(a.rest_positions - b.rest_positions).max() > 0.05


def check_invariants(tree):
    """Structural invariants, checked here independently of Tree.validate()."""
    M = tree.n_objects
    assert np.all(tree.object_count >= 2)
    assert tree.object_start[0] == 0
    assert np.all(tree.object_start[1:] == tree.object_start[:-1] + tree.object_count[:-1])
    assert tree.object_count.sum() == tree.n_nodes
    assert np.all(np.diff(tree.level) >= 0), "objects sorted by level"
    for i in range(M):
        nodes = tree.object_nodes(i)
        seg = np.linalg.norm(np.diff(tree.rest_positions[nodes], axis=0), axis=1)
        assert np.all(seg > 1e-6), f"zero-length segment in object {i}"
        d = tree.node_diameter[nodes]
        assert np.all(d > 0) and np.all(np.diff(d) <= 1e-12), f"diameters of object {i} do not taper"
        p = tree.parent[i]
        if p < 0:
            continue
        assert p < i and tree.level[p] < tree.level[i]
        a = tree.attach_node[i]
        assert a in tree.object_nodes(p), "attach node belongs to the parent"
        np.testing.assert_array_equal(tree.rest_positions[nodes[0]], tree.rest_positions[a])
        assert tree.node_diameter[nodes[0]] <= tree.node_diameter[a] + 1e-12
    assert np.all(np.isfinite(tree.rest_positions))
    w = tree.rest_w
    assert np.allclose(np.linalg.norm(w, axis=1), 1.0)


@pytest.mark.parametrize("name", ["beam", "small_cherry", "tulip_poplar", "grassland"])
def test_preset_invariants(trees, name):
    check_invariants(trees[name])


def test_levels_are_contiguous_slices(trees):
    t = trees["large_cherry"]
    slices = t.level_slices()
    assert len(slices) == len(np.unique(t.level))
    for s in slices:
        assert len(np.unique(t.level[s])) == 1


def test_species_shapes(trees):
    """A cherry forks at the top of a short trunk; the tulip poplar has a clear straight trunk."""
    cherry, poplar = trees["large_cherry"], trees["tulip_poplar"]
    for tree in (cherry, poplar):
        assert tree.rest_positions[:, 1].min() >= -1e-9
    c_trunk = cherry.rest_positions[cherry.object_nodes(0)]
    p_trunk = poplar.rest_positions[poplar.object_nodes(0)]
    c_height = cherry.rest_positions[:, 1].max()
    p_height = poplar.rest_positions[:, 1].max()
    assert c_trunk[-1, 1] < 0.35 * c_height  # the cherry's trunk ends low, in a fork
    assert p_trunk[-1, 1] > 0.8 * p_height  # the poplar's runs nearly to the top
    # ...and it is straight: its tip is within 5 % of its length of the line through its base.
    axis = p_trunk[-1] - p_trunk[0]
    dev = np.linalg.norm(np.cross(p_trunk - p_trunk[0], axis / np.linalg.norm(axis)), axis=1)
    assert dev.max() < 0.05 * np.linalg.norm(axis)
    # Every child of the cherry's trunk sits on its top node.
    kids = np.flatnonzero(cherry.parent == 0)
    assert len(kids) >= 2 and np.all(cherry.attach_node[kids] == cherry.object_nodes(0)[-1])


def test_leaves_fall_in_a_fixed_order(trees):
    t = trees["large_cherry"]
    seasons = np.linspace(0, 1, 11)
    masks = [t.leaves_present(s) for s in seasons]
    counts = [int((m & (t.kind == "leaf")).sum()) for m in masks]
    assert counts[0] == 5460 and counts[-1] == 344
    assert all(a >= b for a, b in zip(counts, counts[1:]))
    for a, b in zip(masks, masks[1:]):
        assert np.all(a | ~b), "a leaf present later was present earlier"
    assert np.all(masks[-1][t.kind == "branch"])


def test_lamina_triangulation_covers_outline(trees):
    for name in ("small_cherry", "tulip_poplar"):
        lam = trees[name].lamina
        p = lam.outline[lam.triangles]
        cross = (p[:, 1, 0] - p[:, 0, 0]) * (p[:, 2, 1] - p[:, 0, 1]) - (p[:, 1, 1] - p[:, 0, 1]) * (p[:, 2, 0] - p[:, 0, 0])
        assert np.all(cross > 0), "every triangle counter-clockwise"
        assert 0.5 * cross.sum() == pytest.approx(lam.area, rel=1e-9)
        assert len(lam.triangles) == len(lam.outline) - 2
    # The poplar's leaf is wider than the cherry's (four-lobed vs ovate).
    assert trees["tulip_poplar"].lamina.area > 1.5 * trees["small_cherry"].lamina.area


def test_make_lamina_rejects_self_intersecting_outline():
    with pytest.raises(ValueError):
        make_lamina("bow", [[0, 0], [0.5, 0.6], [-0.4, 0.3], [0.5, 0.2], [0, 1]], 30, 0, 0.0, 0.0)


level = st.builds(
    LevelSpec,
    segments=st.integers(1, 5),
    length=st.floats(0.3, 1.0),
    length_var=st.floats(0, 0.3),
    diameter=st.floats(0.3, 0.9),
    taper=st.floats(0, 0.9),
    count=st.floats(0.5, 3.0),
    attach=st.tuples(st.floats(0, 0.5), st.floats(0.5, 1.0)),
    down_angle=st.floats(0, 90),
    roll=st.floats(-180, 180),
    curvature=st.floats(-90, 90),
    gravity=st.floats(-45, 45),
    up=st.floats(0, 1),
    cone=st.floats(0, 0.9),
)


@settings(max_examples=30)
@given(
    trunk=st.builds(LevelSpec, segments=st.integers(1, 8), length=st.floats(0.5, 5.0),
                    diameter=st.floats(0.05, 0.5), taper=st.floats(0, 0.9), curvature=st.floats(-30, 30),
                    lean=st.floats(0, 30)),
    levels=st.lists(level, min_size=0, max_size=3),
    leaves=st.integers(0, 200),
    seed=st.integers(0, 2**32),
)
def test_generator_invariants(trunk, levels, leaves, seed):
    base = read_spec(ta.load_preset("small_cherry").source)
    n_levels = 1 + len(levels)
    spec = TreeSpec(
        name="random", seed=seed, levels=(trunk, *levels),
        leaves=dataclasses.replace(base.leaves, count=leaves, winter_count=leaves // 3, levels=tuple(range(1, n_levels + 1))),
        lamina=base.lamina, physics=base.physics,
    )
    tree = generate(spec)
    check_invariants(tree)
    assert int((tree.kind == "leaf").sum()) == leaves
    again = generate(spec)
    assert tree.rest_positions.tobytes() == again.rest_positions.tobytes()
