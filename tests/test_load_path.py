"""The load path (issue #10, docs/design.md §12): whole-tree mechanics measured from the public API."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pytest

import treeanim as ta
from conftest import Uniform

DATA = Path(__file__).parent / "data"


@pytest.fixture(scope="module")
def cherry():
    return ta.load_preset("small_cherry")


def limb_lean(tree, speed, season=0.0, seconds=12.0, dt=1 / 30, **kw):
    """Mean downwind (+x) displacement of the trunk and main-limb tips (levels 1–2) over the
    second half of ``seconds`` in the default turbulent wind along +x, as a fraction of the
    tree's height (benchmarks/bench_lean.py measures the README's table so)."""
    sim = ta.Simulation(tree, wind=ta.WindField(speed=speed, direction=(1.0, 0.0, 0.0)), season=season, **kw)
    objs = np.flatnonzero((tree.kind == "branch") & (tree.level <= 2))
    tips = tree.object_start[objs] + tree.object_count[objs] - 1
    n = int(round(seconds / dt))
    acc = []
    for k in range(n):
        sim.step(dt)
        if k >= n // 2:
            acc.append(np.mean(sim.positions[tips, 0] - tree.rest_positions[tips, 0]))
    return float(np.mean(acc)) / float(np.ptp(tree.rest_positions[:, 1]))


def test_limbs_lean_visibly_and_faster_than_linearly_with_wind_speed(cherry):
    lean = {U: limb_lean(cherry, U) for U in (5.0, 15.0)}
    assert 0.005 < lean[5.0] < 0.08, "a breeze sways the limbs by centimetres, not millimetres or metres"
    assert lean[15.0] > 3.3 * lean[5.0], "drag is quadratic: 3× the wind leans more than 3× as far"
    paper = limb_lean(cherry, 15.0, load_path=False)
    assert lean[15.0] > 20 * paper, "the crown's drag reaches the trunk and the limbs"


def test_summer_crown_leans_more_than_the_bare_winter_tree(cherry):
    summer, winter = limb_lean(cherry, 30.0, 0.0), limb_lean(cherry, 30.0, 1.0)
    assert summer > 1.2 * winter > 0
    assert summer > 0.03, "a gale leans the crown several percent of the height (Fig. 11)"


def test_a_twig_keeps_its_wood_stiffness_when_its_leaves_fall(cherry):
    """K = m·ω² with the leafy mass: bare in winter, the twig that carried the most leaves
    deflects under the same pull by its summer deflection × (f_summer/f_winter)², not by its
    bare mass's far softer K (issue #10's stiff winter shiver)."""
    n_leaves = np.bincount(cherry.parent[cherry.kind == "leaf"], minlength=cherry.n_objects)
    twig = int(np.argmax(n_leaves))
    base, tip = cherry.object_start[twig], cherry.object_start[twig] + cherry.object_count[twig] - 1
    bend, w2 = [], []
    for season in (0.0, 1.0):
        sim = ta.Simulation(cherry, season=season)
        w2.append(sim.modes.f[twig, 0] * sim.modes.f[twig, 2])
        sim.pull(twig, (0.0, 0.0, 0.02))
        for _ in range(240):
            sim.step(1 / 60)
        chord = sim.positions[tip] - sim.positions[base]
        bend.append(np.linalg.norm(chord - (cherry.rest_positions[tip] - cherry.rest_positions[base])))
    assert n_leaves[twig] >= 10 and bend[1] > 0
    assert bend[0] / bend[1] == pytest.approx(w2[1] / w2[0], rel=0.15)


def test_pulling_a_limb_moves_the_trunk(cherry):
    limb = int(np.flatnonzero(cherry.level == 2)[0])
    trunk_tip = cherry.object_start[0] + cherry.object_count[0] - 1
    moved = {}
    for load_path in (True, False):
        sim = ta.Simulation(cherry, load_path=load_path)
        sim.pull(limb, (0.0, 0.0, 100.0))
        for _ in range(120):
            sim.step(1 / 60)
        moved[load_path] = sim.positions[trunk_tip] - cherry.rest_positions[trunk_tip]
    assert np.linalg.norm(moved[False]) < 1e-12  # the paper: a pull stays on its object
    assert moved[True][2] > 1e-3, "the trunk bends towards the pull by millimetres or more"


def test_a_new_pull_builds_up_without_a_jump(cherry):
    limb = int(np.flatnonzero(cherry.level == 3)[0])
    tip = cherry.object_start[limb] + cherry.object_count[limb] - 1
    sim = ta.Simulation(cherry)
    sim.pull(limb, (0.0, 0.0, 5.0))
    path = []
    for _ in range(180):
        sim.step(1 / 60)
        path.append(np.linalg.norm(sim.positions[tip] - cherry.rest_positions[tip]))
    final = path[-1]
    assert final > 0.01
    assert path[0] < 0.1 * final, "the first 1/60 s step is a small part of the way"
    assert np.max(np.diff(path)) < 0.1 * final, "no frame jumps a tenth of the deflection"
    assert max(path) < 1.05 * final, "held, it approaches critically damped: no overshoot"


def swing_amplitudes(tree, obj, speed, seconds=4.0, dt=1 / 60):
    """Pull ``obj`` across the wind, release it, and return |tip − its late mean| per step."""
    sim = ta.Simulation(tree, wind=Uniform((speed, 0.0, 0.0)) if speed else None)
    tip = tree.object_start[obj] + tree.object_count[obj] - 1
    for _ in range(120):
        sim.step(dt)  # settle in the wind first
    sim.pull(obj, (0.0, 0.0, 3.0))
    for _ in range(120):
        sim.step(dt)
    sim.release()
    z = []
    for _ in range(int(seconds / dt)):
        sim.step(dt)
        z.append(sim.positions[tip, 2])
    z = np.array(z)
    return np.abs(z - z[len(z) // 2:].mean())


def test_moving_air_damps_a_released_limb_faster_than_calm_air(cherry):
    obj = int(np.flatnonzero((cherry.kind == "branch") & (cherry.level == 3))[0])
    calm = swing_amplitudes(cherry, obj, 0.0)
    windy = swing_amplitudes(cherry, obj, 10.0)
    n = len(calm)
    late = slice(n // 3, 2 * n // 3)  # after the first swing, before it has died out
    assert windy[late].max() / windy[:20].max() < 0.8 * calm[late].max() / calm[:20].max()


def _reference_module():
    spec = importlib.util.spec_from_file_location("make_paper_reference", DATA / "make_paper_reference.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


@pytest.mark.parametrize("dt", [1 / 30, 1 / 10])
def test_a_released_limb_dies_away_in_calm_air_at_long_steps(cherry, dt):
    """The base excitation is explicit: at 1/30 s steps a bare winter cherry's limbs, released,
    once swung ever wider (the crown's inertia fed back through the limbs that carry it); the
    load path sub-steps, so the swing decays at any frame time."""
    sim = ta.Simulation(cherry, season=1.0)
    wood = np.repeat(cherry.kind == "branch", cherry.object_count)  # (falling leaves drift)
    limb = int(np.flatnonzero(cherry.level == 3)[0])
    sim.pull(limb, (0.0, 0.0, 5.0))
    for _ in range(int(2 / dt)):
        sim.step(dt)
    sim.release(limb)
    swing = []
    for window in range(2):
        pos = []
        for _ in range(int(5 / dt)):
            sim.step(dt)
            pos.append(sim.positions[wood])
        pos = np.array(pos)
        swing.append(float(np.ptp(pos, axis=0).max()))
        for _ in range(int(20 / dt)):
            sim.step(dt)
    assert swing[0] > 0.01, "the release sets the tree swinging"
    # (a bare tree rings long: its ζ is 2–10 % in winter, REALISM.md)
    assert swing[1] < 0.3 * swing[0], "25 s later it swings far less, never more"


def test_a_long_frame_is_the_same_as_its_sixtieths(cherry):
    """``step(1/30)`` takes the load path in two sub-steps of 1/60 s: a caller at 30 fps sees
    the tree a 60 fps caller sees, gusts and pulls included."""
    sims = [ta.Simulation(cherry, wind=ta.WindField(speed=12.0, seed=4)) for _ in range(2)]
    for sim in sims:
        sim.pull(int(np.flatnonzero(cherry.level == 2)[0]), (0.0, 0.0, 20.0))
    for _ in range(30):
        sims[0].step(1 / 30)
        sims[1].step(1 / 60)
        sims[1].step(1 / 60)
    assert sims[0].time == pytest.approx(sims[1].time)
    np.testing.assert_allclose(sims[0].positions, sims[1].positions, atol=1e-9)


def test_load_path_off_reproduces_the_paper_model_bit_for_bit():
    """``load_path=False`` gives the poses the paper model gave before the load path (recorded
    at commit 4ed910f by tests/data/make_paper_reference.py)."""
    ref = np.load(DATA / "paper_reference.npz")
    mod = _reference_module()
    for name, scenario in mod.SCENARIOS.items():
        pos, rot = mod.run(*scenario, load_path=False)
        np.testing.assert_array_equal(pos, ref[f"{name}/positions"], err_msg=name)
        if f"{name}/rotations" in ref:
            np.testing.assert_array_equal(rot, ref[f"{name}/rotations"], err_msg=name)


def test_switching_the_model_restarts_from_rest_and_both_run(cherry):
    sim = ta.Simulation(cherry, wind=Uniform((10.0, 0.0, 0.0)))
    for _ in range(10):
        sim.step(1 / 30)
    t = sim.time
    sim.load_path = False
    assert not sim.load_path and sim.time == t
    np.testing.assert_allclose(sim.positions, cherry.rest_positions, atol=1e-12)
    for _ in range(10):
        sim.step(1 / 30)
    sim.load_path = True
    for _ in range(10):
        sim.step(1 / 30)
    assert np.isfinite(sim.positions).all() and sim.load_path


def _leaf_pose(tree, wind_speed, seconds, pulls=(), dt=1 / 60):
    """Each leaf's petiole on its twig after ``seconds`` in a wind along +x (0: calm) with the
    given (leaf, force) pulls held: how far its tip has moved from rest (K,) and the rotation
    of its lamina (K, 3, 3), both relative to the twig's segment at the leaf's attach node."""
    wind = ta.WindField(speed=wind_speed, direction=(1.0, 0.0, 0.0)) if wind_speed else None
    sim = ta.Simulation(tree, wind=wind)
    for i, f in pulls:
        sim.pull(i, f)
    for _ in range(int(round(seconds / dt))):
        sim.step(dt)
    leaves = np.flatnonzero(tree.kind == "leaf")
    tips, att = tree.object_start[leaves] + tree.object_count[leaves] - 1, tree.attach_node[leaves]
    Ra, P, X = sim.rotations[att], sim.positions, tree.rest_positions
    moved = np.einsum("kji,kj->ki", Ra, P[tips] - P[att]) - (X[tips] - X[att])
    return np.linalg.norm(moved, axis=1), np.einsum("kji,kjl->kil", Ra, sim.rotations[tips])


def _turn(R):
    return np.degrees(np.arccos(np.clip((np.trace(R, axis1=1, axis2=2) - 1.0) / 2.0, -1.0, 1.0)))


def test_a_hinged_petiole_bends_as_its_chain_of_joints(cherry, monkeypatch):
    """The load path solves a petiole (and a grass blade) at its first joint only and turns the
    later joints by fixed multiples of that angle (docs/design.md §12): the leaves move on
    their twigs as when every joint is solved (Eq. 8 at each), under a pull and in a gale."""
    leaves = np.flatnonzero(cherry.kind == "leaf")
    pulled = leaves[::97][:8]
    pulls = [(int(i), np.array([0.0, -0.02, 0.015])) for i in pulled]  # 2.5 grams-force, held

    def run():
        return _leaf_pose(cherry, 0.0, 2.0, pulls) + _leaf_pose(cherry, 25.0, 2.0)

    hinged = run()
    from treeanim.physics import bending, derived

    monkeypatch.setattr(derived, "BendingPlan", lambda tree, frames, hinge=None: bending.BendingPlan(tree, frames))
    chain = run()
    k = np.searchsorted(leaves, pulled)
    (d_h, r_h, g_d_h, g_h), (d_c, r_c, g_d_c, g_c) = hinged, chain
    assert np.all(d_c[k] > 4e-4) and np.all(_turn(r_c[k]) > 3.0), "the pull bends the petioles"
    for h, c in ((d_h[k], d_c[k]), (_turn(r_h[k]), _turn(r_c[k]))):  # the pulled tips, their laminas' tilt
        err = np.abs(h / c - 1.0)
        assert np.median(err) < 0.1 and err.max() < 0.35, err
    # In a gale every leaf bends and twists on its twig about as far with one hinge.
    q_h, q_c = (np.percentile(_turn(g), [25, 50, 90]) for g in (g_h, g_c))
    assert q_c[1] > 5.0, q_c
    np.testing.assert_allclose(q_h, q_c, rtol=0.2)
    np.testing.assert_allclose(np.median(g_d_h), np.median(g_d_c), rtol=0.2)
