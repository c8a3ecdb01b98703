"""The whole tree as one mechanical structure (docs/design.md §12): the static model of the
``tree`` stepper, derived from the tree, its physics and the leaves present.

Every segment of a branch or a grass blade is a rigid body, jointed to the segment (or the
parent's segment) it grows from by a ball joint whose springs come from beam theory; every
present leaf is a lamina on a petiole that rides its twig (its mass rigidly in the twig's
inertia) and turns on its own petiole joint (:func:`~treeanim.physics.articulated.leaf_step`).

Beam theory, per segment of length ℓ between diameters d₀ and d₁ (E the wood's Young's
modulus, ν = 0.3):

* flexural rigidity EI = Eπd⁴/64 with d⁴ the harmonic mean of the linear taper's d⁴ over the
  segment (the segment's own compliance ∫dx/EI);
* bending spring k_b = EI/(ℓ·g), g = (1 − (1 − ℓ/L)³)/(3ℓ/L), L the object's length beyond
  the joint: the springs of a chain of segments then give a uniform cantilever's exact tip
  compliance L³/3EI (a single segment: k = 3EI/ℓ; a short segment low on a long branch EI/ℓ);
* twist spring k_t = GJ/ℓ = EI/((1 + ν)ℓ);
* damping D = (2ζ/ω)·K (stiffness-proportional), ζ the wood's damping ratio and ω the lowest
  swing of the joint's branch (Rayleigh's quotient of everything beyond the branch's base,
  flexible: :func:`_flexible_frequency`), so each branch sways damped at ζ.

Petioles are cantilevers of the leaf's modulus loaded at the lamina's centroid (lever r):
k_b = EI·r/(ℓ(r − ℓ/2)), and twist k_t = k_b·ℓ/(r·EI/GJ) with a petiole's EI/GJ of 4
(grooved petioles twist several times more readily than they bend: Vogel 1992).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
from scipy.spatial import ConvexHull, QhullError

from ..model.geometry import lamina_frames, polygon_centroid, unit
from ..model.scene import Scene
from .compiled import njit

__all__ = ["Structure", "foliage_clusters", "leaf_clusters", "POISSON", "PETIOLE_BEND_TWIST", "PLATE_NORMAL_DRAG"]

#: Poisson's ratio of wood along the grain (G = E / 2(1 + ν)).
POISSON = 0.3
#: EI/GJ of a petiole (Vogel 1992: 1.5–6; grooved petioles twist readily).
PETIOLE_BEND_TWIST = 4.0
#: The normal-force coefficient of a flat plate across the flow (Hoerner): the air's resistance
#: to a lamina's own swing about its petiole.
PLATE_NORMAL_DRAG = 1.2


@njit(cache=True, fastmath=True, error_model="numpy")
def _subtree_inertia(parent, r0, m, h, J, out_m, out_h, out_J):
    """Mass, first and second moments (rest axes, about each joint) of everything beyond each
    joint: the body itself and all its descendants."""
    B = parent.shape[0]
    for b in range(B):
        out_m[b] = m[b]
        for i in range(3):
            out_h[b, i] = h[b, i]
            for j in range(3):
                out_J[b, i, j] = J[b, i, j]
    for b in range(B - 1, -1, -1):
        p = parent[b]
        if p < 0:
            continue
        r = r0[b]
        mb = out_m[b]
        hb = out_h[b]
        # shift to the parent's joint: h' = h + m r, J' = J + m(|r|²1 − rrᵀ) + (|...| cross terms)
        # J about a point displaced by −r: J' = J + 2 sym(r·hᵀ terms) + m(|r|²1 − rrᵀ)
        rh = r[0] * hb[0] + r[1] * hb[1] + r[2] * hb[2]
        rr = r[0] * r[0] + r[1] * r[1] + r[2] * r[2]
        out_m[p] += mb
        for i in range(3):
            out_h[p, i] += hb[i] + mb * r[i]
            for j in range(3):
                d = 1.0 if i == j else 0.0
                out_J[p, i, j] += out_J[b, i, j] + 2.0 * rh * d - r[i] * hb[j] - hb[i] * r[j] + mb * (rr * d - r[i] * r[j])


@njit(cache=True, fastmath=True, error_model="numpy")
def _flexible_frequency(parent, child_start, children, P, C, m, sh, kb, axis, out):
    """Each joint's own bending frequency with everything beyond it flexible: Rayleigh's
    quotient ω² = Σ m δ·e / Σ m |δ|² of the static deflection δ of its subtree, clamped at the
    joint, under a unit acceleration e across the joint's axis (the lower of two such e); each
    joint i beyond turns by (Σ m(c − p_i)) × e / k_b,i."""
    B = m.shape[0]
    stack = np.empty(B, np.int64)
    Th = np.empty((B, 3))
    S = np.empty((B, 3))
    for j in range(B):
        ax, ay, az = axis[j, 0], axis[j, 1], axis[j, 2]
        e1x, e1y, e1z = -az, 0.0, ax  # a × ŷ
        n = np.sqrt(e1x * e1x + e1z * e1z)
        if n < 1e-6:
            e1x, e1y, e1z, n = 0.0, az, -ay, np.sqrt(ay * ay + az * az)  # a × x̂
        e1x, e1y, e1z = e1x / n, e1y / n, e1z / n
        e2x, e2y, e2z = ay * e1z - az * e1y, az * e1x - ax * e1z, ax * e1y - ay * e1x
        best = np.inf
        for d in range(2):
            ex, ey, ez = (e1x, e1y, e1z) if d == 0 else (e2x, e2y, e2z)
            num = 0.0
            den = 0.0
            top = 0
            stack[0] = j
            while top >= 0:
                i = stack[top]
                top -= 1
                tx = (sh[i, 1] * ez - sh[i, 2] * ey) / kb[i]
                ty = (sh[i, 2] * ex - sh[i, 0] * ez) / kb[i]
                tz = (sh[i, 0] * ey - sh[i, 1] * ex) / kb[i]
                sx = ty * P[i, 2] - tz * P[i, 1]
                sy = tz * P[i, 0] - tx * P[i, 2]
                sz = tx * P[i, 1] - ty * P[i, 0]
                if i != j:  # add the parent's accumulated turns
                    q = parent[i]
                    tx += Th[q, 0]
                    ty += Th[q, 1]
                    tz += Th[q, 2]
                    sx += S[q, 0]
                    sy += S[q, 1]
                    sz += S[q, 2]
                Th[i, 0], Th[i, 1], Th[i, 2] = tx, ty, tz
                S[i, 0], S[i, 1], S[i, 2] = sx, sy, sz
                dx = ty * C[i, 2] - tz * C[i, 1] - sx
                dy = tz * C[i, 0] - tx * C[i, 2] - sy
                dz = tx * C[i, 1] - ty * C[i, 0] - sz
                num += m[i] * (dx * ex + dy * ey + dz * ez)
                den += m[i] * (dx * dx + dy * dy + dz * dz)
                for c in range(child_start[i], child_start[i + 1]):
                    top += 1
                    stack[top] = children[c]
            if den > 0.0 and num > 0.0:
                best = min(best, num / den)
        out[j] = np.sqrt(best)


def foliage_clusters(X: np.ndarray, leaf_area: np.ndarray, lai: float) -> float:
    """How many real leaves each of a tree's leaves stands for: enough that all of them cover
    ``lai`` times the crown's ground projection (the convex hull of the nodes seen from
    above), at least one.

    Parameters
    ----------
    X : (N, 3) float
        Rest node positions (y up).
    leaf_area : (L,) float
        Every leaf's lamina area (m²), present or not.
    lai : float
        The leaf area index wanted (m²/m²).
    """
    total = float(np.sum(leaf_area))
    if total <= 0.0:
        return 1.0
    xz = np.asarray(X, float)[:, [0, 2]]
    try:
        crown = float(ConvexHull(xz).volume)  # in 2-D, the hull's area
    except (QhullError, ValueError):
        return 1.0  # a crown with no extent across (all nodes on a line)
    return max(1.0, lai * crown / total)


def leaf_clusters(tree, X: np.ndarray, leaves: np.ndarray, leaf_area: np.ndarray, lai: float) -> np.ndarray:
    """(L,) :func:`foliage_clusters` per leaf: of its own tree's crown in a scene (each placed
    tree's nodes and leaves), of the whole tree otherwise."""
    if not isinstance(tree, Scene) or tree.n_trees <= 1:
        return np.full(len(leaves), foliage_clusters(X, leaf_area, lai))
    owner = tree.object_tree[leaves]
    out = np.ones(len(leaves))
    for k in np.unique(owner):
        mine = owner == k
        out[mine] = foliage_clusters(X[tree.tree_nodes(int(k))], leaf_area[mine], lai)
    return out


def _point_moments(mass: np.ndarray, r: np.ndarray):
    """First and second moments of point masses at offsets r (K, 3)."""
    rr = np.einsum("ij,ij->i", r, r)
    J = mass[:, None, None] * (rr[:, None, None] * np.eye(3) - r[:, :, None] * r[:, None, :])
    return mass[:, None] * r, J


@dataclass
class Structure:
    """The tree stepper's static model. Build it with :meth:`build`.

    Bodies (B): every segment of every branch and blade, a parent before its children.
    Leaves (L): every leaf object, present or not (absent ones are still posed, carrying nothing).
    """

    parent: np.ndarray      # (B,) int64, −1: the ground
    r0: np.ndarray          # (B, 3) rest offset of the joint from the parent's joint
    node: np.ndarray        # (B,) the node at each joint
    tip: np.ndarray         # (B,) bool: the object's last segment
    tip_node: np.ndarray    # (B,) the node at its end
    obj: np.ndarray         # (B,) the object of each body
    axis: np.ndarray        # (B, 3) rest unit axis
    length: np.ndarray      # (B,)
    mid0: np.ndarray        # (B, 3) rest offset of the segment's middle from its joint
    seg0: np.ndarray        # (B, 3) rest segment, joint to end
    floor: np.ndarray       # (B,) lowest height of the segment's end: its radius (its rest height if lower)
    m0: np.ndarray          # (B,) mass with the present leaves
    h0: np.ndarray          # (B, 3)
    J0: np.ndarray          # (B, 3, 3)
    K: np.ndarray           # (B, 3, 3)
    kb: np.ndarray          # (B,) bending stiffness (N·m/rad): K = k_b(1 − aaᵀ) + k_t·aaᵀ
    kt: np.ndarray          # (B,) twisting stiffness
    dk: np.ndarray          # (B,) damping per unit of stiffness (s): D = dk·K
    cda: np.ndarray         # (B,) ½ρC_d·d·ℓ of the segment across the flow
    diameter: np.ndarray    # (B,) at the joint
    # leaves
    leaf_obj: np.ndarray    # (L,)
    leaf_body: np.ndarray   # (L,) the twig body
    leaf_on: np.ndarray     # (L,) bool
    leaf_base0: np.ndarray  # (L, 3) rest petiole base − twig joint
    leaf_rc0: np.ndarray    # (L, 3) rest lamina centroid − petiole base
    leaf_n0: np.ndarray     # (L, 3) rest lamina normal
    leaf_E: np.ndarray      # (L, 3, 3) axes a, b1, b2
    leaf_k: np.ndarray      # (L, 3)
    leaf_J: np.ndarray      # (L, 3)
    leaf_d: np.ndarray      # (L, 3)
    leaf_cna: np.ndarray    # (L,) ½ρC_nA in the wind
    leaf_cswing: np.ndarray  # (L,) ½ρC_nA against the lamina's own swing
    leaf_roll2: np.ndarray  # (L,) width²/12 of the lamina (its roll's lever²)
    leaf_cauchy: np.ndarray  # (L,) the lamina's scaled Cauchy number per (m/s)² (leafjoint.leaf_step)
    leaf_mass: np.ndarray   # (L,)
    leaf_size: np.ndarray   # (L,) lamina length
    leaf_nodes: np.ndarray  # concatenated node lists of the leaves
    leaf_first: np.ndarray  # (L + 1,) offsets into leaf_nodes
    body_of_obj: np.ndarray  # (M,) the first body of each object (−1: a leaf)
    subtree_mass: np.ndarray  # (B,) everything beyond each joint
    omega_j: np.ndarray     # (B,) each joint's lowest swing with everything beyond it flexible (rad/s)
    omega_t: np.ndarray     # (B,) and its twisting one
    # what rides rigidly on a body beyond itself at a coarser level of detail (physics/lod.py):
    # its drag, isotropic c(s)·s·u at one point, c(s) = lump_cd + lump_cl/∛(1 + lump_cauchy·s²)
    lump_cd: np.ndarray     # (B,) the rigid segments' (N·s²/m²)
    lump_cl: np.ndarray     # (B,) the rigid leaves'
    lump_cauchy: np.ndarray  # (B,) the rigid leaves' mean scaled Cauchy number per (m/s)²
    lump_x0: np.ndarray     # (B, 3) the point it acts at (rest axes, from the body's joint)

    @cached_property
    def leaf_geometry(self) -> np.ndarray:
        """(15, L) ``leaf_E`` (row by row), ``leaf_rc0`` and ``leaf_n0`` a row per component,
        contiguous over the leaves, for the compiled pass that turns them all as vectors
        (:func:`~treeanim.physics.leafjoint.leaf_step`)."""
        L = len(self.leaf_body)
        return np.ascontiguousarray(np.concatenate([self.leaf_E.reshape(L, 9), self.leaf_rc0, self.leaf_n0], axis=1).T)

    @classmethod
    def build(cls, tree, physics, present: np.ndarray) -> "Structure":
        """The structure of ``tree`` with ``physics`` (PhysicsParams) and the leaves ``present`` (M,) bool."""
        p = physics
        X = np.asarray(tree.rest_positions, float)
        dia = np.asarray(tree.node_diameter, float)
        start = np.asarray(tree.object_start, np.int64)
        count = np.asarray(tree.object_count, np.int64)
        kind = np.asarray(tree.kind)
        M = len(start)
        solid = kind != "leaf"
        objs = np.flatnonzero(solid)
        nseg = count[objs] - 1
        first_body = np.zeros(M, np.int64) - 1
        first_body[objs] = np.concatenate([[0], np.cumsum(nseg)[:-1]]) if len(objs) else []
        B = int(nseg.sum())
        obj = np.repeat(objs, nseg)
        k_in = np.arange(B) - np.repeat(first_body[objs], nseg)  # segment index within its object
        node = start[obj] + k_in
        parent = np.where(k_in > 0, np.arange(B) - 1, -1)
        first = k_in == 0
        po = np.asarray(tree.parent)[obj]
        has_par = first & (po >= 0)
        if np.any(has_par & ~solid[np.maximum(po, 0)]):
            raise ValueError("a branch cannot grow on a leaf")
        att = np.asarray(tree.attach_node)[obj]
        ka = np.minimum(att - start[np.maximum(po, 0)], count[np.maximum(po, 0)] - 2)
        parent = np.where(has_par, first_body[np.maximum(po, 0)] + ka, parent)
        X0, X1 = X[node], X[node + 1]
        seg = X1 - X0
        length = np.linalg.norm(seg, axis=1)
        axis = unit(seg)
        r0 = X0 - np.where(parent[:, None] >= 0, X[node[np.maximum(parent, 0)]], 0.0)
        d0, d1 = dia[node], dia[node + 1]
        is_blade = kind[obj] == "blade"
        # mass and inertia of each segment (a frustum; a blade: a strip of lamina)
        dm = 0.5 * (d0 + d1)
        vol = np.pi / 12.0 * length * (d0 * d0 + d0 * d1 + d1 * d1)
        mass = np.where(is_blade, p.leaf_density * p.lamina_thickness * dm * length, p.wood_density * vol)
        mid0 = 0.5 * seg
        rad2 = 0.25 * dm * dm
        i_ax = 0.5 * mass * rad2
        i_perp = mass * (0.25 * rad2 + length**2 / 12.0)
        aa = axis[:, :, None] * axis[:, None, :]
        Icom = i_perp[:, None, None] * (np.eye(3) - aa) + i_ax[:, None, None] * aa
        h_s, J_s = _point_moments(mass, mid0)
        J_s = J_s + Icom
        # stiffness from beam theory
        E = np.where(is_blade, p.blade_youngs_modulus, p.wood_youngs_modulus)
        # ℓ/∫dx/d⁴ over the linear taper = 3d₀³d₁³/(d₀² + d₀d₁ + d₁²)
        d4 = 3.0 * d0**3 * d1**3 / np.maximum(d0 * d0 + d0 * d1 + d1 * d1, 1e-300)
        d4 = np.maximum(d4, 1e-24)
        EI = E * np.pi * d4 / 64.0
        beyond = np.zeros(B)
        # the object's length from each joint to its tip (reverse cumulative within the object)
        cum = np.cumsum(length)
        obj_end = np.repeat(cum[first_body[objs] + nseg - 1], nseg)
        beyond = obj_end - (cum - length)
        x = np.clip(length / np.maximum(beyond, 1e-12), 1e-9, 1.0)
        g = (1.0 - (1.0 - x) ** 3) / (3.0 * x)
        kb = EI / (length * g)
        kt = EI / ((1.0 + POISSON) * length)
        K = kb[:, None, None] * (np.eye(3) - aa) + kt[:, None, None] * aa
        # drag across the flow
        cd = np.where(is_blade, p.drag_blade, p.drag_branch)
        cda = 0.5 * p.air_density * cd * dm * length

        # leaves
        leaves = np.flatnonzero(kind == "leaf")
        L = len(leaves)
        lp = start[leaves]
        lbody_obj = np.asarray(tree.parent)[leaves]
        latt = np.asarray(tree.attach_node)[leaves]
        lka = np.minimum(latt - start[lbody_obj], count[lbody_obj] - 2) if L else np.zeros(0, np.int64)
        leaf_body = first_body[lbody_obj] + lka if L else np.zeros(0, np.int64)
        on = np.asarray(present, bool)[leaves]
        if L and tree.lamina is not None:
            cx, cy = polygon_centroid(tree.lamina.outline)
            Llam = np.asarray(tree.lamina_length, float)[leaves]
            tipn, lu, lv, lw = lamina_frames(tree, leaves)
            centroid = X[tipn] + Llam[:, None] * (cx * lu + cy * lv)
            area = float(tree.lamina.area) * Llam**2
            ox = tree.lamina.outline[:, 0]
            width = Llam * float(ox.max() - ox.min())
        else:
            tipn = start[leaves] + count[leaves] - 1
            centroid = X[tipn]
            lw = np.tile([0.0, 0.0, 1.0], (L, 1))
            area = np.zeros(L)
            width = np.zeros(L)
            Llam = np.zeros(L)
        # petiole: length, mean diameter
        seglen = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(X, axis=0), axis=1))]
        lt = start[leaves] + count[leaves] - 1
        pet_len = seglen[lt] - seglen[lp]
        cd_ = np.r_[0.0, np.cumsum(dia)]
        pet_d = (cd_[lt + 1] - cd_[lp]) / np.maximum(count[leaves], 1)
        lam_mass = p.leaf_density * p.lamina_thickness * area
        pet_mass = p.leaf_density * np.pi / 4 * pet_d**2 * pet_len
        leaf_mass = lam_mass + pet_mass
        base0 = X[lp] - X[node[leaf_body]] if L else np.zeros((0, 3))
        rc0 = centroid - X[lp]
        lever = np.maximum(np.linalg.norm(rc0, axis=1), 1e-6)
        a = rc0 / lever[:, None]
        n0 = lw
        b1 = unit(n0 - np.sum(n0 * a, axis=1, keepdims=True) * a) if L else np.zeros((0, 3))
        b2 = np.cross(a, b1)
        Eax = np.stack([a, b1, b2], axis=2)  # columns
        EIp = p.leaf_youngs_modulus * np.pi * pet_d**4 / 64.0
        ell = np.maximum(pet_len, 1e-4)
        kbl = EIp * lever / (ell * np.maximum(lever - 0.5 * ell, 0.5 * lever))
        ktl = kbl * ell / (lever * PETIOLE_BEND_TWIST)
        Jb = lam_mass * (lever**2 + Llam**2 / 12.0) + pet_mass * ell**2 / 3.0
        Ja = lam_mass * width**2 / 12.0 + 1e-12
        # each leaf stands for a cluster of n real ones (physics.leaf_area_index): n times the
        # mass, drag, stiffness and inertia, so it turns as one leaf does and loads its twig as n
        # (of each placed tree's own crown in a scene)
        n = leaf_clusters(tree, X, leaves, area, p.leaf_area_index)
        leaf_mass = leaf_mass * n
        leaf_k = n[:, None] * np.stack([ktl, kbl, kbl], axis=1)
        leaf_J = n[:, None] * np.stack([Ja, Jb, Jb], axis=1)
        leaf_d = 2.0 * p.wood_damping * np.sqrt(leaf_k * leaf_J)
        cna = 0.5 * p.air_density * p.drag_leaf * area * n
        cswing = 0.5 * p.air_density * PLATE_NORMAL_DRAG * area * n
        # the lamina folds and rolls in the flow (Gosselin et al. 2010): its scaled Cauchy number
        # C_n·ρU²ℓ³/(2D) per U², D = Et³/(12(1 − ν²)) its flexural rigidity (veins and all)
        D = p.leaf_youngs_modulus * p.lamina_thickness**3 / (12.0 * (1.0 - POISSON**2))
        cauchy = p.drag_leaf * p.air_density * Llam**3 / (2.0 * D)
        # present leaves ride their twigs rigidly: their mass at their centroid
        m0, h0, J0 = mass.copy(), h_s, J_s
        if L:
            lm = leaf_mass * on
            rl = centroid - X[node[leaf_body]]
            hl, Jl = _point_moments(lm, rl)
            m0 = m0 + np.bincount(leaf_body, lm, minlength=B)
            for c in range(3):
                h0[:, c] += np.bincount(leaf_body, hl[:, c], minlength=B)
                for d in range(3):
                    J0[:, c, d] += np.bincount(leaf_body, Jl[:, c, d], minlength=B)
        # damping: each joint at ζ of its own frequency with all it carries
        sm, sh, sJ = np.empty(B), np.empty((B, 3)), np.empty((B, 3, 3))
        _subtree_inertia(parent, np.ascontiguousarray(r0), m0, np.ascontiguousarray(h0),
                         np.ascontiguousarray(J0), sm, sh, sJ)
        Jperp = 0.5 * (np.trace(sJ, axis1=1, axis2=2) - np.einsum("bi,bij,bj->b", axis, sJ, axis))
        omega_j = np.sqrt(kb / np.maximum(Jperp, 1e-30))
        # the wood damps each joint at ζ in the lowest swing of everything beyond it, flexible,
        kids = np.flatnonzero(parent >= 0)
        children = np.ascontiguousarray(kids[np.argsort(parent[kids], kind="stable")], np.int64)
        child_start = np.r_[0, np.cumsum(np.bincount(parent[kids], minlength=B))].astype(np.int64)
        com = X0 + h0 / np.maximum(m0, 1e-30)[:, None]
        omega_flex = np.empty(B)
        _flexible_frequency(np.asarray(parent, np.int64), child_start, children, np.ascontiguousarray(X0),
                            np.ascontiguousarray(com), m0, np.ascontiguousarray(sh), np.maximum(kb, 1e-30),
                            np.ascontiguousarray(axis), omega_flex)
        omega_flex = np.where(np.isfinite(omega_flex), np.minimum(omega_flex, omega_j), omega_j)
        # a twist's θ follows its fastest swing, the segment's own about its axis (a thin
        # segment's is thousands of times its subtree's); twist is never the motion one sees
        omega_t = np.sqrt(kt / np.maximum(np.einsum("bi,bij,bj->b", axis, J0, axis), 1e-30))
        # ... of its branch: a branch sways mostly as a whole, in its base joint's swing
        dk = 2.0 * p.wood_damping / omega_flex[first_body[obj]]
        leaf_first = np.r_[0, np.cumsum(count[leaves])].astype(np.int64)
        leaf_nodes = np.arange(leaf_first[-1]) - np.repeat(leaf_first[:-1] - lp, count[leaves])
        c = np.ascontiguousarray
        return cls(parent=c(parent, np.int64), r0=c(r0), node=c(node, np.int64), tip=c(k_in == count[obj] - 2),
                   tip_node=c(node + 1, np.int64), obj=obj, axis=c(axis), length=length, mid0=c(mid0),
                   seg0=c(seg), floor=c(np.minimum(0.5 * d1, X1[:, 1])),
                   m0=c(m0), h0=c(h0), J0=c(J0), K=c(K), kb=c(kb), kt=c(kt), dk=c(dk), cda=c(cda), diameter=d0,
                   leaf_obj=leaves, leaf_body=c(leaf_body, np.int64), leaf_on=c(on),
                   leaf_base0=c(base0),
                   leaf_rc0=c(rc0), leaf_n0=c(n0), leaf_E=c(Eax), leaf_k=c(leaf_k), leaf_J=c(leaf_J),
                   leaf_d=c(leaf_d), leaf_cna=c(cna), leaf_cswing=c(cswing),
                   leaf_roll2=c(width**2 / 12.0), leaf_cauchy=c(cauchy), leaf_mass=c(leaf_mass), leaf_size=c(Llam, float),
                   leaf_nodes=c(leaf_nodes, np.int64), leaf_first=leaf_first, body_of_obj=first_body,
                   subtree_mass=sm, omega_j=omega_flex, omega_t=omega_t,
                   lump_cd=np.zeros(B), lump_cl=np.zeros(B), lump_cauchy=np.zeros(B), lump_x0=np.zeros((B, 3)))
