"""The Simulation as physics: traces of pulled and released beams and trees, measured."""

import dataclasses

import numpy as np
import pytest
from scipy.optimize import curve_fit

import treeanim as ta
from conftest import Uniform
from treeanim.model.build import ObjectSpec, assemble
from treeanim.model.geometry import lamina_frames, polygon_centroid
from treeanim.model.params import PhysicsParams
from treeanim.physics.bending import rest_frames
from treeanim.physics.paper_sim import PaperSim
from treeanim.physics.simulation import MAX_PULL, Simulation
from treeanim.physics.trace import trace_tips


def straight_beam(n=8, length=2.0):
    pts = np.stack([np.zeros(n + 1), np.linspace(0, length, n + 1), np.zeros(n + 1)], 1)
    return assemble([ObjectSpec(pts, np.linspace(0.08, 0.03, n + 1), "branch", 1, w=np.array([0.0, 0.0, 1.0]))],
                    name="straight", physics=PhysicsParams(ei_max=200.0))


def fit_damped(t, x):
    """Natural frequency and damping ratio of a damped cosine fitted to x(t)."""
    def model(t, A, zeta, f, ph, c):
        w = 2 * np.pi * f
        return A * np.exp(-zeta * w * t) * np.cos(w * np.sqrt(1 - zeta**2) * t + ph) + c

    spec = np.abs(np.fft.rfft(x - x.mean()))
    f0 = np.fft.rfftfreq(len(x), t[1] - t[0])[np.argmax(spec[1:]) + 1]
    p, _ = curve_fit(model, t, x, p0=[x[0], 0.05, f0, 0.0, 0.0], maxfev=40000)
    return p[2], p[1]


def release_trace(tree, f, zeta, direction, dt, seconds, integrator="exact", deflection=0.01, **kw):
    """Hold the tip of object 0 deflected by ``deflection`` × its length along ``direction``
    (world), release it, and return (times, tip displacement from rest). The paper's model
    unless ``kw`` says otherwise."""
    kw.setdefault("model", "paper")
    sim = Simulation(tree, integrator=integrator, **kw)
    sim.modes.f[0] = f
    sim.modes.zeta[0] = zeta
    tip_rest = tree.rest_positions[tree.object_start[0] + tree.object_count[0] - 1]
    length = np.sum(np.linalg.norm(np.diff(tree.rest_positions[tree.object_nodes(0)], axis=0), axis=1))
    force = 1.0
    for _ in range(20):  # a held object sits at its static deflection: scale the force to it
        sim.pull(0, force * np.asarray(direction))
        sim.step(dt)
        d = np.linalg.norm(sim.tip_position(0) - tip_rest)
        if abs(d / (deflection * length) - 1) < 1e-4:
            break
        force *= deflection * length / d
    sim.release()
    t, tips = trace_tips(sim, 0, seconds, dt)
    return t - t[0], tips[:, 0] - tip_rest, sim


# ---------------------------------------------------------------------------- free decay
@pytest.mark.parametrize("dt", [1 / 10, 1 / 60, 1 / 1000])
def test_free_decay_of_a_beam_has_the_set_f_and_zeta(dt):
    tree = straight_beam()
    w = rest_frames(tree)[0][:, 2]
    u = rest_frames(tree)[0][:, 0]
    f, zeta = (0.75, 0.9, 1.25), (0.045, 0.05, 0.08)
    seconds = 8.0 if dt < 0.01 else 40.0  # (at 1 kHz: 16,000 steps, six swings of the slowest mode)
    # A pull along w moves the tip along w with mode u (Eq. 2) ...
    t, d, _ = release_trace(tree, f, zeta, w, dt, seconds)
    fm, zm = fit_damped(t, d @ w)
    assert fm == pytest.approx(0.75, rel=2e-3)
    assert zm == pytest.approx(0.045, rel=2e-2)
    assert np.max(np.abs(d @ u)) < 1e-6 * np.max(np.abs(d @ w))  # ... and nothing else
    # ... a pull along u moves it along u with mode w (Eq. 4).
    t, d, _ = release_trace(tree, f, zeta, u, dt, seconds)
    fm, zm = fit_damped(t, d @ u)
    assert fm == pytest.approx(1.25, rel=2e-3)
    assert zm == pytest.approx(0.08, rel=2e-2)


def test_euler_agrees_with_exact_at_small_dt():
    tree = straight_beam()
    d_dir = rest_frames(tree)[0] @ np.array([1.0, 0.0, 1.0]) / np.sqrt(2)
    f, zeta = (0.8, 0.8, 1.1), (0.05, 0.05, 0.04)
    _, de, _ = release_trace(tree, f, zeta, d_dir, 1 / 200, 8.0, "exact")
    t, du, _ = release_trace(tree, f, zeta, d_dir, 1 / 200, 8.0, "euler")
    amp = np.max(np.linalg.norm(de, axis=1))
    assert np.max(np.linalg.norm(de - du, axis=1)) < 0.02 * amp
    assert fit_damped(t, du @ rest_frames(tree)[0][:, 0])[0] == pytest.approx(1.1, rel=5e-3)


def test_release_in_the_u_w_plane_shows_both_frequencies():
    tree = ta.load_preset("beam")
    F = rest_frames(tree)[0]
    u, w = F[:, 0], F[:, 2]
    f_u, f_w = 0.6, 1.0
    sim_dir = (u + w) / np.sqrt(2)
    t, d, sim = release_trace(tree, (f_u, f_u, f_w), (0.02, 0.02, 0.02), sim_dir, 1 / 50, 60.0,
                              deflection=0.02)
    freqs = np.fft.rfftfreq(len(t), t[1] - t[0])
    for axis, own in ((w, f_u), (u, f_w)):
        spec = np.abs(np.fft.rfft((d @ axis) * np.hanning(len(t))))
        assert abs(freqs[np.argmax(spec)] - own) < 0.03
    # along the pull, the motion carries both modes: the two strongest separated peaks
    spec = np.abs(np.fft.rfft((d @ sim_dir) * np.hanning(len(t))))
    i1 = np.argmax(spec)
    mask = np.abs(freqs - freqs[i1]) > 0.15
    i2 = np.flatnonzero(mask)[np.argmax(spec[mask])]
    assert sorted([freqs[i1], freqs[i2]]) == pytest.approx([f_u, f_w], abs=0.03)
    assert spec[i2] > 0.2 * spec[i1]


# ---------------------------------------------------------------------------- pulls
@pytest.mark.parametrize("angle", [0.0, 40.0, 90.0, 155.0, 250.0])
def test_static_deflection_points_along_the_pull(angle):
    for tree, obj in ((ta.load_preset("beam"), 0), (ta.load_preset("small_cherry"), 5)):
        F = rest_frames(tree)[obj]
        a = np.radians(angle)
        direction = np.cos(a) * F[:, 0] + np.sin(a) * F[:, 2]
        sim = Simulation(tree, coupling=False, model="paper")  # the paper's held pull
        tip = tree.object_start[obj] + tree.object_count[obj] - 1
        length = np.sum(np.linalg.norm(np.diff(tree.rest_positions[tree.object_nodes(obj)], axis=0), axis=1))
        sim.pull(obj, direction)
        sim.step(1 / 60)
        # a deflection of 2 % of the length (large ones also drop the tip along the arc)
        force = 0.02 * length / np.linalg.norm(sim.tip_position(obj) - tree.rest_positions[tip])
        sim.pull(obj, force * direction)
        sim.step(1 / 60)
        first = sim.tip_position(obj)
        d = first - tree.rest_positions[tip]
        for _ in range(5):
            sim.step(1 / 60)
            # held: no oscillation (equal up to the bend-angle solve's 1e-7 rad tolerance)
            assert np.linalg.norm(sim.tip_position(obj) - first) < 1e-5 * np.linalg.norm(d)
        assert np.linalg.norm(d) > 1e-4
        assert d @ direction > 0.95 * np.linalg.norm(d)


def test_modal_loads_settle_at_the_load_unit_static_gain():
    tree = straight_beam()
    force = np.array([0.3, 0.0, -0.2])
    sim2 = PaperSim(tree, wind=None)
    sim2.modes.zeta[:] = 0.4
    sim2._pulls[0] = force  # a constant force, not held (the oscillators respond freely)
    for _ in range(3000):
        sim2.step(1 / 60)
    np.testing.assert_allclose(sim2.modal_loads[0], sim2.loads[0][[2, 1, 0]] * [1, sim2._lever[0], 1], rtol=1e-9,
                               atol=1e-12)


def test_trunk_release_shakes_leaves_only_with_coupling(tree):
    weak = dataclasses.replace(tree, physics=dataclasses.replace(tree.physics, ei_max=2000.0))
    motion = {}
    for coupling in (True, False):
        sim = Simulation(weak, coupling=coupling, model="paper")  # the paper's objects, Eq. 12
        sim.pull(0, (60.0, 0.0, 30.0))
        for _ in range(30):
            sim.step(1 / 60)
        sim.release()
        leaves = np.flatnonzero(weak.kind == "leaf")
        tips = weak.object_start[leaves] + weak.object_count[leaves] - 1
        att = weak.attach_node[leaves]
        worst = 0.0
        for _ in range(180):
            sim.step(1 / 60)
            R = sim.rotations
            local = np.einsum("kji,kjl->kil", R[att], R[tips])  # leaf bend relative to its twig
            worst = max(worst, float(np.max(np.linalg.norm(local - np.eye(3), axis=(1, 2)))))
        motion[coupling] = worst
        trunk_tip = sim.tip_position(0)
        assert np.all(np.isfinite(trunk_tip))
    assert motion[False] < 1e-9  # the paper's independent objects: nothing moves the leaves
    assert motion[True] > 1e-2  # base excitation: the swinging trunk shakes them


# ---------------------------------------------------------------------------- robustness
@pytest.mark.parametrize("model, integrator", [("tree", "exact"), ("paper", "exact"), ("paper", "euler")])
def test_one_step_of_several_seconds_stays_finite(model, integrator, tree):
    sim = Simulation(tree, wind=Uniform((60.0, 0.0, 10.0)), model=model, integrator=integrator)
    sim.pull(3, (0.0, -50.0, 20.0))
    X = tree.rest_positions
    within = tree.node_object[1:] == tree.node_object[:-1]
    rest_len = np.linalg.norm(np.diff(X, axis=0), axis=1)[within]
    for dt in (5.0, 1e-3, 30.0, 1 / 60, 1e4):
        sim.step(dt)
        P = sim.positions
        assert np.all(np.isfinite(P)) and np.all(np.isfinite(sim.rotations))
        np.testing.assert_allclose(np.linalg.norm(np.diff(P, axis=0), axis=1)[within], rest_len, rtol=1e-9)
    sim.release()
    sim.step(7.0)
    assert np.all(np.isfinite(sim.positions))


@pytest.mark.parametrize("model", ["tree", "paper"])
def test_determinism_per_seed(tree, model):
    def run(seed, wind_seed=1):
        sim = Simulation(tree, wind=ta.WindField(speed=8.0, seed=wind_seed), seed=seed, model=model)
        for _ in range(20):
            sim.step(1 / 60)
        return sim.positions.copy()

    p1 = run(3)
    np.testing.assert_array_equal(p1, run(3))
    assert not np.array_equal(p1, run(4))  # the paper's modal draws; the tree's leaves' flutter


@pytest.mark.parametrize("model", ["tree", "paper"])
def test_reset_returns_to_rest(tree, model):
    sim = Simulation(tree, wind=Uniform((10.0, 0.0, 0.0)), model=model)
    sim.pull(2, (1.0, 0.0, 0.0))
    for _ in range(5):
        sim.step(1 / 60)
    sim.reset()
    assert sim.time == 0.0 and sim.pulls == {}
    np.testing.assert_allclose(sim.positions, tree.rest_positions, atol=1e-12)


def test_wind_bounds_are_fitted_to_the_tree(tree):
    wind = ta.WindField(speed=5.0)
    Simulation(tree, wind=wind)
    X = tree.rest_positions
    b = np.asarray(wind.bounds)
    assert b[1, 1] == pytest.approx(X[:, 1].max())
    assert np.all(b[0] <= X.min(axis=0) + 1e-9) and np.all(b[1] >= X.max(axis=0) - 1e-9)
    own = ta.WindField(speed=5.0, bounds=((-1, 0, -1), (1, 20, 1)))
    Simulation(tree, wind=own)
    np.testing.assert_allclose(own.bounds, [[-1, 0, -1], [1, 20, 1]])


def test_wind_bends_the_tree_downwind_and_harder_in_a_gale():
    tree = ta.load_preset("small_cherry")
    X = tree.rest_positions
    top = np.argsort(X[:, 1])[-30:]
    disp = {}
    for speed in (5.0, 25.0):
        sim = Simulation(tree, wind=Uniform((0.0, 0.0, speed)), coupling=False, model="paper")  # linear drag
        for _ in range(4):
            sim.step(5.0)  # long steps: the static response
        d = sim.positions[top] - X[top]
        assert np.mean(d[:, 2]) > 0  # downwind (+z)
        disp[speed] = np.mean(np.linalg.norm(d, axis=1))
    assert 0.01 < disp[5.0] < 0.4  # a gentle sway: centimetres to decimetres
    assert disp[25.0] > 3 * disp[5.0]


# ---------------------------------------------------------------------------- bad input
def snapshot(sim):
    return (sim.time, sim.positions.copy(), sim.rotations.copy(), sim.season, sim.model, dict(sim.pulls))


def assert_same(a, b):
    assert a[0] == b[0] and a[3] == b[3] and a[4] == b[4]
    for x, y in zip(a[1:3], b[1:3]):
        np.testing.assert_array_equal(x, y)
    assert a[5].keys() == b[5].keys()


def _busy(tree, model):
    sim = Simulation(tree, wind=Uniform((4.0, 0.0, 1.0)), model=model)
    sim.pull(1, (0.0, 0.0, 3.0))
    for _ in range(4):
        sim.step(1 / 60)
    return sim


@pytest.fixture(params=["tree", "paper"])
def busy(tree, request):
    return _busy(tree, request.param)


@pytest.fixture
def busy_paper(tree):
    return _busy(tree, "paper")


@pytest.mark.parametrize("dt", [0.0, -0.01, float("nan"), float("inf"), -float("inf"), "fast", None, 1e154, 2e6])
def test_bad_dt(busy, dt):
    before = snapshot(busy)
    with pytest.raises(ValueError, match="dt"):
        busy.step(dt)
    assert_same(before, snapshot(busy))


@pytest.mark.parametrize("name, value", [("f", 0.0), ("f", -1.0), ("f", float("nan")), ("f", float("inf")),
                                         ("f", 1e155), ("zeta", -0.01), ("zeta", float("nan")),
                                         ("zeta", float("inf")), ("zeta", 1e4)])
def test_bad_modes(busy_paper, name, value):
    busy = busy_paper
    before = snapshot(busy)
    arr = getattr(busy.modes, name)
    old = arr[2, 1]
    arr[2, 1] = value
    with pytest.raises(ValueError, match=f"modes.{name}"):
        busy.step(1 / 60)
    a, b = before, snapshot(busy)
    assert_same(a, b)
    arr[2, 1] = old
    busy.step(1 / 60)  # fixed: steps again
    assert busy.time > before[0]


@pytest.mark.parametrize("model, integrator", [("tree", "exact"), ("paper", "exact"), ("paper", "euler")])
def test_the_state_stays_finite_at_the_bounds_of_dt_f_and_zeta(tree, model, integrator):
    """The longest step, the tiniest one before a normal one, and for the paper's oscillators
    the highest frequency and the strongest damping accepted (Euler included) all leave a
    finite tree."""
    from treeanim.physics.simulation import MAX_FREQUENCY, MAX_STEP, MAX_ZETA

    sim = Simulation(tree, wind=Uniform((12.0, 0.0, 3.0)), model=model, integrator=integrator)
    for dt in (1 / 60, MAX_STEP, 1e-320, 1 / 60):
        sim.step(dt)
    assert np.isfinite(sim.positions).all(), integrator
    if model == "tree":
        return
    sim.modes.f[:] = MAX_FREQUENCY
    sim.modes.zeta[:] = MAX_ZETA
    for _ in range(10):
        sim.step(1 / 60)
    assert np.isfinite(sim.positions).all() and np.isfinite(sim.rotations).all(), integrator
    sim.modes.f[:], sim.modes.zeta[:] = 1.0, 25.0  # Euler once diverged above ζ ≈ 25
    for _ in range(60):
        sim.step(1 / 60)
    assert np.isfinite(sim.positions).all(), integrator


@pytest.mark.parametrize("model", ["tree", "paper"])
def test_lengths_hold_where_forces_and_stiffness_underflow(model):
    """31 levels each 1e-5 as thick as the last (stiffness and loads down to 1e-600 and beyond,
    far below the smallest double) and an EI_max of 1e-300: every segment keeps its length."""
    specs, base, d, parent = [], np.zeros(3), 0.1, -1
    for level in range(31):
        direction = np.array([np.sin(0.3 * level), 1.0, 0.3 * np.cos(0.7 * level)])
        pts = base + np.outer(np.linspace(0.0, 0.5, 3), direction / np.linalg.norm(direction))
        specs.append(ObjectSpec(pts, np.array([d, 0.7 * d, 0.5 * d]), "branch", level + 1, parent, 2 if level else 0))
        parent, base, d = len(specs) - 1, pts[-1], d * 1e-5
    tree = assemble(specs, name="deep")
    start, count = np.asarray(tree.object_start), np.asarray(tree.object_count)
    seg = np.concatenate([np.arange(a, a + c - 1) for a, c in zip(start, count)])
    rest = np.linalg.norm(np.diff(tree.rest_positions, axis=0)[seg], axis=1)
    for ei_max in (None, 1e-300):
        sim = Simulation(tree, wind=Uniform((15.0, 0.0, 4.0)), model=model)
        if ei_max is not None:
            sim.physics = dataclasses.replace(sim.physics, ei_max=ei_max)
        for _ in range(30):
            sim.step(1 / 60)
        P = sim.positions
        assert np.isfinite(P).all()
        assert np.max(np.abs(np.linalg.norm(np.diff(P, axis=0)[seg], axis=1) / rest - 1.0)) < 1e-9


@pytest.mark.parametrize("name, value", [("leaf_zeta_w_scale", 1e300), ("wind_gain_leaf", 1e308), ("ei_max", 1e13),
                                         ("drag_leaf", float("inf"))])
def test_physics_beyond_its_bounds_is_refused_and_the_state_kept(busy, name, value):
    before = snapshot(busy)
    with pytest.raises(ValueError, match=f"physics.{name}"):
        busy.physics = dataclasses.replace(busy.physics, **{name: value})
    assert_same(before, snapshot(busy))


def test_the_paper_models_compliance_predicts_a_small_pull():
    """Simulation.compliance (the viewer's pull spring) uses the stiffness the bending uses:
    a small pull across a tapered three-segment branch moves its tip by force × compliance."""
    from treeanim.model.build import ObjectSpec, assemble

    pts = np.outer(np.linspace(0.0, 1.5, 4), (0.0, 1.0, 0.0))
    tree = assemble([ObjectSpec(pts, np.array([0.08, 0.05, 0.03, 0.01]), "branch", 1)], name="tapered")
    sim = Simulation(tree, model="paper")
    force = 1e-5 * sim.physics.ei_max / 1.5**2  # small: the tip moves about a millimetre
    sim.pull(0, (0.0, 0.0, force))
    sim.step(1 / 60)  # held: the static deflection at once
    moved = sim.positions[3, 2] - tree.rest_positions[3, 2]
    assert moved == pytest.approx(force * sim.compliance(0, 2, 1.0), rel=0.02)


def test_bad_modes_shape(busy_paper):
    busy_paper.modes.f = np.ones((3, 3))
    with pytest.raises(ValueError, match="modes.f"):
        busy_paper.step(1 / 60)


def test_the_paper_models_own_settings_are_refused_on_the_tree_model(busy_paper, tree):
    sim = Simulation(tree)
    for name in ("modes", "integrator", "coupling", "compliance"):
        with pytest.raises(AttributeError, match="paper"):
            getattr(sim, name)
    with pytest.raises(AttributeError, match="paper"):
        sim.integrator = "euler"
    with pytest.raises(AttributeError, match="tree"):
        busy_paper.energy
    with pytest.raises(ValueError, match="model"):
        Simulation(tree, model="fem")


@pytest.mark.parametrize("obj", [-1, 10**6, 1.5, "3", True, None])
def test_bad_object_index(busy, obj):
    before = snapshot(busy)
    with pytest.raises(ValueError, match="object"):
        busy.pull(obj, (1.0, 0.0, 0.0))
    with pytest.raises(ValueError, match="object"):
        busy.release(obj) if obj is not None else busy.tip_position(obj)
    assert_same(before, snapshot(busy))


@pytest.mark.parametrize("force", [(float("nan"), 0, 0), (0, float("inf"), 0), (1, 2), (1, 2, 3, 4), "up", None])
def test_bad_pull_force(busy, force):
    before = snapshot(busy)
    with pytest.raises(ValueError, match="force"):
        busy.pull(0, force)
    assert_same(before, snapshot(busy))


@pytest.mark.parametrize("season", [-0.1, 1.5, float("nan"), "winter", None])
def test_bad_season(busy, tree, season):
    before = snapshot(busy)
    with pytest.raises(ValueError, match="season"):
        busy.season = season
    assert_same(before, snapshot(busy))
    with pytest.raises(ValueError, match="season"):
        Simulation(tree, season=season)


def test_bad_integrator(busy_paper, tree):
    busy = busy_paper
    before = snapshot(busy)
    with pytest.raises(ValueError, match="integrator"):
        busy.integrator = "rk4"
    assert_same(before, snapshot(busy))
    with pytest.raises(ValueError, match="integrator"):
        Simulation(tree, integrator="verlet", model="paper")


def test_bad_constructor_arguments(tree):
    with pytest.raises(ValueError, match="seed"):
        Simulation(tree, seed=-1)
    with pytest.raises(ValueError, match="tree"):
        Simulation("small_cherry")
    with pytest.raises(ValueError, match="wind"):
        Simulation(tree, wind=42)


def test_outputs_you_keep_are_never_overwritten(tree):
    sim = Simulation(tree, wind=Uniform((12.0, 0.0, 4.0)))
    kept = []
    for k in range(6):
        sim.step(1 / 30)
        P, R = sim.positions, sim.rotations
        assert not P.flags.writeable and not R.flags.writeable
        assert sim.positions is P  # cached until the next step
        if k % 2 == 0:
            kept.append((P, P.copy(), R[:5], R[:5].copy()))  # a view keeps its base alive too
    for P, P0, Rv, R0 in kept:
        np.testing.assert_array_equal(P, P0)
        np.testing.assert_array_equal(Rv, R0)
    assert not np.array_equal(kept[0][0], kept[-1][0])


class Broken:
    """A wind whose samples are not finite."""

    def __init__(self, value):
        self.value = value

    def sample(self, points, t):
        U = np.full((len(points), 3), 2.0)
        U[len(points) // 2, 1] = self.value
        return U


@pytest.mark.parametrize("value", [float("nan"), float("inf"), -float("inf")])
def test_non_finite_wind_is_refused_and_the_state_kept(busy, value):
    good = busy.wind
    busy.wind = Broken(value)
    before = snapshot(busy)
    with pytest.raises(ValueError, match="wind"):
        busy.step(1 / 60)
    assert_same(before, snapshot(busy))
    busy.wind = good
    busy.step(1 / 60)  # a good wind steps again
    assert np.all(np.isfinite(busy.positions))


@pytest.mark.parametrize("force", [(1e308, 0, 0), (0, -1e308, 1e308), (MAX_PULL * 1.01, 0, 0),
                                   (0.8 * MAX_PULL, 0.8 * MAX_PULL, 0)])
def test_pull_above_the_largest_force_is_refused(busy, force):
    before = snapshot(busy)
    with pytest.raises(ValueError, match="force_xyz"):
        busy.pull(5, force)
    assert_same(before, snapshot(busy))


@pytest.mark.parametrize("model, integrator", [("tree", "exact"), ("paper", "exact"), ("paper", "euler")])
def test_largest_legal_pulls_give_finite_positions(tree, model, integrator):
    sim = Simulation(tree, wind=Uniform((30.0, 0.0, 10.0)), model=model, integrator=integrator)
    d = np.array([1.0, -2.0, 2.0]) / 3.0
    for i in (0, 1, 5, tree.n_objects - 1):
        sim.pull(i, MAX_PULL * d)
    for _ in range(5):
        sim.step(1 / 30)
    P = sim.positions
    assert np.all(np.isfinite(P)) and np.all(np.isfinite(sim.rotations))
    for i in range(tree.n_objects):  # only rotations: lengths kept
        nodes = tree.object_nodes(i)
        np.testing.assert_allclose(np.linalg.norm(np.diff(P[nodes], axis=0), axis=1),
                                   np.linalg.norm(np.diff(tree.rest_positions[nodes], axis=0), axis=1),
                                   rtol=1e-9)


@pytest.mark.parametrize("objects", [1.0, [0, 2.5], np.array([0.0, 1.0]), [-1], [10**6], True, "0", [[0, 1]]])
def test_trace_tips_refuses_bad_indices(tree, objects):
    sim = Simulation(tree)
    with pytest.raises(ValueError, match="object"):
        trace_tips(sim, objects, 0.1, 0.01)
    assert sim.time == 0.0


@pytest.mark.parametrize("duration, dt", [(1e300, 1e-300), (1e308, 1e-10), (1e9, 1e-3), (1.0, 1e-12)])
def test_trace_tips_refuses_absurd_durations(tree, duration, dt):
    sim = Simulation(tree)
    with pytest.raises(ValueError, match="duration"):
        trace_tips(sim, [0, 1], duration, dt)
    assert sim.time == 0.0


def test_trace_tips_accepts_numpy_indices(tree):
    sim = Simulation(tree)
    t, tips = trace_tips(sim, np.array([0, 3]), 0.05, 0.01)
    assert tips.shape == (6, 2, 3) and len(t) == 6


def test_modal_seeds_use_every_bit(tree):
    a = Simulation(tree, seed=0, model="paper").modes
    b = Simulation(tree, seed=2**32, model="paper").modes
    c = Simulation(tree, seed=2**64 + 7, model="paper").modes
    assert not np.array_equal(a.f, b.f)
    assert not np.array_equal(b.f, c.f)
    np.testing.assert_array_equal(Simulation(tree, seed=2**32, model="paper").modes.f, b.f)


def test_leaf_lever_arm_uses_the_lamina_frame_of_the_mesh(tree):
    def lever(t, frame_of):
        leaves = np.flatnonzero(t.kind == "leaf")
        cx, cy = polygon_centroid(t.lamina.outline)
        tipn, u, v = frame_of(t, leaves)
        centroid = t.rest_positions[tipn] + t.lamina_length[leaves, None] * (cx * u + cy * v)
        return leaves, np.linalg.norm(centroid - t.rest_positions[t.object_start[leaves]], axis=1)

    mesh_frame = lambda t, leaves: lamina_frames(t, leaves)[:3]  # noqa: E731
    leaves, r = lever(tree, mesh_frame)
    np.testing.assert_allclose(PaperSim(tree)._lever[leaves], r, rtol=1e-12)

    # A petiole bent through a right angle: the lamina lies along its last segment (as the
    # mesh and picking draw it), not along the first.
    twig = np.stack([np.zeros(3), np.linspace(0, 1, 3), np.zeros(3)], 1)
    pet = twig[-1] + np.array([[0, 0, 0], [0, 0.02, 0], [0, 0.04, 0], [0.01, 0.04, 0]])
    bent = assemble([ObjectSpec(twig, np.array([0.03, 0.02, 0.01]), "branch", 1),
                     ObjectSpec(pet, np.full(4, 0.003), "leaf", 2, parent=0, attach=2,
                                w=np.array([0.0, 0.0, 1.0]), lamina_length=0.2)],
                    name="bent_petiole", lamina=tree.lamina)
    first_frame = lambda t, leaves: (t.object_start[leaves] + t.object_count[leaves] - 1,  # noqa: E731
                                     rest_frames(t)[leaves, :, 0], rest_frames(t)[leaves, :, 1])
    leaves, r = lever(bent, mesh_frame)
    _, r_first = lever(bent, first_frame)
    lev = PaperSim(bent)._lever[leaves]
    np.testing.assert_allclose(lev, r, rtol=1e-12)
    assert abs(lev[0] - r_first[0]) > 0.01
