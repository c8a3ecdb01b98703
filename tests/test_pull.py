"""The viewer's grab controllers without a window (physics/pull.py): on the tree model a drag
handed to Simulation.drag, on the paper's a spring pull whose stiffness is the simulation's own
compliance (the grabbed point settles GAIN / (1 + GAIN) of the way)."""

from __future__ import annotations

import numpy as np
import pytest

import treeanim as ta
from treeanim.physics.pull import GAIN, SpringPull, TreeDrag, grab


def test_a_small_pull_settles_at_the_spring_share_of_the_way_on_the_paper_model():
    sim = ta.Simulation(ta.load_preset("beam"), wind=None, model="paper")
    tip = sim.tip_position(0)
    g = grab(sim, 0, tip, plane_normal=(0.0, 0.0, -1.0))
    assert isinstance(g, SpringPull)
    assert g.k == pytest.approx(GAIN / sim.compliance(0, g.node - int(sim.tree.object_start[0]), g.s, g.offset))
    g.aim(tip + [0.0, 0.0, 5.0], [0.02, 0.0, -1.0])  # a ray to 2 cm beside the tip, in the plane z = 0
    np.testing.assert_allclose(g.target, tip + [0.02 * 5.0, 0.0, 0.0])
    for j in range(300):
        g.step(sim, 1 / 60, exact=j % 3 == 0)
        sim.step(1 / 60)
    moved = np.linalg.norm(g.anchor(sim) - tip)
    assert moved == pytest.approx(GAIN / (1 + GAIN) * 0.1, rel=0.15)
    assert np.linalg.norm(g.force) <= g.f_max
    g.release(sim)
    assert not sim.pulls


#: The tree model's drag diverges when it holds a point short of the tip (found while porting
#: the viewer; physics/treestep.py's grab, not this controller).


def _bark_point(sim, k):
    """A point on the beam's bark, 1 cm off the axis in the middle of segment k."""
    nodes = sim.tree.object_nodes(0)
    return 0.5 * (sim.positions[nodes[k]] + sim.positions[nodes[k + 1]]) + [0.0, 0.0, 0.01]


def test_a_drag_on_the_tree_model_holds_the_picked_point_where_it_was_picked():
    sim = ta.Simulation(ta.load_preset("beam"), wind=None)
    tree = sim.tree
    picked = _bark_point(sim, 4)
    g = grab(sim, 0, picked, plane_normal=(0.0, 0.0, -1.0))
    assert isinstance(g, TreeDrag) and not sim.pulls
    L = np.linalg.norm(np.diff(tree.rest_positions[tree.object_nodes(0)], axis=0), axis=1)
    assert g.s == pytest.approx((L[:4].sum() + 0.5 * L[4]) / L.sum(), abs=1e-6)
    np.testing.assert_allclose(g.offset, [0.0, 0.0, 0.01], atol=1e-9)
    np.testing.assert_allclose(g.anchor(sim), picked, atol=1e-9)  # the picked point itself: no jump
    assert list(sim.drags) == [0]
    target = sim.drags[0][0]
    np.testing.assert_allclose(target, sim.point_position(0, g.s), atol=1e-9)
    g.aim(picked + [0.0, 0.0, 5.0], [0.03, 0.0, -1.0])  # 15 cm sideways in the plane z = picked z
    np.testing.assert_allclose(g.target, picked + [0.15, 0.0, 0.0], atol=1e-12)
    g.step(sim, 1 / 60)
    np.testing.assert_allclose(sim.drags[0][0], g.target - g.offset)
    g.release(sim)
    assert not sim.drags


@pytest.mark.parametrize("segment", [9, 4], ids=["tip", "middle"])
def test_a_drag_on_the_tree_model_brings_the_grabbed_point_to_the_cursor(segment):
    sim = ta.Simulation(ta.load_preset("beam"), wind=None)
    picked = _bark_point(sim, segment)
    if segment == 9:
        picked = sim.tip_position(0)
    g = grab(sim, 0, picked, plane_normal=(0.0, 0.0, -1.0))
    g.aim(picked + [0.0, 0.0, 5.0], [0.02, 0.0, -1.0])  # 10 cm sideways
    for j in range(120):
        g.step(sim, 1 / 60, exact=j % 3 == 0)
        sim.step(1 / 60)
    gap = g.anchor(sim) - g.target  # (the inextensible beam lifts its tip a little on the way)
    assert abs(gap[0]) < 0.1 * 0.1 and np.linalg.norm(gap) < 0.3 * 0.1, "the grabbed point follows the cursor"
    assert np.array_equal(g.grabbed_point(sim, exact=False), g.anchor(sim))
    g.release(sim)
    assert not sim.drags


def test_grabbing_a_leaf_on_the_tree_model_holds_it_where_it_hangs():
    sim = ta.Simulation(ta.load_preset("small_cherry"), wind=None)
    leaf = int(np.flatnonzero(sim.tree.kind == "leaf")[0])
    nodes = sim.tree.object_nodes(leaf)
    picked = sim.positions[nodes[-1]]
    g = grab(sim, leaf, picked, plane_normal=(0.0, 0.0, -1.0))
    assert isinstance(g, TreeDrag) and list(sim.drags) == [leaf]
    np.testing.assert_allclose(g.anchor(sim), picked, atol=1e-9)
    g.release(sim)
    assert not sim.drags


def test_a_drag_past_the_woods_strength_settles_without_swinging_the_tree_through_its_target():
    """A 1 cm drag of a small-cherry limb: its 50× spring passes the wood's rupture force at
    once, so it pulls along the gap at that force. Damped for the limb's own subtree, it swung
    the whole tree through the target (0.11–1.5 cm about 1 cm for 2.5 s); damped for the
    slowest swing the point moves in, it settles within half a second."""
    sim = ta.Simulation(ta.load_preset("small_cherry"), wind=None)
    tree = sim.tree
    b = int(np.flatnonzero((tree.kind == "branch") & (tree.level == 2))[1])
    p0 = sim.point_position(b, 1.0)
    nodes = tree.rest_positions[tree.object_nodes(b)]
    d = np.cross(nodes[-1] - nodes[0], [0.0, 1.0, 0.0])
    d /= np.linalg.norm(d)
    sim.drag(b, p0 + 0.01 * d)
    x = []
    for _ in range(120):
        sim.step(1 / 60)
        x.append((sim.point_position(b, 1.0) - p0) @ d / 0.01)
    x = np.array(x)
    assert np.ptp(x[30:]) < 0.05, (x[30:].min(), x[30:].max())
    assert 0.9 < x[-1] <= 1.0


def test_a_drag_at_the_trunks_foot_where_nothing_moves_is_held_finite():
    """The point at fraction 0 of the trunk sits on its root joint: the tree's compliance
    there is 0 (a drag's damper divided by it once, hypothesis found)."""
    for name in ("beam", "small_cherry"):
        sim = ta.Simulation(ta.load_preset(name), wind=None)
        sim.drag(0, sim.tree.rest_positions[0] + np.array([0.3, 0.2, 0.0]), 0.0)
        for dt in (1 / 60, 0.5):
            sim.step(dt)
        assert np.isfinite(sim.positions).all()
        np.testing.assert_allclose(sim.positions[0], sim.tree.rest_positions[0], atol=1e-9)


def test_the_tree_model_holds_several_drags_each_with_its_own_spring():
    sim = ta.Simulation(ta.load_preset("small_cherry"), wind=None)
    tree = sim.tree
    a, b = (int(i) for i in np.flatnonzero((tree.kind == "branch") & (tree.level == 2))[:2])
    for _ in range(60):  # settled under its weight
        sim.step(1 / 60)
    pa = sim.point_position(a, 1.0)

    def across(i):  # 1 cm level and square to the branch: it bends, not stretches
        nodes = tree.rest_positions[tree.object_nodes(i)]
        d = np.cross(nodes[-1] - nodes[0], [0.0, 1.0, 0.0])
        return 0.01 * d / np.linalg.norm(d)

    sim.drag(a, pa + across(a))  # the default: 50 times as stiff as the tree there
    k50 = sim.drags[a][1]
    sim.drag(a, pa + across(a), 1.0, stiffness=1.0)  # again: as stiff as the tree
    assert sim.drags[a][1] == pytest.approx(k50 / 50)
    for _ in range(180):
        sim.step(1 / 60)
    # the point held by its spring in series with the tree: s / (1 + s) of its drag
    assert (sim.point_position(a, 1.0) - pa) @ across(a) / 1e-4 == pytest.approx(0.5, abs=0.03)
    pb = sim.point_position(b, 1.0)
    sim.drag(b, pb + across(b))  # a second drag: both held (b's bends the trunk a carries on)
    assert sorted(sim.drags) == sorted([a, b])
    for _ in range(180):
        sim.step(1 / 60)
    assert (sim.point_position(b, 1.0) - pb) @ across(b) / 1e-4 > 0.9
    assert (sim.point_position(a, 1.0) - pa) @ across(a) / 1e-4 > 0.3
    sim.release(a)
    assert list(sim.drags) == [b]
    for bad in (0.0, -1.0, float("nan"), 1e5):
        with pytest.raises(ValueError, match="stiffness") as e:
            sim.drag(a, pa, 1.0, stiffness=bad)
        assert "\n" not in str(e.value)
