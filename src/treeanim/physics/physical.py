"""Physical modal parameters (``modes="physical"``): each branch's frequency from beam theory.

The paper maps d/h² onto a preset's frequency range (Eqs. 20–22, :mod:`.modal`). Here every
branch is instead a tapered Euler–Bernoulli cantilever clamped at its base, of Young's modulus
``wood_youngs_modulus`` (EI = E π D⁴/64 along it), its own mass spread along it, and carrying
what grows on it — each child's whole subtree (wood and the leaves present) as a rigid body at
the node it sits on (its mass, and its first and second moments about that node, so a wide
crown's rotary inertia counts). Its first bending frequency comes from Stodola's iteration on
that beam: each segment is cut into elements (at least :data:`MIN_ELEMENTS` per object), the
deflection under the inertial load of the last shape is integrated exactly for moments linear
over an element of constant EI, and the Rayleigh quotient of successive shapes converges to
ω² from above.

Damping: ζ = ``wood_damping`` (the wood's internal damping) plus the drag of everything the
mode moves, linearised about a light air speed :data:`U_REF` (the calm in which field
pull-and-release tests are made): c = ρ C A U_REF per object, ζ_air = Σc·y² / (2 ω Σm·y²)
with y the mode shape over the branch's own elements and its children's bases. Leaves add
mass (the frequency falls) and a large drag area for their mass (ζ rises).

These modes drive the paper's oscillators (``model="paper"``, ``modes="physical"``); the tree
model takes its stiffness from beam theory itself. Modes above :data:`QUASI_STATIC_F` are
critically damped (ζ = 1): they keep their frequency, so their stiffness is the beam's, but a
short stout twig ringing at tens of hertz is invisible at any frame rate.

Leaves and grass blades keep the paper's mapping: a petiole modelled as a cantilever would ring
at tens of hertz, while a leaf's visible motion comes from its twig and its flutter.
"""

from __future__ import annotations

import numpy as np

from ..model.geometry import segment_lengths
from ..model.params import PhysicsParams
from ..model.tree import Tree
from .compiled import njit
from .modal import ModalParameters, subtree_sums

__all__ = ["MODAL_MODELS", "MIN_ELEMENTS", "QUASI_STATIC_F", "MAX_PHYSICAL_F", "U_REF", "branch_modes", "physical_modes", "subtree_sums"]

#: The sources of modal parameters a Simulation accepts.
MODAL_MODELS = ("paper", "physical")
#: Fewest beam elements per object (the first cantilever mode of a uniform beam is then within
#: 0.1 % of its exact frequency).
MIN_ELEMENTS = 32
#: Air speed (m/s) about which drag is linearised into modal damping.
U_REF = 1.0
#: Frequency (Hz) above which a branch's mode is critically damped (see the module notes).
QUASI_STATIC_F = 5.0
#: The highest frequency given (Hz; the paper's oscillators accept up to 10⁴): a scan's stub
#: twig computes to 14–20 kHz, and is just as stiff, critically damped, at this one.
MAX_PHYSICAL_F = 1.0e4
#: Stodola iterations (from the static deflection under the beam's own weight).
ITERATIONS = 6


def _node_weights(tree: Tree, per_object: np.ndarray) -> np.ndarray:
    """Spread each object's value over its nodes: a leaf's on its tip (the lamina), a branch's
    by the volume of the segments each node ends (half of each)."""
    d = np.asarray(tree.node_diameter, float)
    seg = segment_lengths(tree)
    vol = np.zeros(len(d))
    vol[:-1] = 0.25 * (d[1:] + d[:-1]) ** 2 * seg[:-1]  # zero past each tip (seg = 0 there)
    node_vol = 0.5 * vol
    node_vol[1:] += 0.5 * vol[:-1]
    start = np.asarray(tree.object_start)
    node_vol[start] = 0.5 * vol[start]  # nothing from the previous object
    obj = tree.node_object
    leaf = tree.kind[obj] == "leaf"
    tip = np.asarray(tree.object_start) + np.asarray(tree.object_count) - 1
    node_vol[leaf] = 0.0
    is_tip = np.zeros(len(d), bool)
    is_tip[tip] = True
    node_vol[leaf & is_tip] = 1.0
    total = np.bincount(obj, node_vol, tree.n_objects)
    return np.asarray(per_object, float)[obj] * node_vol / np.maximum(total[obj], 1e-300)


def _carried(tree: Tree, per_object: np.ndarray, kids: np.ndarray, axis: np.ndarray) -> np.ndarray:
    """(3, K) inertia of each child's whole subtree about the point it sits on, for a parent
    swaying across ``axis`` (its direction there): the total S0, the first moment along the axis
    S1, and the second moment S2 (along the axis, plus half the radial one: a point beside the
    axis moves along it as the section turns, in a sway plane of any direction)."""
    X = np.asarray(tree.rest_positions, float)
    w = _node_weights(tree, per_object)
    start = np.asarray(tree.object_start)
    mom = np.concatenate([w[:, None], w[:, None] * X, (w[:, None, None] * X[:, :, None] * X[:, None, :])
                          .reshape(-1, 9)], axis=1)
    sub = subtree_sums(tree, np.add.reduceat(mom, start, axis=0))[kids]
    S0, Sx, Sxx = sub[:, 0], sub[:, 1:4], sub[:, 4:].reshape(-1, 3, 3)
    P = X[np.asarray(tree.attach_node)[kids]]
    S1v = Sx - S0[:, None] * P
    J = Sxx - np.einsum("ki,kj->kij", Sx, P) - np.einsum("ki,kj->kij", P, Sx) + S0[:, None, None] * \
        np.einsum("ki,kj->kij", P, P)
    a2 = np.einsum("ki,kij,kj->k", axis, J, axis)
    radial2 = np.trace(J, axis1=1, axis2=2) - a2
    return np.stack([S0, np.einsum("ki,ki->k", S1v, axis), a2 + 0.5 * radial2])


def branch_modes(tree: Tree, youngs_modulus: float, mass: np.ndarray, air: np.ndarray,
                 objects: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """First bending frequency and air damping of the given objects as loaded cantilevers.

    Parameters
    ----------
    tree : Tree
    youngs_modulus : float
        E (Pa) of the wood.
    mass : (M,) float
        Each object's own mass (kg; zero for absent leaves), spread along it by volume (a
        leaf's at its lamina).
    air : (M,) float
        Each object's ½ρ C A (kg/m; zero where absent), spread the same way.
    objects : (K,) int
        The objects to analyse (branches).

    Returns
    -------
    f : (K,) float
        First natural frequency (Hz).
    zeta_air : (K,) float
        Damping ratio of the linearised drag at :data:`U_REF` on that mode.
    """
    objects = np.asarray(objects, np.int64)
    K = len(objects)
    if K == 0:
        return np.zeros(0), np.zeros(0)
    start = np.asarray(tree.object_start)[objects]
    nseg = np.asarray(tree.object_count)[objects] - 1
    per_seg = -(-MIN_ELEMENTS // nseg)  # elements per segment of each object
    seg_node = np.repeat(start, nseg) + (np.arange(nseg.sum()) - np.repeat(np.cumsum(nseg) - nseg, nseg))
    seg_obj = np.repeat(np.arange(K), nseg)
    h_seg = segment_lengths(tree)[seg_node]
    d = np.asarray(tree.node_diameter, float)
    # Elements: per_seg equal parts of each segment, object by object, base to tip.
    k_el = per_seg[seg_obj]
    el_seg = np.repeat(np.arange(len(seg_node)), k_el)
    el_i = np.arange(len(el_seg)) - np.repeat(np.cumsum(k_el) - k_el, k_el)
    t_mid = (el_i + 0.5) / k_el[el_seg]
    d_mid = d[seg_node[el_seg]] + t_mid * (d[seg_node[el_seg] + 1] - d[seg_node[el_seg]])
    h = h_seg[el_seg] / k_el[el_seg]
    el_obj = seg_obj[el_seg]
    n_el = np.bincount(el_obj, minlength=K)
    EI = youngs_modulus * np.pi / 64.0 * d_mid**4
    # Stations: each object's base, then the end of each element (station = element + object + 1).
    n_st = len(h) + K
    st_end = np.arange(len(h)) + el_obj + 1
    base = np.cumsum(n_el + 1) - (n_el + 1)
    st_obj = np.repeat(np.arange(K), n_el + 1)
    x = np.zeros(n_st)
    x[st_end] = h
    x = _segmented_cumsum(x, base, n_el + 1)
    # What grows on each object: its children's subtrees, rigid, at the stations they sit on.
    which = np.full(tree.n_objects, -1, np.int64)
    which[objects] = np.arange(K)
    kids = np.flatnonzero((tree.parent >= 0) & (which[np.maximum(tree.parent, 0)] >= 0))
    kp = which[tree.parent[kids]]
    node_in = np.asarray(tree.attach_node)[kids] - start[kp]
    kid_st = base[kp] + node_in * per_seg[kp]
    X = np.asarray(tree.rest_positions, float)
    at = np.asarray(tree.attach_node)[kids]
    at_seg = np.where(node_in < nseg[kp], at, at - 1)  # the parent's segment there
    axis = X[at_seg + 1] - X[at_seg]
    axis /= np.linalg.norm(axis, axis=1, keepdims=True)

    def inertia(own: np.ndarray):
        """Lumped station weights and the children's (S0, S1, S2) of a per-object quantity."""
        vol, area = d_mid**2 * h, d_mid * h
        share = vol if own is mass else area
        w_el = own[objects][el_obj] * share / np.bincount(el_obj, share, K)[el_obj]
        w_st = np.zeros(n_st)
        np.add.at(w_st, st_end, 0.5 * w_el)
        np.add.at(w_st, st_end - 1, 0.5 * w_el)
        S = _carried(tree, own, kids, axis)
        np.add.at(w_st, kid_st, S[0])
        w_st[base] = 0.0  # clamped
        return w_st, S

    def loads(w_st, S, y, theta):
        """Forces and moments at the stations of a shape (y, θ) weighted by (w_st, S)."""
        P = w_st * y
        C = np.zeros(n_st)
        np.add.at(P, kid_st, S[1] * theta[kid_st])
        np.add.at(C, kid_st, S[1] * y[kid_st] + S[2] * theta[kid_st])
        return P, C

    a, b = st_end - 1, st_end  # each element's start and end station

    def deflect(P, C):
        B = _segmented_suffix(P, base, n_el + 1)
        A = _segmented_suffix(P * x, base, n_el + 1)
        M = A - x * B + _segmented_suffix(C, base, n_el + 1) - C  # of the loads beyond each station
        Ma, Mb = M[a], M[b] + C[b]  # over an element: a moment at its end acts on all of it
        dtheta = h * (Ma + Mb) / (2.0 * EI)
        theta0 = _segmented_cumsum(dtheta, base - np.arange(K), n_el) - dtheta
        dy = h * theta0 + h * h * (2.0 * Ma + Mb) / (6.0 * EI)
        y = np.zeros(n_st)
        th = np.zeros(n_st)
        y[st_end] = dy
        th[st_end] = dtheta
        return _segmented_cumsum(y, base, n_el + 1), _segmented_cumsum(th, base, n_el + 1)

    m_st, Sm = inertia(mass)
    c_st, Sc = inertia(air)
    def unit_tip(y, theta):
        scale = 1.0 / np.maximum(np.abs(y[base + n_el]), 1e-300)[st_obj]
        return y * scale, theta * scale

    y, theta = unit_tip(*deflect(m_st, np.zeros(n_st)))  # the static deflection under its weight
    for _ in range(ITERATIONS):
        P, C = loads(m_st, Sm, y, theta)
        y_next, th_next = deflect(P, C)
        num = np.bincount(st_obj, P * y_next + C * th_next, K)
        P1, C1 = loads(m_st, Sm, y_next, th_next)
        den = np.bincount(st_obj, P1 * y_next + C1 * th_next, K)
        y, theta = unit_tip(y_next, th_next)
    omega = np.sqrt(num / den)
    P, C = loads(m_st, Sm, y, theta)
    m_gen = np.bincount(st_obj, P * y + C * theta, K)
    P, C = loads(c_st, Sc, y, theta)
    c_gen = np.bincount(st_obj, P * y + C * theta, K)
    zeta_air = U_REF * c_gen / (omega * m_gen)  # c = 2·½ρCA·U_REF on the mode, over 2ωm
    return omega / (2.0 * np.pi), zeta_air


def _segmented_cumsum(v: np.ndarray, first: np.ndarray, count: np.ndarray) -> np.ndarray:
    """Cumulative sums of ``v`` restarting at each run (runs ``first[i] : first[i] + count[i]``
    tile ``v``), each run summed on its own: one running sum minus its value at a run's start
    lost a deep tree's small outer runs to the round-off of the large inner ones (NaN modes for
    the tip of a 5,000-deep chain)."""
    return _runs(np.ascontiguousarray(v, float), np.asarray(first, np.int64), np.asarray(count, np.int64), False)


def _segmented_suffix(v: np.ndarray, first: np.ndarray, count: np.ndarray) -> np.ndarray:
    """Sums of ``v`` from each entry to the end of its run (inclusive)."""
    return _runs(np.ascontiguousarray(v, float), np.asarray(first, np.int64), np.asarray(count, np.int64), True)


@njit(cache=True)
def _runs(v, first, count, suffix):
    out = np.empty_like(v)
    for i in range(first.shape[0]):
        s = 0.0
        for j in range(count[i]):
            k = first[i] + count[i] - 1 - j if suffix else first[i] + j
            s += v[k]
            out[k] = s
    return out


def physical_modes(tree: Tree, params: PhysicsParams, paper: ModalParameters, mass: np.ndarray,
                   air: np.ndarray) -> ModalParameters:
    """Modal parameters with the branches' f and ζ from beam theory (see the module notes).

    Parameters
    ----------
    tree : Tree
    params : PhysicsParams
        ``wood_youngs_modulus`` and ``wood_damping``.
    paper : ModalParameters
        The paper's modes (:func:`~treeanim.physics.modal.derive_modes`), kept for leaves and
        blades.
    mass : (M,) float
        Each object's own mass (kg), zero for leaves that are not present.
    air : (M,) float
        Each object's ½ρ C A (kg/m), zero where not present.

    Returns
    -------
    ModalParameters
        New arrays: branches' three modes all at their beam frequency (at most
        :data:`MAX_PHYSICAL_F`) and damping (1 above :data:`QUASI_STATIC_F`).
    """
    F, Z = paper.f.copy(), paper.zeta.copy()
    branches = np.flatnonzero(tree.kind == "branch")
    f, zeta_air = branch_modes(tree, params.wood_youngs_modulus, np.asarray(mass, float),
                               np.asarray(air, float), branches)
    F[branches] = np.minimum(f, MAX_PHYSICAL_F)[:, None]
    Z[branches] = np.where(f > QUASI_STATIC_F, 1.0, params.wood_damping + zeta_air)[:, None]
    return ModalParameters(F, Z)
