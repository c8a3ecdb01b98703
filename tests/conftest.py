"""Shared fixtures: small hand-built trees and one EGL offscreen context per test session."""

from __future__ import annotations

import numpy as np
import pytest

from treeanim.model.build import ObjectSpec, assemble
from treeanim.model.tree import Lamina

# --------------------------------------------------------------------------- markers
#: Modules that draw through OpenGL (EGL offscreen), and those that open a window (Xvfb).
GL_MODULES = {"test_render_gl", "test_render_look", "test_render_uniforms", "test_junctions", "test_offline",
              "test_examples"}
WINDOW_MODULES = {"test_app", "test_render_window"}
#: Tests of a second or more on a 2-core machine (``pytest --durations``): ``-m "not slow"`` is
#: the quick loop, under a minute; CI runs everything.
SLOW = (
    "test_simulation.py::test_free_decay_of_a_beam_has_the_set_f_and_zeta",
    "test_simulation.py::test_release_in_the_u_w_plane_shows_both_frequencies",
    "test_simulation.py::test_euler_agrees_with_exact_at_small_dt",
    "test_simulation.py::test_modal_loads_settle_at_the_load_unit_static_gain",
    "test_export.py",
    "test_examples.py",
    "test_readme.py::test_the_quick_readme_commands_run_as_typed",
    "test_install.py",
    "test_offline.py::test_bench_json_reports_every_preset",
    "test_offline.py::test_a_write_that_fails_part_way",
    "test_offline.py::test_ctrl_c_keeps_a_playable_video",
    "test_offline.py::test_trace_after_release_has_the_beams_modal_frequencies",
    "test_offline.py::test_png_frames_and_still_match_the_simulated_times",
    "test_offline.py::test_render_mp4_reads_back_and_moves",
    "test_offline.py::test_sigterm_during_a_render",
    "test_presets_fuzz.py::test_a_mutated_preset",
    "test_leaves.py",
    "test_grass.py",
    "test_simulation_hypothesis.py",
    "test_wind_physical.py",
    "test_junctions.py::test_collars_stay_welded_in_a_gale",
    "test_species.py::test_crown_pruning_and_leaf_placement_keep_the_invariants",
    "test_model.py::test_generator_invariants",
    "test_app.py",
)


def pytest_collection_modifyitems(items):
    for item in items:
        module = item.path.stem
        if module in GL_MODULES:
            item.add_marker(pytest.mark.gl)
        if module in WINDOW_MODULES:
            item.add_marker(pytest.mark.window)
        nodeid = f"{item.path.name}::{item.name}"
        if nodeid.startswith(SLOW):
            item.add_marker(pytest.mark.slow)


def rot(axis, angle):
    """The rotation matrix of ``angle`` radians about ``axis`` (the identity for a zero axis)."""
    axis = np.asarray(axis, float)
    n = np.linalg.norm(axis)
    if n == 0:
        return np.eye(3)
    axis = axis / n
    K = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K


def identity(tree):
    """(N, 3, 3) identity rotations: every node of ``tree`` at rest."""
    return np.broadcast_to(np.eye(3), (tree.n_nodes, 3, 3))


def rest_pose(tree):
    """``tree``'s rest pose as a renderer takes it: (positions, rotations)."""
    return tree.rest_positions, identity(tree)


class Uniform:
    """A steady uniform wind U (m/s) everywhere (only ``sample`` is needed)."""

    def __init__(self, U):
        self.U = np.asarray(U, float)

    def sample(self, points, t):
        return np.tile(self.U, (len(points), 1))


def ovate_lamina(k: int = 24, curl: float = 0.12) -> Lamina:
    """An ovate, pointed leaf outline (midrib length 1), fan-triangulated from its base."""
    s = np.linspace(0.0, 1.0, k // 2 + 1)
    y = s
    half = 0.42 * np.sin(np.pi * s) ** 0.8 * (1.0 - 0.35 * s)
    right = np.stack([half, y], 1)[1:-1]
    left = np.stack([-half, y], 1)[1:-1][::-1]
    outline = np.concatenate([[[0.0, 0.0]], right, [[0.0, 1.0]], left])
    n = len(outline)
    tris = np.stack([np.zeros(n - 2, int), np.arange(1, n - 1), np.arange(2, n)], 1)
    return Lamina("ovate", outline, tris, curl)


def _curve(base, direction, length, n, bend=0.0, bend_dir=(0.0, -1.0, 0.0)):
    """n points from ``base`` along ``direction``, curving gently towards ``bend_dir``."""
    d = np.asarray(direction, float)
    d = d / np.linalg.norm(d)
    g = np.asarray(bend_dir, float)
    pts = [np.asarray(base, float)]
    step = length / (n - 1)
    for _ in range(n - 1):
        pts.append(pts[-1] + step * d)
        d = d + bend * g
        d = d / np.linalg.norm(d)
    return np.array(pts)


def small_tree(leaves_per_twig: int = 4, seed: int = 3) -> "Tree":  # noqa: F821
    """A ~2.5 m tree: trunk, 5 branches, 3 twigs each, leaves on the twigs (hand-built)."""
    rng = np.random.default_rng(seed)
    specs: list[ObjectSpec] = []
    trunk = _curve((0, 0, 0), (0.03, 1, 0.0), 1.6, 6)
    specs.append(ObjectSpec(trunk, np.linspace(0.16, 0.07, 6), "branch", 1))
    for b in range(5):
        at = 2 + b % 4
        az = 2 * np.pi * b / 5 + 0.3
        d = (np.cos(az), 0.9, np.sin(az))
        pts = _curve(trunk[at], d, 1.0, 5, bend=0.08)
        specs.append(ObjectSpec(pts, np.linspace(0.06, 0.02, 5), "branch", 2, parent=0, attach=at))
        bi = len(specs) - 1
        for t in range(3):
            tat = 2 + t % 3
            az2 = az + (t - 1) * 0.9
            d2 = (np.cos(az2), 0.6 + 0.3 * t, np.sin(az2))
            tw = _curve(pts[tat], d2, 0.55, 4, bend=0.1)
            specs.append(ObjectSpec(tw, np.linspace(0.02, 0.008, 4), "branch", 3, parent=bi, attach=tat))
            ti = len(specs) - 1
            for leaf in range(leaves_per_twig):
                lat = 1 + leaf % 3
                dl = rng.normal(size=3) + np.array([0.0, 0.3, 0.0])
                pet = _curve(tw[lat], dl, 0.05, 4, bend=0.15)
                wl = np.cross(dl, rng.normal(size=3))
                specs.append(ObjectSpec(pet, np.full(4, 0.004), "leaf", 4, parent=ti, attach=lat,
                                        w=wl, lamina_length=0.16))
    return assemble(specs, name="small_test", lamina=ovate_lamina(), petiole_sides=4, seed=seed,
                    winter_leaves=4)


def grass_patch(n: int = 60, seed: int = 5) -> "Tree":  # noqa: F821
    """A patch of ``n`` grass blades (4 nodes each) on a 1 m square."""
    rng = np.random.default_rng(seed)
    specs = []
    for _ in range(n):
        base = (rng.uniform(-0.5, 0.5), 0.0, rng.uniform(-0.5, 0.5))
        lean = rng.normal(size=3) * 0.2
        pts = _curve(base, (lean[0], 1.0, lean[2]), rng.uniform(0.25, 0.4), 4, bend=0.15,
                     bend_dir=(lean[0], -1.0, lean[2]))
        specs.append(ObjectSpec(pts, np.array([0.02, 0.018, 0.012, 0.005]), "blade", 1))
    return assemble(specs, name="grass_test", seed=seed)


def beam_tree() -> "Tree":  # noqa: F821
    """One curved beam (the 'beam' preset's shape)."""
    pts = _curve((0, 0, 0), (0.2, 1, 0), 2.0, 9, bend=0.05, bend_dir=(1.0, 0.0, 0.0))
    return assemble([ObjectSpec(pts, np.linspace(0.1, 0.03, 9), "branch", 1)], name="beam_test")


def twig_tree(length: float = 0.6) -> "Tree":  # noqa: F821
    """A 1 m trunk carrying one straight one-segment twig along +x at its top."""
    trunk = _curve((0, 0, 0), (0, 1, 0), 1.0, 3)
    twig = np.array([trunk[2], trunk[2] + (length, 0.0, 0.0)])
    return assemble([ObjectSpec(trunk, np.linspace(0.08, 0.05, 3), "branch", 1),
                     ObjectSpec(twig, np.array([0.03, 0.015]), "branch", 2, parent=0, attach=2)],
                    name="twig_test")


@pytest.fixture(scope="session")
def tree():
    return small_tree()


@pytest.fixture(scope="session")
def grass():
    return grass_patch()


@pytest.fixture(scope="session")
def offscreen():
    """One EGL context for the whole session (creating contexts is the slow part)."""
    from treeanim.render.offscreen import OffscreenRenderer

    off = OffscreenRenderer(160, 120, samples=4)
    yield off
    off.release()
