"""Curved-beam bending (Eqs. 6–11) and the hierarchy (Eq. 12) against a plain reference."""

import dataclasses

import numpy as np
import pytest
from scipy.optimize import brentq

from conftest import rot
from treeanim.model.build import ObjectSpec, assemble
from treeanim.model.params import PhysicsParams
from treeanim.physics.bend_angle import solve_bend_angle
from treeanim.physics.bending import rest_frames
from treeanim.physics.paper_sim import PaperSim


# ---------------------------------------------------------------------------- the angle solve
def random_problem(rng, K):
    a = 10 ** rng.uniform(-6, 3, K)
    th = rng.uniform(0, np.pi, K)
    k = 10 ** rng.uniform(-6, 3, K)
    k[:50] = 0.0
    a[50:100] = 0.0
    th[100:150] = 0.0
    nn, dot = a * np.sin(th), a * np.cos(th)
    return a, np.arctan2(nn, dot), k, nn, dot


@pytest.mark.parametrize("start", ["cold", "random", "zero", "theta0"])
def test_bend_angle_solves_eq8_to_tolerance(start):
    rng = np.random.default_rng(7)
    a, th, k, nn, dot = random_problem(rng, 50_000)
    phi0 = {"cold": None, "random": rng.uniform(0, np.pi, len(a)), "zero": np.zeros(len(a)), "theta0": th}[start]
    phi, t = solve_bend_angle(nn, dot, k, th, phi0)
    assert np.all(np.isfinite(phi)) and np.all((phi >= 0) & (phi <= th))
    np.testing.assert_allclose(t, np.tan(phi / 2), rtol=1e-14, atol=0)
    ok = (a > 0) & (nn > 1e-12 * a)
    res = a * np.sin(th - phi) - k * phi
    slope = a * np.cos(th - phi) + k  # −h′ > 0 at the root
    assert np.all(np.abs(res[ok]) <= 1.01e-7 * slope[ok] + 1e-300)  # |φ − root| < 1e-7 rad
    assert np.all(phi[a == 0] < 1e-12)  # no load, no bend (the caller zeroes these exactly)


def test_bend_angle_small_load_is_linear_and_large_load_aligns():
    k = np.ones(3)
    th = np.full(3, np.pi / 2)
    a = np.array([1e-6, 1.0, 1e9])
    phi, _ = solve_bend_angle(a * np.sin(th), a * np.cos(th), k, th)
    assert phi[0] == pytest.approx(1e-6, rel=1e-5)  # Hooke: φ ≈ a sin θ₀ / k
    assert 0 < phi[1] < th[1]
    assert phi[2] == pytest.approx(np.pi / 2, abs=1e-8)  # the segment turns onto the force


# ---------------------------------------------------------------------------- one beam vs reference


def reference_beam(points, diam, F, gamma, v, ei_max, m, dmax):
    """Eqs. 7–11 for one object, literally, in world rest coordinates, with 3×3 matrices."""
    s = np.diff(points, axis=0)
    n = len(s)
    C = np.eye(3)
    pos = [points[0]]
    rots = []
    Dr, Dt = diam[0], diam[-1]
    for i in range(n):
        Fi = F * (n - i) / n  # Eq. 7
        T = rot(v, -gamma) @ C  # twist (Eq. 11), turned by −γ (see bending.py)
        sp = T @ s[i]
        a = np.linalg.norm(Fi) * np.linalg.norm(s[i])
        N = np.cross(sp, Fi)
        phi = 0.0
        if np.linalg.norm(N) > 1e-12 * a > 0:
            th0 = np.arccos(np.clip(Fi @ sp / a, -1, 1))
            k = ei_max * ((Dr - (Dr - Dt) * i / max(n - 1, 1)) / dmax) ** m  # Eq. 10
            phi = brentq(lambda p: a * np.sin(th0 - p) - k * p, 0.0, th0, xtol=1e-14)  # Eqs. 8–9
        C = rot(N, phi) @ T
        rots.append(C)
        pos.append(pos[-1] + C @ s[i])
    return np.array(pos), np.array(rots + [rots[-1]])


def curved_beam(rng, n=7):
    d = np.array([rng.normal(0, 0.2), 1.0, rng.normal(0, 0.2)])
    pts = [np.zeros(3)]
    for _ in range(n):
        d = d + rng.normal(0, 0.15, 3)
        pts.append(pts[-1] + 0.3 * d / np.linalg.norm(d))
    return np.array(pts), np.linspace(0.08, 0.02, n + 1)


@pytest.mark.parametrize("seed", range(6))
def test_held_beam_matches_the_reference(seed):
    rng = np.random.default_rng(seed)
    pts, diam = curved_beam(rng)
    ei_max, m, c0 = 10 ** rng.uniform(1, 3), rng.choice([2.0, 3.0, 4.0]), rng.uniform(0, 2)
    tree = assemble([ObjectSpec(pts, diam, "branch", 1)], name="beam",
                    physics=PhysicsParams(ei_max=ei_max, stiffness_exponent=m, twist_c0=c0))
    sim = PaperSim(tree)  # the paper's held beam (Eqs. 2–11)
    force = rng.normal(size=3) * 10 ** rng.uniform(-1, 2)
    sim.pull(0, force)
    sim.step(1 / 60)  # held: the oscillators sit at the static load, L′ = L
    u, v, w = rest_frames(tree)[0].T
    Lu, Lw = force @ u, force @ w
    np.testing.assert_allclose(sim.modal_loads[0], [Lw, sim._lever[0] * Lw, Lu], rtol=1e-12, atol=1e-12)
    F_rest = Lu * u + Lw * w  # Eq. 6, L′_w·u + L′_u·w with L′_w = L_u, L′_u = L_w: the u–w part
    np.testing.assert_allclose(F_rest, force - (force @ v) * v, atol=1e-12)
    n = len(pts) - 1
    k0 = ei_max * (diam[0] / diam.max()) ** m
    Lv_ = sim._lever[0] * Lw
    gamma = 0.5 * np.pi * np.sign(Lv_) * (1 - np.exp(-c0 * abs(Lv_) / k0)) / n
    ref_pos, ref_rot = reference_beam(pts, diam, F_rest, gamma, v, ei_max, m, diam.max())
    np.testing.assert_allclose(sim.positions, ref_pos, atol=2e-7 * n)
    np.testing.assert_allclose(sim.rotations, ref_rot, atol=2e-7 * n)


def test_bend_direction_lengths_and_no_stretch_in_a_huge_load():
    pts = np.stack([np.zeros(6), np.linspace(0, 2, 6), np.zeros(6)], 1)
    tree = assemble([ObjectSpec(pts, np.linspace(0.1, 0.04, 6), "branch", 1)], name="straight")
    for mag in (1e-3, 1.0, 1e3, 1e9):
        sim = PaperSim(tree)
        sim.pull(0, (mag, 0.0, 0.0))
        sim.step(0.1)
        P = sim.positions
        np.testing.assert_allclose(np.linalg.norm(np.diff(P, axis=0), axis=1), 0.4, rtol=1e-12)
        tip = P[-1] - pts[-1]
        assert tip[0] > 0 and abs(tip[2]) < 1e-9 * max(tip[0], 1e-300)  # towards the force only
    # In the strongest load every segment turns (almost) onto the force, never past it.
    assert np.all(np.diff(P[:, 0]) > 0.4 * np.cos(np.radians(1)))


# ---------------------------------------------------------------------------- hierarchy (Eq. 12)
def two_level():
    trunk = np.stack([np.zeros(4), np.linspace(0, 1.5, 4), np.zeros(4)], 1) + [[0, 0, 0], [0.02, 0, 0], [0.05, 0, 0.01],
                                                                                 [0.1, 0, 0.03]]
    br = trunk[2] + np.outer(np.linspace(0, 0.8, 3), [0.8, 0.5, 0.2])
    leaf = br[2] + np.outer(np.linspace(0, 0.04, 4), [0.1, -0.5, 0.8])
    return assemble([
        ObjectSpec(trunk, np.array([0.12, 0.1, 0.08, 0.06]), "branch", 1),
        ObjectSpec(br, np.array([0.04, 0.03, 0.02]), "branch", 2, parent=0, attach=2),
        ObjectSpec(leaf, np.full(4, 0.002), "leaf", 3, parent=1, attach=2, w=np.array([0.0, 1.0, 0.3]),
                   lamina_length=0.1),
    ], name="two_level")


def test_children_ride_rigidly_on_the_parent_when_unloaded():
    tree = two_level()
    sim = PaperSim(tree, coupling=False)
    sim.pull(0, (30.0, 0.0, 20.0))
    for _ in range(3):
        sim.step(1 / 60)
    P, R, X = sim.positions, sim.rotations, tree.rest_positions
    assert np.linalg.norm(P[3] - X[3]) > 1e-3  # the trunk did bend
    for obj in (1, 2):
        nodes = tree.object_nodes(obj)
        a = tree.attach_node[obj]
        np.testing.assert_allclose(P[nodes], P[a] + (X[nodes] - X[a]) @ R[a].T, atol=1e-12)
        np.testing.assert_allclose(R[nodes], np.broadcast_to(R[a], (len(nodes), 3, 3)), atol=1e-12)


def test_output_convention_rigid_points_follow_their_node():
    tree = two_level()
    sim = PaperSim(tree, coupling=False)
    sim.pull(1, (0.0, -5.0, 3.0))
    sim.pull(2, (0.0, 0.0, 0.05))
    sim.step(1 / 60)
    P, R, X = sim.positions, sim.rotations, tree.rest_positions
    for obj in range(tree.n_objects):
        nodes = tree.object_nodes(obj)
        # the next node of a segment is its start plus the rotated rest segment
        np.testing.assert_allclose(P[nodes[1:]], P[nodes[:-1]] + np.einsum("kij,kj->ki", R[nodes[:-1]],
                                                                            X[nodes[1:]] - X[nodes[:-1]]), atol=1e-12)
        np.testing.assert_allclose(R[nodes[-1]], R[nodes[-2]])  # a tip carries its last segment
    np.testing.assert_allclose(np.einsum("kij,kil->kjl", R, R), np.broadcast_to(np.eye(3), R.shape), atol=1e-12)
    np.testing.assert_allclose(np.linalg.det(R), 1.0, atol=1e-12)


def test_rest_pose_is_exact_for_presets():
    import treeanim as ta

    for name in ("beam", "small_cherry", "tulip_poplar", "grassland"):
        tree = ta.load_preset(name)
        for integrator in ("exact", "euler"):
            sim = PaperSim(tree, integrator=integrator)
            np.testing.assert_allclose(sim.positions, tree.rest_positions, rtol=0, atol=1e-12)
            for _ in range(3):
                sim.step(1 / 60)
            np.testing.assert_allclose(sim.positions, tree.rest_positions, rtol=0, atol=1e-12)
            np.testing.assert_allclose(sim.rotations, np.broadcast_to(np.eye(3), sim.rotations.shape), atol=1e-12)


def test_frames_follow_eq1_and_fig6():
    tree = two_level()
    F = rest_frames(tree)
    np.testing.assert_allclose(np.einsum("kji,kjl->kil", F, F), np.broadcast_to(np.eye(3), F.shape), atol=1e-12)
    np.testing.assert_allclose(np.linalg.det(F), 1.0)
    X = tree.rest_positions
    for obj in range(tree.n_objects):
        nodes = tree.object_nodes(obj)
        u, v, w = F[obj].T
        np.testing.assert_allclose(v, (X[nodes[1]] - X[nodes[0]]) / np.linalg.norm(X[nodes[1]] - X[nodes[0]]))
        np.testing.assert_allclose(u, np.cross(v, w), atol=1e-15)
        if tree.kind[obj] == "branch":  # Eq. 1: w ∥ P0Pn × v
            e = np.cross(X[nodes[-1]] - X[nodes[0]], v)
            np.testing.assert_allclose(w, e / np.linalg.norm(e), atol=1e-12)
        else:  # Fig. 6: w is the lamina normal (made ⟂ v)
            n = tree.rest_w[obj] - (tree.rest_w[obj] @ v) * v
            np.testing.assert_allclose(w, n / np.linalg.norm(n), atol=1e-12)
    assert dataclasses.is_dataclass(tree.physics)
