"""Levels of detail of the tree model (issue 28, docs/design.md §17): a coarser tree steps fewer
degrees of freedom, a switch moves no node and jolts none, a tree at full detail steps as if the
others were whole, the energy in calm air never rises; levels from the camera, the held tree
whole; bad levels refused in one line."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import treeanim as ta
from app_helpers import DT, W, branch_on_screen, open_viewer, press
from conftest import Uniform, grass_patch
from treeanim.model.scene import make_scene
from treeanim.physics.lod import DETAIL_PIXELS, HYSTERESIS, MAX_DETAIL, choose_detail, tree_extents
from treeanim.physics.wind import WindField


@pytest.fixture(scope="module")
def scene():
    cherry = ta.load_preset("small_cherry")
    return make_scene([cherry, cherry, grass_patch()], [(0, 0, 0), (8, 0, 0), (0, 0, 6)], [0, 120, 0])


def gusty(sim, steps=30):
    sim.wind = WindField(speed=12.0)
    for _ in range(steps):
        sim.step(1 / 30)


def test_each_coarser_level_steps_fewer_degrees_of_freedom_and_what_rides_still_moves(scene):
    sim = ta.Simulation(scene)
    s = sim.structure
    whole = 3 * (len(s.parent) + len(s.leaf_body))
    dof = []
    for level in range(MAX_DETAIL + 1):
        sim.set_detail(level)
        dof.append(sim.active_dof)
    assert dof[0] == whole and dof[0] > 10 * dof[1] > 10 * dof[2] and dof[2] > dof[3] == 0, dof
    mine = scene.object_tree == 1  # one tree still: the others' degrees of freedom all stay
    sim.set_detail([0, MAX_DETAIL, 0])
    assert sim.active_dof == whole - 3 * (mine[s.obj].sum() + mine[s.leaf_obj].sum())
    sim.set_detail(1)  # the leaves ride their twigs rigidly, and move with them
    leaves = np.flatnonzero(scene.kind == "leaf")
    tips = scene.object_start[leaves] + scene.object_count[leaves] - 1
    gusty(sim)
    assert np.all(np.isfinite(sim.positions))
    assert np.linalg.norm(sim.positions[tips] - scene.rest_positions[tips], axis=1).mean() > 1e-3


def test_a_switch_moves_no_node_and_its_frame_moves_them_no_more_than_any_other(scene):
    sim = ta.Simulation(scene)
    gusty(sim)
    moves, switches = [], []
    for i, level in enumerate([0, 1, 2, 3, 0, 2, 0, 1, 3, 1, 0]):
        before = sim.positions
        sim.set_detail([level, (level + 1) % 4, 3 - level])
        assert np.array_equal(sim.positions, before)
        switches.append(len(moves))
        for _ in range(15):
            before = sim.positions
            sim.step(1 / 30)
            moves.append(np.abs(sim.positions - before).max())
    moves = np.array(moves)
    ordinary = np.delete(moves, switches)
    assert moves[switches].max() <= ordinary.max(), (moves[switches], ordinary.max())


def test_a_tree_at_full_detail_steps_as_if_the_others_were_whole(scene):
    mine = scene.tree_nodes(0)
    out = []
    for levels in ([0, 0, 0], [0, 2, 3], [0, 1, 1]):
        sim = ta.Simulation(scene)
        sim.set_detail(levels)
        gusty(sim, 40)
        out.append(sim.positions[mine])
    np.testing.assert_allclose(out[1], out[0], rtol=0, atol=1e-12)
    np.testing.assert_allclose(out[2], out[0], rtol=0, atol=1e-12)


def test_the_energy_in_calm_air_never_rises_at_mixed_levels_and_their_switches(scene):
    sim = ta.Simulation(scene, wind=Uniform((15.0, 0.0, 0.0)))
    for _ in range(30):
        sim.step(1 / 30)
    sim.wind = None
    E = [sim.energy]
    for levels in ([0, 1, 2], [2, 0, 1], [1, 2, 0], [3, 1, 0], [0, 0, 0], [1, 1, 3]):
        sim.set_detail(levels)
        for _ in range(30):
            sim.step(1 / 30)
            E.append(sim.energy)
    assert np.all(np.diff(E) <= 1e-9 * E[0]), np.max(np.diff(E))
    assert E[-1] < 0.1 * E[0]


def test_a_state_taken_at_mixed_levels_replays_exactly(scene):
    sim = ta.Simulation(scene, wind=WindField(speed=8.0))
    sim.set_detail([1, 2, 0])
    for _ in range(5):
        sim.step(1 / 30)
    state = sim.state
    runs = []
    for _ in range(2):
        sim.state = state
        for _ in range(10):
            sim.step(1 / 30)
        runs.append(sim.positions)
    assert np.array_equal(runs[0], runs[1])
    sim.state = sim.state  # posed whole again: the still trees' nodes were where they are
    assert np.array_equal(sim.positions, runs[1])
    sim.season = 0.9  # a new structure, the same levels
    sim.step(1 / 30)
    assert list(sim.detail) == [1, 2, 0] and np.all(np.isfinite(sim.positions))


def test_a_switch_after_switches_builds_exactly_what_a_build_from_scratch_would(scene):
    """A switch freezes only the trees whose level changed (the others' frozen parts are as a
    freeze would leave them): after several switches and steps, the reduced model, the state
    and the motion are bit for bit those built from scratch at those levels on that state."""
    sims = [ta.Simulation(scene, wind=WindField(speed=12.0)) for _ in range(2)]
    for levels in ([1, 2, 0], [3, 2, 1], [0, 2, 3], [2, 2, 1], [2, 0, 1]):
        sims[0].set_detail(levels)
        for _ in range(5):
            sims[0].step(1 / 30)
    sims[1].set_detail([2, 1, 1])
    sims[1].state = sims[0].state  # built from scratch on this state
    sims[0].set_detail([2, 1, 1])
    a, b = (sim._impl._lod for sim in sims)
    for name in ("bodies", "leaves", "body_index", "carried"):
        assert np.array_equal(getattr(a, name), getattr(b, name)), name
    for x, y in [(a.s, b.s), (sims[0].state.tree, sims[1].state.tree)]:
        for f in dataclasses.fields(x):
            assert np.array_equal(getattr(x, f.name), getattr(y, f.name)), f.name
    for _ in range(10):
        for sim in sims:
            sim.step(1 / 30)
    assert np.array_equal(sims[0].positions, sims[1].positions)


def test_a_held_tree_steps_at_full_detail(scene):
    branch = int(np.flatnonzero((scene.object_tree == 1) & (scene.level == 3))[0])
    out = []
    for level in (0, 3):
        sim = ta.Simulation(scene)
        sim.set_detail(level)
        sim.drag(branch, sim.point_position(branch) + (0.0, 0.0, 0.3))
        assert list(sim.detail) == [level, 0, level]
        for _ in range(20):
            sim.step(1 / 30)
        out.append(sim.positions[scene.tree_nodes(1)])
    assert np.abs(out[0] - scene.rest_positions[scene.tree_nodes(1)]).max() > 0.02
    np.testing.assert_allclose(out[1], out[0], rtol=0, atol=1e-12)
    sim.release()
    assert list(sim.detail) == [3, 3, 3]


@pytest.mark.parametrize("levels, words", [
    ([0, 1], "one integer per tree (3)"),
    ([0, 1, 4], "in 0..3"),
    ([0, -1, 0], "in 0..3"),
    ([0, 1.5, 0], "one integer per tree"),
    ("far", "one integer per tree"),
    (True, "one integer per tree"),
    ([[0, 1, 2]], "one integer per tree"),
])
def test_bad_levels_are_refused_in_one_line(scene, levels, words):
    sim = ta.Simulation(scene)
    with pytest.raises(ValueError, match=r"levels must be") as e:
        sim.set_detail(levels)
    assert words in str(e.value) and "\n" not in str(e.value)
    assert list(sim.detail) == [0, 0, 0]


def test_the_papers_model_refuses_levels_in_one_line():
    sim = ta.Simulation(ta.load_preset("small_cherry"), model="paper")
    with pytest.raises(ValueError, match="detail levels need model='tree'"):
        sim.set_detail(1)


def test_levels_follow_each_trees_height_on_the_screen_and_the_hero_is_whole():
    roots = np.array([[0.0, 0.0, d] for d in (5.0, 20.0, 60.0, 400.0)])
    heights = np.full(4, 3.0)
    eye = np.array([0.0, 1.5, 0.0])
    focal = 540.0  # 3 m at 5 m: 324 px; at 20 m: 81; at 60 m: 27; at 400 m: 4
    assert list(choose_detail(eye, roots, heights, focal)) == [0, 1, 2, 3]
    assert list(choose_detail(eye, roots, heights, focal, hero=[3])) == [0, 1, 2, 0]
    # just under a level's height a tree keeps the finer level it has; well under, it goes coarser
    edge = 3.0 * focal / DETAIL_PIXELS[1]
    near = np.array([[0.0, 0.0, edge * (1 + HYSTERESIS / 2)], [0.0, 0.0, edge * (1 + 2 * HYSTERESIS)]])
    assert list(choose_detail(eye, near, heights[:2], focal)) == [2, 2]
    assert list(choose_detail(eye, near, heights[:2], focal, current=np.array([1, 1]))) == [1, 2]
    assert list(choose_detail(eye, near, heights[:2], focal, current=np.array([3, 3]))) == [2, 2]


def test_tree_extents_are_each_trees_root_and_height(scene):
    roots, heights = tree_extents(scene)
    np.testing.assert_allclose(roots[:2], [(0, 0, 0), (8, 0, 0)], atol=1e-9)
    for k in range(3):
        y = scene.rest_positions[scene.tree_nodes(k), 1]
        assert heights[k] == pytest.approx(y.max() - y.min())


def test_the_viewer_keeps_the_tree_it_holds_whole_as_the_camera_leaves(no_display):
    from treeanim.app.headless import HeadlessWindow

    cherry = ta.load_preset("small_cherry")
    far = make_scene([cherry] * 3, [(0, 0, 0), (40, 0, 0), (80, 0, 0)], [0, 90, 200])
    for v in open_viewer(HeadlessWindow(W, 360), far):
        v.camera.target = np.array([0.0, 1.5, 0.0])
        v.camera.distance = 4.0
        v.advance(DT)
        assert v.sim.detail[0] == 0 and v.sim.detail[2] >= 2, v.sim.detail
        obj, x, y = branch_on_screen(v)
        hero = int(far.object_tree[obj])
        press(v, x, y)
        v.camera.distance = 300.0  # every tree a few pixels high
        for _ in range(3):
            v.advance(DT)
        assert v.sim.detail[hero] == 0 and sum(v.sim.detail) >= 2 * MAX_DETAIL, v.sim.detail


def test_a_tree_whose_twigs_and_leaves_ride_sways_in_the_wind_as_the_whole_tree_does():
    """What rides keeps its drag (lumped on its anchor): in an 8 m/s turbulent wind the cherry's
    top leans and sways at level 1 as it does whole (1 % and 8 % apart; with a third of the
    leaves' lumped drag, 40 % as far)."""
    cherry = ta.load_preset("small_cherry")
    top = int(np.argmax(cherry.rest_positions[:, 1]))
    lean, sway = [], []
    for level in (0, 1):
        sim = ta.Simulation(cherry, wind=WindField(speed=8.0, seed=2))
        sim.set_detail(level)
        x = []
        for _ in range(150):
            sim.step(1 / 30)
            x.append(sim.positions[top] - cherry.rest_positions[top])
        x = np.array(x[60:])
        lean.append(np.linalg.norm(x.mean(axis=0)))
        sway.append(x.std(axis=0).sum())
    assert lean[0] > 0.01 and lean[1] == pytest.approx(lean[0], rel=0.2), lean
    assert sway[1] == pytest.approx(sway[0], rel=0.2), sway
