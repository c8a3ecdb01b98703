"""The paper's model (Hu, Chiba & He 2012) as its own simulation: it reproduces the recorded
reference poses bit for bit, and a snapshot of its state replays the same steps."""

from __future__ import annotations

import dataclasses
import importlib.util
from pathlib import Path

import numpy as np
import pytest

import treeanim as ta
from treeanim.physics.paper_sim import PaperSim

DATA = Path(__file__).parent / "data"


def _reference_module():
    spec = importlib.util.spec_from_file_location("make_paper_reference", DATA / "make_paper_reference.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_the_paper_model_reproduces_its_reference_bit_for_bit():
    """The poses the paper model gave before the load path (recorded at commit 4ed910f by
    tests/data/make_paper_reference.py)."""
    ref = np.load(DATA / "paper_reference.npz")
    mod = _reference_module()
    for name, scenario in mod.SCENARIOS.items():
        pos, rot = mod.run(*scenario, sim_class=PaperSim)
        np.testing.assert_array_equal(pos, ref[f"{name}/positions"], err_msg=name)
        if f"{name}/rotations" in ref:
            np.testing.assert_array_equal(rot, ref[f"{name}/rotations"], err_msg=name)


def _shown(sim):
    """Everything ``sim`` shows of its state (and the oscillators' rates)."""
    return (sim.time, sim.positions.copy(), sim.rotations.copy(), sim.modal_loads, sim.loads, sim._pd.copy(),
            sim.tip_position(0))


def _run(sim, script):
    """Step ``sim`` through ``script`` [(dt, pulls {object: force or None to release})], recording
    after every step what it shows."""
    out = []
    for dt, pulls in script:
        for i, f in pulls.items():
            sim.pull(i, f) if f is not None else sim.release(i)
        sim.step(dt)
        out.append(_shown(sim))
    return out


@pytest.mark.parametrize("integrator", ["exact", "euler"])
def test_set_state_replays_the_steps_bit_for_bit(integrator):
    tree = ta.load_preset("small_cherry")
    limb, twig = int(np.flatnonzero(tree.level == 2)[0]), int(np.flatnonzero(tree.level == 3)[-1])
    sim = PaperSim(tree, wind=ta.WindField(speed=12.0, seed=4, model="paper"), season=0.3, seed=2,
                   integrator=integrator)
    sim.pull(limb, (0.0, 0.0, 150.0))
    for k in range(11):  # a tree already moving, the solver's warm start and dt_prev (1/45) set
        sim.step(1 / 60 if k % 2 else 1 / 45)
    state = sim.get_state()
    then = _shown(sim)
    kept = state.copy()
    # steps of two lengths (the bending's extrapolation reads the last), a release and a new pull
    script = [(1 / 60 if k % 3 else 1 / 30, {limb: None} if k == 12 else {twig: (5.0, 0.0, -20.0)} if k == 18 else {})
              for k in range(30)]
    first = _run(sim, script)
    sim.set_state(state)
    assert sim.pulls.keys() == {limb} and sim.time == state.time
    second = [_shown(sim)] + _run(sim, script)  # the pose shown at once, then the same steps
    for a, b in zip([then] + first, second):
        for x, y in zip(a, b):
            np.testing.assert_array_equal(x, y)
    # the snapshot was copied both ways: stepping changed neither it nor its copy
    for f in dataclasses.fields(state):
        x, y = getattr(state, f.name), getattr(kept, f.name)
        if isinstance(x, dict):
            assert x.keys() == y.keys() and all(np.array_equal(x[i], y[i]) for i in x)
        else:
            np.testing.assert_array_equal(x, y)
    sim.set_state(kept)  # and it restores again, from the copy
    third = _run(sim, script)
    np.testing.assert_array_equal(third[-1][1], first[-1][1])


def test_set_state_refuses_a_state_of_another_tree():
    a, b = PaperSim(ta.load_preset("beam")), PaperSim(ta.load_preset("small_cherry"))
    b.step(1 / 60)
    before = b.get_state()
    with pytest.raises(ValueError, match="shape"):
        b.set_state(a.get_state())
    with pytest.raises(ValueError, match="PaperState"):
        b.set_state({"time": 0.0})
    after = b.get_state()
    np.testing.assert_array_equal(after.p, before.p)
    assert after.time == before.time
