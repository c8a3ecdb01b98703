"""Shared geometry helpers (treeanim.model.geometry), the Tree's argument checks, the modal
seed and the overflow safety of the bending."""

import numpy as np
import pytest

from treeanim.model import build, geometry
from treeanim.model.build import ObjectSpec, assemble
from treeanim.model.geometry import (
    arc_length,
    lamina_frames,
    object_lengths,
    perpendicular,
    polygon_area,
    polygon_centroid,
    segment_lengths,
    unit,
)
from treeanim.physics import modal
from treeanim.physics.bending import BendingPlan, rest_frames
from treeanim.physics.modal import ModalDraws
from treeanim.physics.paper_sim import PaperSim
from treeanim.render import mesh
from treeanim.validate import finite_float


def test_unit_and_perpendicular():
    v = np.array([[3.0, 4.0, 0.0], [0.0, 0.0, 0.0], [0.0, 2.0, 0.0], [1e-3, -5.0, 2.0]])
    u = unit(v)
    np.testing.assert_allclose(np.linalg.norm(u[[0, 2, 3]], axis=1), 1.0)
    np.testing.assert_array_equal(u[1], 0.0)  # no NaN for a zero vector
    fb = np.array([1.0, 0.0, 0.0])
    np.testing.assert_array_equal(unit(v, fb)[1], fb)
    p = perpendicular(v[[0, 2, 3]])
    np.testing.assert_allclose(np.linalg.norm(p, axis=1), 1.0)
    np.testing.assert_allclose(np.einsum("ij,ij->i", p, v[[0, 2, 3]]), 0.0, atol=1e-15)
    np.testing.assert_allclose(perpendicular(np.array([0.0, 1.0, 0.0])) @ [0.0, 1.0, 0.0], 0.0)


def test_one_home_for_the_shared_helpers():
    assert build.perpendicular is geometry.perpendicular
    assert mesh.lamina_frames is geometry.lamina_frames and mesh.arc_length is geometry.arc_length
    assert modal.object_lengths is geometry.object_lengths


def test_polygon_area_and_centroid():
    square = np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 1.0], [0.0, 1.0]])
    assert polygon_area(square) == pytest.approx(2.0)
    assert polygon_area(square[::-1]) == pytest.approx(2.0)
    assert polygon_area(square[::-1], signed=True) == pytest.approx(-2.0)
    assert polygon_centroid(square) == pytest.approx((1.0, 0.5))
    assert polygon_centroid(square[::-1]) == pytest.approx((1.0, 0.5))
    tri = np.array([[0.0, 0.0], [3.0, 0.0], [0.0, 3.0]])
    assert polygon_centroid(tri) == pytest.approx((1.0, 1.0))
    line = np.array([[0.0, 0.0], [1.0, 1.0], [2.0, 2.0]])
    assert polygon_centroid(line) == pytest.approx((1.0, 1.0))  # degenerate: vertex mean


def test_lamina_area_is_the_polygon_area(tree):
    assert tree.lamina.area == polygon_area(tree.lamina.outline)


def test_lengths_never_cross_object_boundaries(tree):
    seg = segment_lengths(tree)
    arc = arc_length(tree)
    tips = tree.object_start + tree.object_count - 1
    assert np.all(seg[tips] == 0.0)
    np.testing.assert_array_equal(arc[tree.object_start], 0.0)
    for i in range(tree.n_objects):
        nodes = tree.object_nodes(i)
        d = np.linalg.norm(np.diff(tree.rest_positions[nodes], axis=0), axis=1)
        np.testing.assert_allclose(seg[nodes[:-1]], d, rtol=1e-15)
        np.testing.assert_allclose(arc[nodes], np.concatenate([[0.0], np.cumsum(d)]), rtol=1e-12, atol=1e-15)
        assert object_lengths(tree)[i] == pytest.approx(d.sum(), rel=1e-12)


def test_lamina_frame_sits_on_the_last_petiole_segment(tree):
    leaves = np.flatnonzero(tree.kind == "leaf")
    tipn, u, v, w = lamina_frames(tree, leaves)
    P = tree.rest_positions
    np.testing.assert_array_equal(tipn, tree.object_start[leaves] + tree.object_count[leaves] - 1)
    np.testing.assert_allclose(v, unit(P[tipn] - P[tipn - 1]), rtol=1e-12)
    R = np.stack([u, v, w], axis=2)
    np.testing.assert_allclose(R.transpose(0, 2, 1) @ R, np.broadcast_to(np.eye(3), R.shape), atol=1e-12)
    np.testing.assert_allclose(np.linalg.det(R), 1.0)
    # w is the leaf's lamina normal, made perpendicular to v.
    assert np.all(np.einsum("ij,ij->i", w, tree.rest_w[leaves]) > 0)


# ----------------------------------------------------------------------------- Tree checks
@pytest.mark.parametrize("i", [-1, 10**6, 1.5, np.float64(2.0), "3", True, None])
def test_object_nodes_refuses_bad_indices(tree, i):
    with pytest.raises(ValueError, match="object index i"):
        tree.object_nodes(i)


def test_object_nodes_accepts_numpy_integers(tree):
    np.testing.assert_array_equal(tree.object_nodes(np.int64(2)), tree.object_nodes(2))


@pytest.mark.parametrize("season", [float("nan"), float("inf"), -float("inf"), "winter", None])
def test_leaves_present_refuses_non_finite_seasons(tree, season):
    with pytest.raises(ValueError, match="season"):
        tree.leaves_present(season)


def test_leaves_present_still_clips_finite_seasons(tree):
    np.testing.assert_array_equal(tree.leaves_present(-3.0), tree.leaves_present(0.0))
    np.testing.assert_array_equal(tree.leaves_present(7.0), tree.leaves_present(1.0))


@pytest.mark.parametrize("value", [float("nan"), float("inf"), "x", None, 10**400])
def test_finite_float_names_the_argument(value):
    with pytest.raises(ValueError, match="^speed must be"):
        finite_float("speed", value)


# ----------------------------------------------------------------------------- modal seed
def test_modal_draws_use_the_whole_seed():
    a, b = ModalDraws.draw(50, 0), ModalDraws.draw(50, 2**32)
    assert not np.array_equal(a.noise, b.noise)
    assert not np.array_equal(a.f_uniform, b.f_uniform)
    c = ModalDraws.draw(50, 2**32)
    np.testing.assert_array_equal(b.noise, c.noise)


# ----------------------------------------------------------------------------- overflow
def _beam():
    pts = np.stack([np.linspace(0, 0.3, 7), np.linspace(0, 2.0, 7), np.zeros(7)], 1)
    return assemble([ObjectSpec(pts, np.linspace(0.08, 0.03, 7), "branch", 1)], name="b")


@pytest.mark.parametrize("F", [1e7, 1e160, 1e250, 1e300])
def test_bending_huge_forces_stays_finite_and_keeps_lengths(F, tree):
    with np.errstate(all="raise"):
        for t in (_beam(), tree):
            sim = PaperSim(t)
            plan = BendingPlan(t, rest_frames(t))
            M = t.n_objects
            plan.bend(np.full(M, F), np.full(M, -0.5 * F), np.zeros(M), sim._k)
            assert np.all(np.isfinite(plan.o)) and np.all(np.isfinite(plan.q))
            np.testing.assert_allclose(np.linalg.norm(plan.q[:, :-1], axis=0), 1.0, atol=1e-12)
            assert np.all(plan.phi >= 0)
