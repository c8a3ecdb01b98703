"""Invariants of both models under hypothesis: any wind, any step, any preset.

Segment lengths are kept (only rotations are applied, docs/design.md §5), everything stays finite,
rotations stay rotations, and the same inputs give the same result.
"""

import functools

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

import treeanim as ta
from treeanim.physics.paper_sim import PaperSim

PRESETS = ["beam", "small_cherry", "tulip_poplar", "grassland", "large_cherry"]


@functools.lru_cache(maxsize=None)
def preset(name):
    tree = ta.load_preset(name)
    within = tree.node_object[1:] == tree.node_object[:-1]
    rest_len = np.linalg.norm(np.diff(tree.rest_positions, axis=0), axis=1)[within]
    return tree, within, rest_len


def check_pose(sim, within, rest_len):
    P, R = sim.positions, sim.rotations
    assert np.all(np.isfinite(P)) and np.all(np.isfinite(R))
    np.testing.assert_allclose(np.linalg.norm(np.diff(P, axis=0), axis=1)[within], rest_len, rtol=1e-9)
    np.testing.assert_allclose(np.einsum("kji,kjl->kil", R, R), np.broadcast_to(np.eye(3), R.shape), atol=1e-9)


wind_args = dict(
    name=st.sampled_from(PRESETS),
    azimuth=st.floats(0, 2 * np.pi),
    speed=st.floats(0, 60),
    turbulence=st.floats(1, 2),
    wind_seed=st.integers(0, 2**16),
    seed=st.integers(0, 2**16),
    dts=st.lists(st.sampled_from([1e-3, 1 / 60, 1 / 10, 0.5, 4.0]), min_size=1, max_size=4),
    integrator=st.sampled_from(["exact", "euler"]),
    coupling=st.booleans(),
    season=st.floats(0, 1),
)


@settings(max_examples=60)
@given(**wind_args)
def test_gale_keeps_lengths_and_stays_finite(name, azimuth, speed, turbulence, wind_seed, seed, dts, integrator,
                                             coupling, season):
    tree, within, rest_len = preset(name)
    wind = ta.WindField(direction=(np.cos(azimuth), 0.0, np.sin(azimuth)), speed=speed, turbulence=turbulence,
                        seed=wind_seed, grid=16, model="paper")
    sim = PaperSim(tree, wind=wind, seed=seed, integrator=integrator, coupling=coupling, season=season)
    for dt in dts:
        sim.step(dt)
    check_pose(sim, within, rest_len)


@settings(max_examples=30)
@given(name=st.sampled_from(PRESETS[:4]), obj_frac=st.floats(0, 1), force=st.lists(st.floats(-1e6, 1e6), min_size=3,
                                                                                      max_size=3),
       hold=st.integers(1, 4), after=st.lists(st.sampled_from([1e-3, 1 / 60, 2.0]), min_size=1, max_size=3))
def test_any_pull_and_release_keeps_lengths(name, obj_frac, force, hold, after):
    tree, within, rest_len = preset(name)
    obj = min(int(obj_frac * tree.n_objects), tree.n_objects - 1)
    sim = PaperSim(tree)
    sim.pull(obj, force)
    for _ in range(hold):
        sim.step(1 / 60)
    check_pose(sim, within, rest_len)
    sim.release()
    for dt in after:
        sim.step(dt)
    check_pose(sim, within, rest_len)


@settings(max_examples=6)
@given(name=st.sampled_from(PRESETS[:4]), seed=st.integers(0, 1000), speed=st.floats(0, 40),
       steps=st.integers(1, 5))
def test_same_inputs_same_result(name, seed, speed, steps):
    tree, _, _ = preset(name)
    runs = []
    for _ in range(2):
        sim = PaperSim(tree, wind=ta.WindField(speed=speed, seed=seed, grid=16, model="paper"), seed=seed)
        for _ in range(steps):
            sim.step(1 / 60)
        runs.append(sim.positions)
    np.testing.assert_array_equal(runs[0], runs[1])


# ---------------------------------------------------------------------------- the tree model
@settings(max_examples=25)
@given(name=st.sampled_from(PRESETS[:4]), azimuth=st.floats(0, 2 * np.pi), speed=st.floats(0, 60),
       seed=st.integers(0, 2**16), dts=st.lists(st.sampled_from([1e-3, 1 / 240, 1 / 60, 1 / 10, 0.5, 4.0]),
                                                min_size=1, max_size=5),
       season=st.floats(0, 1), obj_frac=st.floats(0, 1), s=st.floats(0, 1),
       reach=st.lists(st.floats(-20, 20), min_size=3, max_size=3), force=st.floats(0, 1e5))
def test_the_tree_model_stays_finite_keeps_lengths_and_the_ground(name, azimuth, speed, seed, dts, season, obj_frac,
                                                                  s, reach, force):
    """Any wind, any step, any drag (far targets included) and pull: a finite tree of rigid
    segments, held above the ground where it is dragged."""
    tree, within, rest_len = preset(name)
    wind = ta.WindField(direction=(np.cos(azimuth), 0.0, np.sin(azimuth)), speed=speed, seed=seed)
    sim = ta.Simulation(tree, wind=wind, seed=seed, season=season)
    obj = min(int(obj_frac * tree.n_objects), tree.n_objects - 1)
    sim.drag(obj, tree.rest_positions[tree.object_start[obj]] + np.asarray(reach), s)
    sim.pull(tree.n_objects - 1 - obj, (force, -force, 0.0))
    for dt in dts:
        sim.step(dt)
    check_pose(sim, within, rest_len)
    sim.release()
    for dt in dts:
        sim.step(dt)
    check_pose(sim, within, rest_len)
