"""Modal parameters (Eqs. 20–22) and the season / physics setters that re-derive them."""

import dataclasses

import numpy as np
import pytest

import treeanim as ta
from treeanim.model.build import ObjectSpec, assemble
from treeanim.model.params import ModeRange, PhysicsParams, SeasonModes
from treeanim.physics.modal import (
    ModalDraws,
    derive_modes,
    descendant_counts,
    mean_diameters,
    object_lengths,
)
from treeanim.physics.paper_sim import PaperSim


def fan_tree():
    """A trunk with three branches of different slenderness; two carry twigs and leaves."""
    specs = [ObjectSpec(np.array([[0, 0, 0], [0, 1, 0], [0, 2, 0.0]]), np.array([0.2, 0.15, 0.1]), "branch", 1)]
    for j, (L, D) in enumerate([(1.0, 0.08), (0.6, 0.05), (1.4, 0.03)]):
        d = np.array([np.cos(j * 2.1), 0.8, np.sin(j * 2.1)])
        d /= np.linalg.norm(d)
        pts = specs[0].points[2] + np.outer(np.linspace(0, L, 3), d)
        specs.append(ObjectSpec(pts, np.linspace(D, D / 2, 3), "branch", 2, parent=0, attach=2))
    for b in (1, 2):
        tw = specs[b].points[2] + np.outer(np.linspace(0, 0.3, 2), [0.3, 1, 0])
        specs.append(ObjectSpec(tw, np.array([0.01, 0.005]), "branch", 3, parent=b, attach=2))
        tw_i = len(specs) - 1
        for k in range(3 * b):
            pet = tw[1] + np.outer(np.linspace(0, 0.03, 4), [np.cos(k), -0.3, np.sin(k)])
            specs.append(ObjectSpec(pet, np.full(4, 0.002), "leaf", 4, parent=tw_i, attach=1,
                                    w=np.array([0.0, 1.0, 0.0]), lamina_length=0.08))
    return assemble(specs, name="fan", winter_leaves=2)


@pytest.fixture(scope="module")
def fan():
    return fan_tree()


def test_descendant_counts(fan):
    nb, nl = descendant_counts(fan)
    kinds = fan.kind
    # trunk: 3 branches + 2 twigs below, 3 + 6 leaves
    assert nb[0] == 5 and nl[0] == 9
    # every leaf and every twig with no children has none
    assert np.all(nb[kinds == "leaf"] == 0) and np.all(nl[kinds == "leaf"] == 0)
    assert sorted(nl[(kinds == "branch") & (fan.level == 3)]) == [3, 6]


def test_eq20_frequency_maps_slenderness_onto_the_range(fan):
    p = PhysicsParams()
    m = derive_modes(fan, p, 0.0, ModalDraws.draw(fan.n_objects, 0))
    br = np.flatnonzero(fan.kind == "branch")
    fprime = (mean_diameters(fan) / object_lengths(fan) ** 2)[br]
    f = m.f[br, 0]
    lo, hi = p.summer.branch.f
    assert f.min() == pytest.approx(lo) and f.max() == pytest.approx(hi)
    # linear in f′ (Eq. 20)
    np.testing.assert_allclose(f, lo + (fprime - fprime.min()) * (hi - lo) / (fprime.max() - fprime.min()))


def test_eq21_damping_grows_with_descendants(fan):
    p = PhysicsParams()
    m = derive_modes(fan, p, 0.0, ModalDraws.draw(fan.n_objects, 0))
    nb, nl = descendant_counts(fan)
    br = np.flatnonzero(fan.kind == "branch")
    r = nb[br] + nl[br] / 6
    z = m.zeta[br, 0]
    lo, hi = p.summer.branch.zeta
    np.testing.assert_allclose(z, lo + (r - r.min()) * (hi - lo) / (r.max() - r.min()))
    assert z[np.argmax(r)] == pytest.approx(hi) and z[np.argmin(r)] == pytest.approx(lo)


def test_eq22_three_modes_and_leaf_scales(fan):
    p = PhysicsParams()
    draws = ModalDraws.draw(fan.n_objects, 5)
    m = derive_modes(fan, p, 0.0, draws)
    f, z = m.f, m.zeta
    assert np.all(np.abs(f[:, 1:] / f[:, :1] - 1) <= 0.05 + 1e-12)
    n = draws.noise
    np.testing.assert_allclose(f[:, 1], f[:, 0] * (1 + 0.1 * n[:, 0]))
    np.testing.assert_allclose(f[:, 2], f[:, 0] * (1 + 0.1 * n[:, 1]))
    leaf = fan.kind == "leaf"
    np.testing.assert_allclose(z[~leaf, 1], z[~leaf, 0] * (1 + 0.1 * n[~leaf, 2]))
    np.testing.assert_allclose(z[leaf, 1], z[leaf, 0] * (1 + 0.1 * n[leaf, 2]) * p.leaf_zeta_v_scale)
    np.testing.assert_allclose(z[leaf, 2], z[leaf, 0] * (1 + 0.1 * n[leaf, 3]) * p.leaf_zeta_w_scale)


def test_degenerate_ranges_draw_uniformly_and_are_seeded(fan):
    p = PhysicsParams()
    leaf = fan.kind == "leaf"  # every leaf has r = 0 and the same f′: both ranges degenerate
    a = derive_modes(fan, p, 0.0, ModalDraws.draw(fan.n_objects, 1))
    b = derive_modes(fan, p, 0.0, ModalDraws.draw(fan.n_objects, 1))
    c = derive_modes(fan, p, 0.0, ModalDraws.draw(fan.n_objects, 2))
    np.testing.assert_array_equal(a.f, b.f)
    assert not np.array_equal(a.f[leaf], c.f[leaf])
    lo, hi = p.summer.leaf.f
    assert np.all((a.f[leaf, 0] >= lo) & (a.f[leaf, 0] <= hi))
    assert np.ptp(a.f[leaf, 0]) > 0.05 * (hi - lo)
    zlo, zhi = p.summer.leaf.zeta
    assert np.all((a.zeta[leaf, 0] >= zlo) & (a.zeta[leaf, 0] <= zhi))


def test_season_interpolates_and_drops_leaves(fan):
    summer = SeasonModes(branch=ModeRange((0.4, 0.8), (0.12, 0.3)), leaf=ModeRange((1.0, 1.4), (0.08, 0.12)))
    winter = SeasonModes(branch=ModeRange((0.6, 1.3), (0.07, 0.15)), leaf=ModeRange((1.6, 2.8), (0.03, 0.07)))
    tree = dataclasses.replace(fan, physics=PhysicsParams(summer=summer, winter=winter))
    sim = PaperSim(tree)
    f0, z0 = sim.modes.f.copy(), sim.modes.zeta.copy()
    ref = sim.modes.f  # the arrays are updated in place
    sim.season = 0.5
    assert sim.modes.f is ref
    br = tree.kind == "branch"
    assert sim.modes.f[br, 0].min() == pytest.approx(0.5) and sim.modes.f[br, 0].max() == pytest.approx(1.05)
    sim.season = 1.0
    assert np.all(sim.modes.f > f0) and np.all(sim.modes.zeta < z0)
    assert int((sim.present & (tree.kind == "leaf")).sum()) == 2
    assert sim.present_nodes.sum() == tree.object_count[sim.present].sum()
    sim.season = 0.0
    np.testing.assert_allclose(sim.modes.f, f0)
    assert sim.present.all()


def test_physics_setter_rederives(fan):
    sim = PaperSim(fan)
    p = sim.physics
    faster = dataclasses.replace(p, summer=dataclasses.replace(p.summer, branch=ModeRange((2.0, 3.0), (0.01, 0.02))))
    sim.physics = faster
    br = fan.kind == "branch"
    assert sim.modes.f[br, 0].min() == pytest.approx(2.0) and sim.modes.f[br, 0].max() == pytest.approx(3.0)
    assert sim.physics is faster
    with pytest.raises(ValueError, match="ei_max"):
        sim.physics = dataclasses.replace(p, ei_max=-1.0)
    with pytest.raises(ValueError, match="physics"):
        sim.physics = "not params"
    assert sim.physics is faster


def test_large_cherry_seasons():
    tree = ta.load_preset("large_cherry")
    sim = PaperSim(tree, season=0.0)
    br = tree.kind == "branch"
    f0, z0 = sim.modes.f[br].mean(), sim.modes.zeta[br].mean()
    sim.season = 1.0
    assert sim.modes.f[br].mean() > 1.3 * f0  # 0.4–0.8 Hz → 0.6–1.3 Hz
    assert sim.modes.zeta[br].mean() < 0.7 * z0  # 0.12–0.30 → 0.07–0.15
    assert int((sim.present & (tree.kind == "leaf")).sum()) == 344
    leaf = tree.kind == "leaf"
    assert sim.modes.f[leaf & sim.present, 0].min() >= 1.6 - 1e-9
    for _ in range(3):
        sim.step(1 / 30)
    assert np.all(np.isfinite(sim.positions))
