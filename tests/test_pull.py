"""The viewer's pull controller without a window (physics/pull.py): its spring uses the
simulation's own compliance, and the grabbed point settles GAIN / (1 + GAIN) of the way."""

from __future__ import annotations

import numpy as np
import pytest

import treeanim as ta
from treeanim.physics.pull import GAIN, SpringPull


@pytest.mark.parametrize("load_path", [True, False])
def test_a_small_drag_settles_at_the_spring_share_of_the_way(load_path):
    sim = ta.Simulation(ta.load_preset("beam"), wind=None, load_path=load_path)
    tip = sim.tip_position(0)
    g = SpringPull.grab(sim, 0, tip, plane_normal=(0.0, 0.0, -1.0))
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
