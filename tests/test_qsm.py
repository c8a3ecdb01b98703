"""TreeQSM import (model/qsm/) and physical modal parameters (physics/physical.py)."""

from __future__ import annotations

import dataclasses
import re
from pathlib import Path

import numpy as np
import pytest
from scipy.io import savemat

import treeanim as ta
from test_simulation import fit_damped
from treeanim.cli import main
from treeanim.errors import PresetError, QSMError
from treeanim.model.build import ObjectSpec, assemble
from treeanim.model.geometry import arc_length, object_lengths
from treeanim.model.params import WOOD_TYPES, PhysicsParams
from treeanim.model.qsm import LEAF_SPACING, SPECIES, build_tree, load_qsm, synthetic_table, write_table
from treeanim.model.qsm.leaves import LEAVES_FOR_QSM_ONLY
from treeanim.physics.trace import trace_tips

ASSET = Path(__file__).resolve().parents[1] / "assets" / "qsm" / "synthetic_broadleaf.txt"


def row(radius, length, start, axis, parent, branch, order=0, pos=1):
    return [radius, length, *start, *axis, parent, 0, branch, order, pos, 0]


def small_table():
    """A 3-cylinder vertical stem (1 m each, z up) with a 2-cylinder branch along +x from the
    end of its second cylinder, and a twig from the end of the branch's first cylinder along +y."""
    z, x, y = (0, 0, 1), (1, 0, 0), (0, 1, 0)
    return np.array([
        row(0.20, 1.0, (0, 0, 0), z, 0, 1),
        row(0.18, 1.0, (0, 0, 1), z, 1, 1, pos=2),
        row(0.16, 1.0, (0, 0, 2), z, 2, 1, pos=3),
        row(0.08, 0.5, (0, 0, 2), x, 2, 2, order=1),
        row(0.06, 0.5, (0.5, 0, 2), x, 4, 2, order=1, pos=2),
        row(0.03, 0.4, (0.5, 0, 2), y, 4, 3, order=2),
    ], float)


# ---------------------------------------------------------------------------- import
def test_a_known_qsm_imports_with_its_topology_lengths_and_radii(tmp_path):
    path = tmp_path / "small.txt"
    write_table(path, small_table())
    tree = load_qsm(path)
    assert tree.kind.tolist() == ["branch"] * 3
    assert tree.object_count.tolist() == [4, 3, 2]  # cylinders + 1
    assert tree.parent.tolist() == [-1, 0, 1]
    assert tree.level.tolist() == [1, 2, 3]
    # y up: the stem stands on the origin; (x, y, z) -> (x, z, -y)
    np.testing.assert_allclose(tree.rest_positions[tree.object_nodes(0)], [[0, 0, 0], [0, 1, 0], [0, 2, 0], [0, 3, 0]],
                               atol=1e-9)
    np.testing.assert_allclose(tree.rest_positions[tree.object_nodes(1)], [[0, 2, 0], [0.5, 2, 0], [1.0, 2, 0]],
                               atol=1e-9)
    np.testing.assert_allclose(tree.rest_positions[tree.object_nodes(2)], [[0.5, 2, 0], [0.5, 2, -0.4]], atol=1e-9)
    assert tree.attach_node[1] == 2 and tree.attach_node[2] == tree.object_start[1] + 1  # end of the 2nd / 1st cylinder
    # diameters: 2r at a branch's base and tip, the mean where two cylinders meet
    np.testing.assert_allclose(tree.node_diameter[tree.object_nodes(0)], [0.40, 0.38, 0.34, 0.32])
    np.testing.assert_allclose(tree.node_diameter[tree.object_nodes(1)], [0.16, 0.14, 0.12])
    tree.validate()


def test_the_synthetic_asset_imports_every_cylinder_and_branch():
    table = np.loadtxt(ASSET, skiprows=1)
    tree = load_qsm(ASSET)
    assert tree.n_objects == len(np.unique(table[:, 10]))  # one object per branch
    assert tree.n_nodes == len(table) + tree.n_objects
    seg = np.linalg.norm(np.diff(tree.rest_positions, axis=0), axis=1)
    inner = np.ones(len(seg), bool)
    inner[tree.object_start[1:] - 1] = False
    assert seg[inner].sum() == pytest.approx(table[:, 1].sum(), rel=1e-5)  # every cylinder's length
    assert tree.node_diameter.max() == pytest.approx(2 * table[:, 0].max(), rel=1e-6)
    assert tree.node_diameter.min() == pytest.approx(2 * table[:, 0].min(), rel=1e-6)
    height = tree.rest_positions[:, 1].max()
    assert tree.rest_positions[tree.object_nodes(0)][-1, 1] == pytest.approx(15.0, rel=1e-5)  # the stem
    assert height >= 15.0 and tree.rest_positions[:, 1].min() == pytest.approx(0.0, abs=1e-9)


def test_text_csv_struct_and_matrix_mat_files_build_the_same_tree(tmp_path):
    table = synthetic_table(limbs=3, twigs=2)
    write_table(tmp_path / "a.txt", table)
    np.savetxt(tmp_path / "b.csv", table, delimiter=",", fmt="%.6f")
    cyl = {"radius": table[:, 0], "length": table[:, 1], "start": table[:, 2:5], "axis": table[:, 5:8],
           "parent": table[:, 8], "extension": table[:, 9], "branch": table[:, 10], "BranchOrder": table[:, 11],
           "PositionInBranch": table[:, 12], "added": table[:, 13]}
    savemat(tmp_path / "c.mat", {"QSM": {"cylinder": cyl}})
    savemat(tmp_path / "d.mat", {"cylinders": np.hstack([table[:, :13], np.zeros((len(table), 4))])})  # 17 columns
    trees = [load_qsm(tmp_path / n) for n in ("a.txt", "b.csv", "c.mat", "d.mat")]
    for t in trees[1:]:
        np.testing.assert_allclose(t.rest_positions, trees[0].rest_positions, atol=2e-6)
        assert np.array_equal(t.parent, trees[0].parent)


def test_a_branch_starting_mid_cylinder_snaps_to_its_nearest_node_with_what_grows_on_it(tmp_path):
    t = small_table()
    t[3:5, 4] -= 0.2  # the branch starts 0.2 m below the stem's node (and its twig with it)
    t[5, 4] -= 0.2
    tree = build_tree(t)
    np.testing.assert_allclose(tree.rest_positions[tree.object_start[1]], [0, 2, 0], atol=1e-9)
    np.testing.assert_allclose(tree.rest_positions[tree.object_nodes(2)], [[0.5, 2, 0], [0.5, 2, -0.4]], atol=1e-9)


# ---------------------------------------------------------------------------- refusals
def refuse(tmp_path, table_or_text, match):
    path = tmp_path / "bad.txt"
    if isinstance(table_or_text, str):
        path.write_text(table_or_text)
    else:
        write_table(path, table_or_text)
    with pytest.raises(QSMError, match=match) as e:
        load_qsm(path)
    msg = str(e.value)
    assert "\n" not in msg and msg.startswith(str(path))
    assert isinstance(e.value, PresetError)  # the command line and the panel catch it as a preset's
    return msg


def test_refuses_a_cycle(tmp_path):
    t = small_table()
    t[3, 8], t[4, 8] = 5, 4  # rows 4 and 5 are each other's parent
    refuse(tmp_path, t, r"row 4 \(line 5\): its parents lead round a cycle")


def test_refuses_a_cylinder_that_is_its_own_parent(tmp_path):
    t = small_table()
    t[2, 8] = 3
    refuse(tmp_path, t, r"row 3 .*its own parent")


def test_refuses_an_orphan_whose_parent_does_not_exist(tmp_path):
    t = small_table()
    t[4, 8] = 99
    refuse(tmp_path, t, r"row 5 .*parent 99 names no cylinder \(orphan\)")


def test_refuses_a_second_cylinder_without_a_parent(tmp_path):
    t = small_table()
    t[5, 8] = 0
    refuse(tmp_path, t, r"row 6 .*parent 0 \(no parent\), but row 1 already starts the stem")


@pytest.mark.parametrize("col,value,what", [(0, np.nan, "radius is nan"), (1, np.inf, "length is inf"),
                                            (3, np.nan, "start_y is nan")])
def test_refuses_a_non_finite_number(tmp_path, col, value, what):
    t = small_table()
    t[2, col] = value
    refuse(tmp_path, t, rf"row 3 .*{what}; expected a finite number")


@pytest.mark.parametrize("col,value,what", [(0, 0.0, "radius is 0"), (1, -0.5, "length is -0.5"),
                                            (0, 1e300, "radius is 1e\\+300"), (0, 5e-5, "radius is 5e-05"),
                                            (1, 1e3, "length is 1000")])
def test_refuses_a_radius_or_length_no_tree_has(tmp_path, col, value, what):
    """Issue 31: a radius of 1e300 gave an OverflowError traceback, subnormal radii an
    uncaught ValueError from deep inside."""
    t = small_table()
    t[1, col] = value
    refuse(tmp_path, t, rf"row 2 .*{what}; expected 0.0001 to (10|150) m")


def test_refuses_a_table_scaled_far_beyond_a_tree(tmp_path):
    """Issue 31: every size times 1e150 gave 'repeats may not contain negative values'."""
    t = small_table()
    t[:, :5] *= 1e150
    refuse(tmp_path, t, r"row 1 .*radius is .*; expected 0.0001 to 10 m")


def test_refuses_a_start_far_from_the_origin_but_loads_a_georeferenced_scan(tmp_path):
    """Issue 31: a start coordinate of 1e308 overflowed. A scan in UTM coordinates (hundreds
    of kilometres east, thousands north) is a tree as any other."""
    t = small_table()
    t[2, 3] = 1e308
    refuse(tmp_path, t, r"row 3 .*the start \(.*1e\+308.*\) is more than 1e\+07 m from the origin")
    t = small_table()
    t[:, 2:4] += (6.0e5, 5.7e6)
    path = tmp_path / "utm.txt"
    write_table(path, t)
    assert load_qsm(path).n_objects == build_tree(small_table()).n_objects


def test_refuses_an_empty_table(tmp_path):
    refuse(tmp_path, "radius length start_x\n\n# nothing here\n", "empty table: no cylinder rows")


def test_refuses_a_wrong_column_count(tmp_path):
    text = "\n".join(" ".join(str(v) for v in r) for r in small_table()[:, :12])
    refuse(tmp_path, text, r"row 1 \(line 1\): 12 columns; expected 14")


def test_refuses_a_row_with_a_word_in_it(tmp_path):
    lines = [" ".join(str(v) for v in r) for r in small_table()]
    lines[3] = lines[3].replace("0.08", "thick", 1)
    refuse(tmp_path, "\n".join(lines), r"row 4 \(line 4\): column 1 \(radius\) is 'thick', not a number")


def test_refuses_a_mat_file_without_a_cylinder_table(tmp_path):
    savemat(tmp_path / "x.mat", {"points": np.zeros((5, 3))})
    with pytest.raises(QSMError, match=r"x\.mat: expected a TreeQSM 'cylinder' struct .* found variables points"):
        load_qsm(tmp_path / "x.mat")


def test_the_command_line_reads_a_qsm_and_reports_a_bad_one_in_one_line(tmp_path, capsys):
    assert main(["info", str(ASSET), "--leaves", "cherry"]) == 0
    out = capsys.readouterr().out
    assert "synthetic_broadleaf" in out and "leaf" in out
    bad = small_table()
    bad[2, 0] = -1
    write_table(tmp_path / "bad.txt", bad)
    assert main(["info", str(tmp_path / "bad.txt")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "row 3" in err and "radius is -1;" in err
    assert main(["info", "small_cherry", "--leaves", "cherry"]) == 2  # a preset has its own leaves
    assert LEAVES_FOR_QSM_ONLY in capsys.readouterr().err
    assert main(["info", str(ASSET), "--leaves", "cherry:many"]) == 2
    assert "expected leaves per metre of twig in (0, 1000]" in capsys.readouterr().err
    assert main(["info", "large_cherry", "--modes", "physical"]) == 0
    assert "modes: physical (beam theory); the trunk sways at" in capsys.readouterr().out
    assert main(["info", "large_cherry"]) == 0
    assert "modes: physical" not in capsys.readouterr().out


# ---------------------------------------------------------------------------- leaves
def test_leaves_grow_only_on_twigs_and_free_tips():
    species = SPECIES["cherry"]
    tree = load_qsm(ASSET, leaves="cherry")
    leaf = np.flatnonzero(tree.kind == "leaf")
    assert len(leaf) > 1000 and tree.lamina is not None
    on = tree.attach_node[leaf]
    # the node a leaf sits on ends a piece of a cylinder at most the twig diameter thick (within
    # the taper along that cylinder), or lies on the last cylinder of a free tip
    twig = 0.5 * (tree.node_diameter[on] + tree.node_diameter[on - 1]) <= 1.1 * species.twig_diameter
    tips = tree.object_start + tree.object_count - 1
    branch = tree.parent[leaf]
    free = ~np.isin(tips[branch], tree.attach_node[tree.kind == "branch"])  # nothing grows on its tip
    arc = arc_length(tree)
    last = arc[tips[branch]] - arc[on] < 0.5  # on its last cylinder (the asset's are at most 0.5 m)
    assert np.all(twig | (free & last)) and np.any(~twig) and np.any(twig)
    assert np.all(tree.kind[tree.parent[leaf]] == "branch")
    # leaves spread along the twigs: no twig stretch longer than the leaf spacing bears them
    gap = np.linalg.norm(tree.rest_positions[on] - tree.rest_positions[on - 1], axis=1)
    assert gap.max() <= LEAF_SPACING + 1e-9
    # leafless: the same wood (its leaf-bearing cylinders in one piece), no leaves
    bare = load_qsm(ASSET)
    assert bare.stats()["leaves"] == 0
    wood = tree.kind == "branch"
    np.testing.assert_allclose(object_lengths(bare), object_lengths(tree)[wood], rtol=1e-12)
    ends = np.concatenate([tree.object_start[wood], (tree.object_start + tree.object_count - 1)[wood]])
    bare_ends = np.concatenate([bare.object_start, bare.object_start + bare.object_count - 1])
    np.testing.assert_allclose(bare.rest_positions[bare_ends], tree.rest_positions[ends], atol=1e-12)


def test_an_unknown_species_is_refused():
    with pytest.raises(QSMError, match="unknown species; expected none or one of cherry"):
        load_qsm(ASSET, leaves="baobab")


# ---------------------------------------------------------------------------- physical modes
def cylinder(length=10.0, diameter=0.3, segments=6, wood=WOOD_TYPES["hardwood"]):
    pts = np.column_stack([np.zeros(segments + 1), np.linspace(0, length, segments + 1), np.zeros(segments + 1)])
    return assemble([ObjectSpec(pts, np.full(segments + 1, diameter))], name="cylinder",
                    physics=PhysicsParams(**wood))


def beam_theory(length, diameter, wood):
    E, rho = wood["wood_youngs_modulus"], wood["wood_density"]
    area, inertia = np.pi * diameter**2 / 4, np.pi * diameter**4 / 64
    return 1.875104**2 / (2 * np.pi) * np.sqrt(E * inertia / (rho * area * length**4))


@pytest.mark.parametrize("length,diameter,segments,wood", [(10.0, 0.3, 1, "hardwood"), (10.0, 0.3, 6, "hardwood"),
                                                           (3.0, 0.05, 4, "softwood")])
def test_a_uniform_cylinder_has_the_first_cantilever_frequency(length, diameter, segments, wood):
    w = WOOD_TYPES[wood]
    sim = ta.Simulation(cylinder(length, diameter, segments, w), modes="physical", model="paper")
    assert sim.modal == "physical"
    np.testing.assert_allclose(sim.modes.f[0], beam_theory(length, diameter, w), rtol=0.02)
    assert sim.modes.zeta[0, 0] == pytest.approx(w["wood_damping"], abs=0.01)  # its wood, and a little air


def test_a_released_cylinder_sways_at_the_beam_frequency():
    w = WOOD_TYPES["hardwood"]
    tree = cylinder(wood=w)
    f_beam = beam_theory(10.0, 0.3, w)
    sim = ta.Simulation(tree, modes="physical", model="paper")
    sim.pull(0, (2000.0, 0.0, 0.0))
    sim.step(30.0)  # a held pull settles
    sim.release()
    dt = 1 / 60
    t, tips = trace_tips(sim, 0, 12.0, dt)
    x = tips[:, 0, 0] - tree.rest_positions[-1, 0]
    assert np.ptp(x) > 0.01
    fm, zm = fit_damped(t - t[0], x)
    assert fm == pytest.approx(f_beam, rel=0.02)
    assert zm == pytest.approx(w["wood_damping"], abs=0.02)


def test_paper_modes_stay_the_default_for_presets_and_physical_is_selectable():
    tree = ta.load_preset("small_cherry")
    paper = ta.Simulation(tree, model="paper")
    assert paper.modal == "paper"
    rng = tree.physics.modes("branch", 0.0)
    assert rng.f[0] - 1e-9 <= paper.modes.f[tree.kind == "branch", 0].min()
    phys = ta.Simulation(tree, modes="physical", model="paper")
    assert not np.allclose(phys.modes.f, paper.modes.f)
    paper.modal = "physical"
    np.testing.assert_allclose(paper.modes.f, phys.modes.f)
    with pytest.raises(ValueError, match="modes must be one of"):
        ta.Simulation(tree, modes="guess", model="paper")


def trunk_modes(height, dbh, leaves=None, season=0.0):
    tree = build_tree(synthetic_table(height=height, dbh=dbh), leaves=leaves)
    sim = ta.Simulation(tree, season=season, model="paper")  # an imported tree: physical modes by default
    return sim.modes.f[0, 0], sim.modes.zeta[0, 0]


def test_frequency_scales_with_dbh_over_height_squared():
    family = [(10.0, 0.25), (12.0, 0.3), (15.0, 0.3), (15.0, 0.45), (20.0, 0.5), (25.0, 0.45), (25.0, 0.7)]
    ratio = np.array([dbh / h**2 for h, dbh in family])
    f = np.array([trunk_modes(h, dbh)[0] for h, dbh in family])
    slope = np.sum(f * ratio) / np.sum(ratio * ratio)  # f = c · DBH/H², through the origin
    assert np.max(np.abs(f / (slope * ratio) - 1)) < 0.1
    assert np.corrcoef(ratio, f)[0, 1] > 0.99


def test_leaves_lower_the_frequency_and_raise_the_damping():
    f_off, z_off = trunk_modes(15.0, 0.4)
    f_on, z_on = trunk_modes(15.0, 0.4, leaves="cherry")
    assert f_on < f_off and z_on > z_off
    # the leaves' season: the same tree at winter has lost them
    f_winter, z_winter = trunk_modes(15.0, 0.4, leaves="cherry", season=1.0)
    assert f_on < f_winter and z_on > z_winter
    # and so for a preset's twigs (their stubs ring too fast to show: critically damped)
    tree = ta.load_preset("small_cherry")
    summer, winter = (ta.Simulation(tree, season=s, modes="physical", model="paper") for s in (0.0, 1.0))
    twigs = (tree.kind == "branch") & np.isin(np.arange(tree.n_objects), tree.parent[tree.kind == "leaf"])
    assert np.all(summer.modes.f[twigs, 0] < winter.modes.f[twigs, 0])
    assert np.all(summer.modes.zeta[twigs, 0] == 1.0)


@pytest.mark.parametrize("name", ["small_cherry", "large_cherry", "tulip_poplar"])
def test_presets_with_physical_modes_stay_calm_in_a_gale(name):
    tree = ta.load_preset(name)
    sim = ta.Simulation(tree, wind=ta.WindField(speed=25.0, seed=1), modes="physical", model="paper")
    for _ in range(120):
        sim.step(1 / 60)
    height = np.ptp(tree.rest_positions[:, 1])
    wood = np.repeat(tree.kind == "branch", tree.object_count)
    moved = np.linalg.norm(sim.positions - tree.rest_positions, axis=1)[wood]
    assert np.all(np.isfinite(moved)) and moved.max() < 0.1 * height  # (unstable, they flew apart: > height)


def test_physical_parameters_are_checked():
    tree = cylinder()
    sim = ta.Simulation(tree, modes="physical", model="paper")
    with pytest.raises(ValueError, match=r"physics\.wood_youngs_modulus: expected a number in \[1, 1e\+12\], got 0\.0"):
        sim.physics = dataclasses.replace(tree.physics, wood_youngs_modulus=0.0)


@pytest.mark.parametrize("seed", range(40))
def test_a_mutated_table_builds_a_valid_tree_or_says_why_in_one_line(seed):
    rng = np.random.default_rng(seed)
    table = synthetic_table(limbs=4, twigs=2, seed=seed)
    for _ in range(rng.integers(1, 4)):
        r, c = rng.integers(len(table)), rng.integers(14)
        table[r, c] = rng.choice([0.0, -1.0, np.nan, np.inf, 1e-12, 1e6, table[rng.integers(len(table)), c],
                                  float(rng.integers(-2, len(table) + 3))])
    try:
        tree = build_tree(table, name="mutated", leaves=rng.choice([None, "cherry"]))
    except QSMError as e:
        assert "\n" not in str(e) and str(e).startswith("mutated:")
    else:
        tree.validate()
        assert np.all(np.isfinite(tree.rest_positions)) and np.all(tree.node_diameter > 0)


def test_saving_a_models_physics_as_a_preset_is_refused_clearly(tmp_path):
    from treeanim.app.save import save_preset

    tree = load_qsm(ASSET)
    with pytest.raises(ValueError, match="not a preset file; there is no preset shape"):
        save_preset(tmp_path / "x.toml", tree, tree.physics)
    assert not (tmp_path / "x.toml").exists()


@pytest.mark.parametrize("where", ["next", "last"])
def test_refuses_a_zero_length_segment(tmp_path, where):
    t = small_table()
    if where == "next":
        t[1, 2:5] = t[0, 2:5]  # row 2 starts where row 1 starts
        refuse(tmp_path, t, r"row 1 .*a zero-length segment")
    else:
        t[2, 1] = 1e-12  # the stem's last cylinder: shorter than any tree's
        with pytest.raises(QSMError, match=r"^stem: row 3: length is 1e-12; expected 0.0001 to 150 m"):
            build_tree(t, name="stem")


def test_a_stiff_stub_twig_is_just_stiff_in_either_model():
    """Issue 26: three Wytham scans were refused, their stub twigs computing to 14–20 kHz."""
    stem = np.outer(np.linspace(0.0, 3.0, 4), (0.0, 1.0, 0.0))
    stub = stem[2] + np.outer(np.linspace(0.0, 0.004, 2), (1.0, 0.0, 0.0))
    tree = assemble([ObjectSpec(stem, np.linspace(0.2, 0.1, 4), "branch", 1),
                     ObjectSpec(stub, np.array([0.06, 0.05]), "branch", 2, parent=0, attach=2)], name="stub")
    for model in ("tree", "paper"):
        sim = ta.Simulation(tree, wind=ta.WindField(speed=20.0), model=model,
                            **({"modes": "physical"} if model == "paper" else {}))
        for _ in range(30):
            sim.step(1 / 60)
        assert np.isfinite(sim.positions).all()


def test_a_chain_of_five_thousand_nested_branches_has_finite_modes(tmp_path):
    """Issue 31: 5,000 nested one-cylinder branches gave the tip NaN modes (one running sum
    over the whole tree lost the small outer branches to round-off): `info` printed nan–nan.
    The tip of the deep chain sways as the tip of a short one does."""
    def tip_modes(n):
        t = np.zeros((n, 14))
        t[:, 0], t[:, 1] = 0.01, 0.05
        t[:, 4] = np.arange(n) * 0.05  # straight up, z
        t[:, 7] = 1.0
        t[:, 8] = np.arange(n)  # each row's parent is the row before (1-based; the first: 0)
        t[:, 10] = np.arange(1, n + 1)  # each its own branch
        t[:, 11] = np.arange(n)
        path = tmp_path / f"chain{n}.txt"
        write_table(path, t)
        return ta.Simulation(load_qsm(path), model="paper").modes

    deep, short = tip_modes(5000), tip_modes(50)
    assert np.isfinite(deep.f).all() and np.isfinite(deep.zeta).all()
    np.testing.assert_allclose(deep.f[-1], short.f[-1], rtol=1e-3)


def test_a_million_row_table_is_refused_before_it_is_parsed(tmp_path):
    """Issue 31: a 1,000,000-row table was refused only after every row was parsed (30–50 s)."""
    path = tmp_path / "big.txt"
    path.write_text("0.01 0.05 0 0 0 0 0 1 0 0 1 0 0 0\n" * 1_000_000)
    with pytest.raises(QSMError, match=r"1,000,000 lines; a model may have at most 200,000 cylinders"):
        ta.load_tree(path)


def test_load_tree_reads_a_treeqsm_model_by_its_suffix_as_the_command_line_does(tmp_path):
    """Issue 31: ta.load_tree("scan.txt") said "not valid TOML" where the CLI read a TreeQSM model."""
    assert ta.load_tree(ASSET).n_objects == load_qsm(ASSET).n_objects
    assert ta.load_tree(ASSET, leaves="cherry").n_objects == load_qsm(ASSET, leaves="cherry").n_objects
    with pytest.raises(PresetError, match=re.escape(LEAVES_FOR_QSM_ONLY)):
        ta.load_tree(ASSET.parents[1] / "presets" / "beam.toml", leaves="cherry")


def test_a_complex_valued_mat_file_is_refused(tmp_path):
    """Issue 31: a complex-valued .mat was accepted with a ComplexWarning (its imaginary parts dropped)."""
    import scipy.io

    t = small_table()
    cyl = {"radius": t[:, 0] + 1j, "length": t[:, 1], "start": t[:, 2:5], "axis": t[:, 5:8], "parent": t[:, 8],
           "extension": t[:, 9], "branch": t[:, 10]}
    scipy.io.savemat(tmp_path / "c.mat", {"cylinder": cyl})
    with pytest.raises(QSMError, match="cylinder field 'radius' is not an array of 1 number"):
        load_qsm(tmp_path / "c.mat")


def test_make_synthetic_writes_the_committed_files_byte_for_byte(tmp_path, capsys):
    """Issue 31: running assets/qsm/make_synthetic.py dirtied the checkout (scipy's .mat header
    holds the time it was written). Run twice, it writes the committed files exactly."""
    import importlib.util

    script = ASSET.parent / "make_synthetic.py"
    spec = importlib.util.spec_from_file_location("make_synthetic", script)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    for run in ("first", "second"):
        (tmp_path / run).mkdir()
        module.main(tmp_path / run)
        for name in ("synthetic_broadleaf.txt", "synthetic_broadleaf.mat"):
            assert (tmp_path / run / name).read_bytes() == (ASSET.parent / name).read_bytes(), (run, name)
    assert load_qsm(tmp_path / "second" / "synthetic_broadleaf.mat").n_objects == ta.load_tree(ASSET).n_objects
