"""The load path (docs/design.md §12): every object carries the loads of everything that grows on it.

In the paper each object feels only the wind on its own area (Eq. 19), so the crown's drag
never reaches the trunk. Here:

* an object's load is its own drag plus the force and moment each child transmits at its
  attach node: one pass up the tree, level by level from the outermost in, sums each level's
  subtrees into their attach slots and parents and solves the oscillators' coupling on the
  way (whole-level array operations);
* each object's three oscillators (Eqs. 2–5) filter its **total** load: modes u and w the
  equivalent force at the object's load point, E = (base moment) / lever, mode v the torsion
  about v. A child transmits its elastic reaction — its static load plus the dynamic excess
  of its oscillators, E′ − E, at its load point — so the trunk sways at its own f and ζ under
  the crown's gusts, and a swinging limb shakes its parent;
* a load at node j bends segments 0 … j−1 only (Eq. 7 generalised): joint i turns under the
  moment of everything beyond it, solved by Eq. 8 for the equivalent force at the lever ℓᵢ
  from the joint to the object's load point;
* joint stiffness kᵢ = ℓᵢ² / ∫_seg ℓ(x)²/EI(x) dx with EI = E π D⁴/64 (Eq. 10's D⁴ with a
  physical modulus), so a chain of hinges deflects at its load point as the continuous tapered
  cantilever does, however many segments the object has;
* base excitation: each object's base moves with its parent's modal acceleration (the
  translation and rotation at the attach node, from the parent's oscillator state at the start
  of the step — no finite differences, no lag), and the object feels −m_eff·a with the
  effective mass m_eff = K/(2πf)² of its own mode (K its stiffness at the load point).

Loads travel down the tree in rest-world coordinates — the frame in which every object's rest
frame is constant — as forces and first moments about the origin (S = X × F), so a child's
load reaches its parent by a plain sum; the oscillators' inputs and the bending take them in
each object's own rest frame (u, v, w), called *local*. Levers are rest offsets, so the
geometric non-linearity stays in Eq. 8, as in the paper.
"""

from __future__ import annotations

import numpy as np
from scipy import sparse

from .bend_angle import saturating_twist
from .rotation import Workspace, cross, dot

__all__ = ["LoadPath", "TWIST_RATIO"]

#: EI/GJ of wood and of petioles and blades: they twist this many times more readily than a
#: beam of equal bending and torsional stiffness (green wood's shear modulus is ~E/16; petioles
#: have twist-to-bend ratios of 2–10, Vogel 1992).
TWIST_RATIO = 8.0
#: Simpson's rule on four sub-intervals: the points along a segment and their weights.
_T = np.linspace(0.0, 1.0, 5)
_W = np.array([1.0, 4.0, 2.0, 4.0, 1.0]) / 12.0


def _csr(rows: list, cols: list, vals: list, shape: tuple[int, int]):
    """A CSR matrix from lists of (row indices, column indices, values) blocks."""
    return sparse.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=shape)


class LoadPath:
    """Index arrays, levers and stiffnesses of the load path, and its per-step stages.

    Parameters
    ----------
    tree : Tree
    frames : (M, 3, 3) float
        Rest frames, columns (u, v, w) (:func:`treeanim.physics.bending.rest_frames`).
    bplan : BendingPlan
        For the flat segment order of the bending pass.
    load_point : (M, 3) float
        Where each object's own load acts, world rest: the lamina's centroid for a leaf,
        the tip for branches and blades.
    """

    def __init__(self, tree, frames: np.ndarray, bplan, load_point: np.ndarray):
        X = np.asarray(tree.rest_positions, float)
        start, count = np.asarray(tree.object_start), np.asarray(tree.object_count)
        parent, attach = np.asarray(tree.parent), np.asarray(tree.attach_node)
        self.M, self.N = M, N = len(start), len(X)
        R0 = np.asarray(frames, float)
        self.axes = np.ascontiguousarray(R0.transpose(2, 1, 0))  # axes[c] = (3, M) rest u, v, w
        Xb = X[start]

        def local(obj, pts):  # world rest points → local offsets from the object's base
            return np.einsum("kji,kj->ik", R0[obj], pts - Xb[obj])

        self.Xb = np.ascontiguousarray(Xb.T)
        self.Xl = np.ascontiguousarray(np.asarray(load_point, float).T)
        self.x_load = local(np.arange(M), self.Xl.T)
        # Flat segments in the bending pass's order (block i: segment i of the objects having one).
        seg_obj, seg_i = bplan.seg_obj, bplan.seg_index
        node = start[seg_obj] + seg_i
        hinged = bplan.hinge[seg_obj]
        self.hinge_first = np.flatnonzero(hinged & (seg_i == 0))
        self.hinge_rest = np.flatnonzero(hinged & (seg_i > 0))
        xj = local(seg_obj, X[node])
        s = local(seg_obj, X[node + 1]) - xj
        h = np.linalg.norm(s, axis=0)
        lever_vec = self.x_load[:, seg_obj] - xj  # joint → load point
        lever = np.maximum(np.linalg.norm(lever_vec, axis=0), 1e-12)
        self.lever0 = np.maximum(np.linalg.norm(self.x_load, axis=0), 1e-12)
        diam = np.asarray(tree.node_diameter, float)
        # Every segment's geometry, for the stiffness (:meth:`derive`).
        self.geo = (seg_obj, node, s, h, lever_vec, lever, diam[node], diam[node + 1])

        # Own load beyond joint i: a fraction W of it, with first moment A × F about the joint.
        # Branches and blades spread it over their segments by frontal area; a leaf's acts on
        # its lamina, beyond every joint of the petiole.
        area = 0.5 * (diam[node] + diam[node + 1]) * h
        w = area / np.maximum(np.bincount(seg_obj, area, M)[seg_obj], 1e-300)
        W = self._suffix(w[None], node, start, count)[0]
        A = self._suffix(w * (xj + 0.5 * s), node, start, count) - W * xj
        leafseg = tree.kind[seg_obj] == "leaf"
        W[leafseg] = 1.0
        A[:, leafseg] = lever_vec[:, leafseg]
        A0 = np.empty((3, M))
        A0[:, bplan.order] = A[:, :M]  # block 0 holds segment 0 of every object
        self.Xo = self.Xb + self._to_world(A0)  # where the own load's moment acts
        self.own_arm = np.linalg.norm(A, axis=0)  # the own load's lever about each joint

        # Per step only the joints Eq. 8 solves: a hinge object's later joints follow its first.
        self.keep = keep = np.flatnonzero(~hinged | (seg_i == 0))
        seg_obj, node, s, h, lever_vec, lever, W, A, leafseg = (
            x[..., keep] for x in (seg_obj, node, s, h, lever_vec, lever, W, A, leafseg))
        S = len(seg_obj)
        ends = np.cumsum([0] + bplan.solved)
        self.blocks = list(zip(ends[:-1], ends[1:]))
        self.seg_obj = seg_obj
        s_hat = s / np.maximum(h, 1e-300)
        self.lever = lever
        self.lever_per_len = lever / np.maximum(h, 1e-300)  # a·sin θ₀ = |N|·ℓ/|s|
        self.s_hat = s_hat
        self.leaf_seg = np.flatnonzero(leafseg)
        own = (seg_obj, s_hat, lever, lever_vec, W, A, leafseg)

        # Children and the nodes they sit on.
        nonroot = np.flatnonzero(parent >= 0)
        self.nonroot, self.par = nonroot, parent[nonroot]
        att_nodes, slot = np.unique(attach[nonroot], return_inverse=True)
        self.att_nodes = att_nodes
        has_kids = np.zeros(M, bool)
        has_kids[self.par] = True
        owner = np.searchsorted(start, att_nodes, side="right") - 1  # the object of each slot
        self.slot = slot  # each non-root object's attach slot
        self.levels = []
        for sl in tree.level_slices():
            lo, hi = np.searchsorted(nonroot, [sl.start, sl.stop])
            if hi - lo not in (0, sl.stop - sl.start):
                raise ValueError("a hierarchy level mixes roots and children")  # never built so
            self.levels.append((sl, hi > lo))
        self.slot_owner = owner
        self.Xslot = np.ascontiguousarray(X[att_nodes].T)
        self.r_load = self.Xl - self.Xb
        # Segments of objects with children: what the children put beyond each joint.
        k_flat = np.flatnonzero(has_kids[seg_obj])
        ko = seg_obj[k_flat]
        hi = np.maximum(np.searchsorted(att_nodes, node[k_flat], side="right"),
                        np.searchsorted(owner, ko))  # the object's slots after the joint
        end = np.searchsorted(owner, ko, side="right")
        self.seg_map = self._segment_map(*own, self._children(k_flat, hi, end, X[node[k_flat]].T, S, len(att_nodes)))
        self.start = start
        self.diam_max = float(diam.max()) if N else 1.0
        self.kind = tree.kind
        self.ws = Workspace()
        self._couplings(parent, has_kids)

    def _segment_map(self, seg_obj, s_hat, lever, lever_vec, W, A, leafseg, children):
        """(4S, 8M + 6A) sparse: the solved joints' equivalent forces (rows c·S + joint, local)
        and torsions (rows 3S + joint) per unit load, as :meth:`segment_forces` stacks them:
        own loads (columns c·M + object), load-point loads (3M + c·M + object), the
        torsional excess (6M + object), L′_v (7M + object) and the children (8M + …).

        Joint i's equivalent force of Eq. 8 at the lever ℓ, (F·ŝ)ŝ + (M × ŝ)/ℓ, is linear in
        the loads at their rest levers: for the own load, share W with first moment A × F
        about the joint, F·α + (F·ŝ)·dA with α = A·ŝ/ℓ, dA = W·ŝ − A/ℓ; for a load at the
        load point (lever vector B: W = 1, A = B) the same. Its torsion is (A × F)·ŝ; a
        leaf's petiole twists under L′_v alone (see :meth:`segment_forces`)."""
        M, S = self.M, len(seg_obj)
        seg = np.arange(S)
        rows, cols, vals = children
        for block, (arm, share) in enumerate(((A, W), (lever_vec, 1.0))):  # own, load point
            alpha = dot(arm, s_hat) / lever
            dA = share * s_hat - arm / lever
            for c in range(3):
                for c2 in range(3):
                    rows.append(c * S + seg), cols.append((3 * block + c2) * M + seg_obj)
                    vals.append(dA[c] * s_hat[c2] + (alpha if c == c2 else 0.0))
            twist = cross(s_hat, arm)  # (A × F)·ŝ = F·(ŝ × A)
            for c2 in range(3):
                rows.append(3 * S + seg[~leafseg]), cols.append((3 * block + c2) * M + seg_obj[~leafseg])
                vals.append(twist[c2, ~leafseg])
        for col, segs in ((6, ~leafseg), (7, leafseg)):  # torsional excess, L′_v
            rows.append(3 * S + seg[segs]), cols.append(col * M + seg_obj[segs]), vals.append(np.ones(segs.sum()))
        m = _csr(rows, cols, vals, (4 * S, 8 * M + 6 * len(self.att_nodes)))
        m.eliminate_zeros()
        return m

    def _children(self, k_flat, hi, end, Xj, S: int, A: int) -> tuple[list, list, list]:
        """Rows, columns and values of :meth:`_segment_map` for the children at the attach
        slots ``hi … end−1`` beyond each joint ``k_flat``, per rest-world force and first
        moment of each slot (column 8M + d·A + slot).

        Mᵢ = S − Xⱼ × F about the joint, local; Fᵢ = (F·ŝ)ŝ + (Mᵢ × ŝ)/ℓᵢ (Eq. 8's equivalent
        force) and Tᵢ = Mᵢ·ŝ, linear in the slot's (F, S): built on the six unit loads."""
        u, v, w = (a[:, self.seg_obj[k_flat]] for a in self.axes)
        sh, lev = self.s_hat[:, k_flat], self.lever[k_flat]
        G = np.empty((4, 6, len(k_flat)))
        for d in range(6):
            unit = np.zeros((6, 1))
            unit[d] = 1.0
            F = np.broadcast_to(unit[:3], Xj.shape)
            Mi = unit[3:] - cross(Xj, F)
            Fl = np.stack([dot(u, F), dot(v, F), dot(w, F)])
            Ml = np.stack([dot(u, Mi), dot(v, Mi), dot(w, Mi)])
            G[:3, d] = dot(Fl, sh) * sh + cross(Ml, sh) / lev
            G[3, d] = dot(Ml, sh)
        n = end - hi  # slots beyond each joint
        seg = np.repeat(np.arange(len(k_flat)), n)
        slot = np.arange(n.sum()) - np.repeat(np.cumsum(n) - n, n) + np.repeat(hi, n)
        rows, cols, vals = [], [], []
        for r in range(4):
            for d in range(6):
                rows.append(r * S + k_flat[seg]), cols.append(8 * self.M + d * A + slot), vals.append(G[r, d, seg])
        return rows, cols, vals

    def _couplings(self, parent: np.ndarray, has_kids: np.ndarray) -> None:
        """The tree's constant maps for the upward pass of :meth:`inward` and for :meth:`_base_map`.

        * ``pairs``: (descendant, ancestor, the ancestor's child on the way) of every
          (ancestor, descendant) pair;
        * ``own_map`` (6, 3, M): an object's local load → rest-world force and first moment;
        * per level, outermost first (``up``): ``Pe`` (3, 6, n), the equivalent loads
          (E_w, T, E_u) of a subtree's force and first moment about the object's base;
          ``Q`` (6, 3, n), the force and first moment of the dynamic excess x (rows u, v, w of
          the modes); and how the level's subtrees add up into attach slots and parents.
        """
        M = self.M
        k, j, c = [], [], []  # descendant, its ancestor, the ancestor's child on the way
        cur = np.flatnonzero(parent >= 0)
        desc, via = cur, cur
        while len(desc):
            anc = parent[via]
            k.append(desc), j.append(anc), c.append(via)
            up = parent[anc] >= 0
            desc, via = desc[up], anc[up]
        self.pairs = tuple(np.concatenate(a) if a else np.zeros(0, int) for a in (k, j, c))
        u, v, w = self.axes
        self.own_map = np.stack([np.concatenate([a, cross(self.Xo, a)]) for a in (u, v, w)], axis=1)
        # E = a·S − (a × X_b)·F for a = u/ℓ, v, −w/ℓ (the moment about the base, S − X_b × F)
        a = (u / self.lever0, v, -w / self.lever0)
        Pe = np.stack([np.concatenate([-cross(ac, self.Xb), ac]) for ac in a])
        # The excess x moves the load point by u x₂ + w x₀ and twists it by v x₁.
        zero = np.zeros((3, M))
        Q = np.stack([np.concatenate([w, cross(self.Xl, w)]), np.concatenate([zero, v]),
                      np.concatenate([u, cross(self.Xl, u)])], axis=1)
        self.up = []
        for sl, transmits in reversed(self.levels):
            lvl = {"sl": sl, "Pe": np.ascontiguousarray(Pe[:, :, sl]), "Q": np.ascontiguousarray(Q[:, :, sl])}
            if transmits:  # the level's subtrees → their attach slots (contiguous) → parents
                slot = self.slot[np.searchsorted(self.nonroot, np.arange(sl.start, sl.stop))]
                perm = np.argsort(slot, kind="stable")
                s = slot[perm]
                first = np.flatnonzero(np.r_[True, s[1:] != s[:-1]])
                lo, hi = int(s[0]), int(s[-1]) + 1
                owner = self.slot_owner[lo:hi]
                ofirst = np.flatnonzero(np.r_[True, owner[1:] != owner[:-1]])
                lvl.update(perm=None if np.all(perm == np.arange(len(perm))) else perm, first=first,
                           slots=slice(lo, hi), owners=owner[ofirst], ofirst=ofirst)
            self.up.append(lvl)

    def _to_world(self, x: np.ndarray, objs=slice(None)) -> np.ndarray:
        """Local (3, K) vectors of objects ``objs`` in rest-world coordinates."""
        u, v, w = self.axes[0][:, objs], self.axes[1][:, objs], self.axes[2][:, objs]
        return u * x[0] + v * x[1] + w * x[2]

    @staticmethod
    def _suffix(v: np.ndarray, node: np.ndarray, start: np.ndarray, count: np.ndarray) -> np.ndarray:
        """Per segment, the sum of ``v`` over it and the segments after it in its object.

        ``v`` is (k, S) in flat order; ``node`` the segments' joint nodes."""
        N = int(start[-1] + count[-1]) if len(start) else 0
        by_node = np.zeros((v.shape[0], N + 1))
        by_node[:, node] = v
        rc = np.cumsum(by_node[:, ::-1], axis=1)[:, ::-1]  # rc[:, a] = Σ_{b >= a}
        tip_next = np.repeat(start + count, count)[node]  # first node after the object
        return rc[:, node] - rc[:, np.minimum(tip_next, N)]

    # ------------------------------------------------------------------ stiffness
    def derive(self, E: np.ndarray, exponent: float, air: np.ndarray, foliage: np.ndarray,
               mass: np.ndarray, leafy_mass: np.ndarray, modal: np.ndarray) -> None:
        """Stiffness shapes, the modal masses and the air's damping participation.

        Parameters
        ----------
        E : (M,) float
            Young's modulus of each object (Pa); for the ``modal`` objects only its shape along
            the object matters (:meth:`tune` scales their stiffness).
        exponent : float
            m of Eq. 10: EI = E π D_max⁴/64 · (D/D_max)^m (4: a solid round section).
        air : (M,) float
            ½ρ C A of every object (N·s²/m², zero where absent).
        foliage : (M,) bool
            Whose drag reconfigures (leaves, blades).
        mass : (M,) float
            Each object's own mass (kg, zero where absent): what the modes carry.
        leafy_mass : (M,) float
            The same with every leaf on, which sets the stiffness (:meth:`tune`).
        modal : (M,) bool
            Objects whose stiffness :meth:`tune` sets from their modal frequency and mass.
        """
        so, node, seg_vec, h, lever_vec, lever, d0, d1 = self.geo
        Es = E[so]
        ei0 = np.pi / 64.0 * self.diam_max**4

        def EI(t):
            d = d0 + t * (d1 - d0)
            return Es * ei0 * np.maximum(d / self.diam_max, 1e-12) ** exponent

        integral = np.zeros_like(h)
        for t, wt in zip(_T, _W):  # ∫_seg ℓ(x)² / EI(x) dx, Simpson
            r = lever_vec - t * seg_vec
            integral += wt * np.einsum("ij,ij->j", r, r) / EI(t)
        integral *= h
        k_E = lever**2 / np.maximum(integral, 1e-300)
        self.K_E = 1.0 / np.maximum(np.bincount(so, integral, self.M), 1e-300)  # at the load point
        # Each joint twists under the torsion it carries, by c = ∫dx/GJ over its segment
        # (GJ = EI/TWIST_RATIO); Eq. 11's law saturates it at a quarter turn, rate (2/π)c.
        twist_rate = (2.0 / np.pi) * h * TWIST_RATIO / EI(0.5)
        self._hinges(so, k_E, twist_rate)
        self.modal = np.asarray(modal, bool)
        # Where a child's base sits on its parent's deflection: translation ψ and rotation χ per
        # unit deflection of the parent's load point (φᵢ = ℓᵢ/kᵢ per newton there).
        phi = integral / lever
        N = self.N
        c1 = np.zeros(N + 1)
        c2 = np.zeros(N + 1)
        arc = np.zeros(N + 1)
        arc[node + 1] = h
        arc = np.cumsum(arc)  # arc length, with jumps between objects that cancel below
        c1[node + 1] = phi
        c2[node + 1] = phi * arc[node]
        c1, c2 = np.cumsum(c1), np.cumsum(c2)
        a = self.att_nodes
        s0 = self.start[self.slot_owner]
        p1 = c1[a] - c1[s0]
        p2 = c2[a] - c2[s0]
        Kp = self.K_E[self.slot_owner]
        self.psi = Kp * (arc[a] * p1 - p2)  # per attach slot
        self.chi = Kp * p1
        # The air's damping and the mass on each object's mode: its own (a leaf's at its load
        # point, a branch's spread along it, ~1/4 participation) plus its children's subtrees
        # at ψ², the square of the share of the mode's deflection their bases move by.
        share = np.where(self.kind == "leaf", 1.0, 0.25)
        own = air * share
        Qw, Qf = np.where(foliage, 0.0, own), np.where(foliage, own, 0.0)
        sub_w, sub_f = np.where(foliage, 0.0, air), np.where(foliage, air, 0.0)
        m_modal, sub_m = mass * share, np.array(mass, float)
        m_leafy, sub_leafy = leafy_mass * share, np.array(leafy_mass, float)
        for sl, transmits, *_ in reversed(self.levels):
            if not transmits:
                continue
            kids = np.arange(sl.start, sl.stop)
            j = np.searchsorted(self.nonroot, kids)
            par = self.par[j]
            psi2 = self.psi[self.slot[j]] ** 2
            for acc, sub in ((Qw, sub_w), (Qf, sub_f), (m_modal, sub_m), (m_leafy, sub_leafy)):
                np.add.at(acc, par, psi2 * sub[kids])
                np.add.at(sub, par, sub[kids])
        self.Q_wood, self.Q_foliage = Qw, Qf
        self.m_modal, self.m_leafy = m_modal, m_leafy
        self._base_map()
        self.tune(None)

    def _hinges(self, so, k_E, twist_rate) -> None:
        """The solved joints' stiffness ``k_E`` and twist rate, and ``hinge_gain``.

        A hinge object (a leaf's petiole, a grass blade) is solved at its first joint only, as
        in the chain of hinges (Eq. 8 with that joint's k₀), and twists there by the sum of its
        joints' twist rates. Joint i of the chain turns by Mᵢ/kᵢ under the object's own load,
        whose moment about it is Mᵢ ∝ aᵢ (``own_arm``: the lamina's lever for a leaf, the first
        moment of the drag along a blade): the later joints turn by the fixed multiples
        cᵢ = (aᵢ/a₀)·(k₀/kᵢ) of the first joint's angle, as in the chain in small bends.
        ``hinge_gain`` holds cᵢ for every flat segment (1 where not hinged)."""
        first, rest = self.hinge_first, self.hinge_rest
        hinged = np.concatenate([first, rest])
        a0k0 = np.ones(self.M)  # a₀/k₀ of every hinge object
        a0k0[so[first]] = self.own_arm[first] / np.maximum(k_E[first], 1e-300)
        self.hinge_gain = np.ones(len(so))
        self.hinge_gain[rest] = self.own_arm[rest] / np.maximum(k_E[rest], 1e-300) / np.maximum(a0k0[so[rest]], 1e-300)
        twist_rate[first] = np.bincount(so[hinged], twist_rate[hinged], self.M)[so[first]]
        self.k_E, self.twist_rate = k_E[self.keep], twist_rate[self.keep]

    def _base_map(self) -> None:
        """``B`` (2M, 2M): the local (u, w) acceleration of each object's load point per unit
        deflection acceleration (along u, along w) of each of its ancestors' load points.

        An ancestor j moves the base of its child c on the way by ψ (translation) and turns it
        by χ v_j × δ̈ (rotation); the rotation carries every load point k beyond it round by
        the rigid chain of levers from c to k (rest offsets, as the loads)."""
        M = self.M
        k, j, c = self.pairs
        s = self.slot[np.searchsorted(self.nonroot, c)]
        V = np.zeros((3, M))  # each base reached along its chain of levers from its root
        for row in range(3):
            np.add.at(V[row], k, self.Xslot[row, s] - self.Xb[row, j])
        R = V[:, k] + self.r_load[:, k] - V[:, c]
        u, v, w = self.axes
        rows, cols, vals = [], [], []
        for col, d in enumerate((u[:, j], w[:, j])):
            t = self.psi[s] * d + self.chi[s] * cross(cross(v[:, j], d), R)
            for row, axis in enumerate((u[:, k], w[:, k])):
                rows.append(row * M + k), cols.append(col * M + j), vals.append(dot(axis, t))
        self.B = _csr(rows, cols, vals, (2 * M, 2 * M))

    def tune(self, w2: np.ndarray | None) -> None:
        """Set the stiffness of the ``modal`` objects from their modes: K = m·ω², with m the
        modal mass (own and carried) with every leaf on and ω² = ω_u·ω_w of the bending modes,
        so a branch's static lean and its sway frequency agree (the Table 1 frequencies stay
        what they are). The wood does not soften as the leaves fall: a bare twig keeps the
        stiffness that carried its leaves (and Table 1's higher winter frequencies stiffen it
        further), where its bare mass would leave it many times softer than in summer.
        Their twist keeps the modulus-based torsional stiffness: wood twists little.

        Parameters
        ----------
        w2 : (3, M) float or None
            (2πf)² of every mode (rows u, v, w); None keeps the modulus-based stiffness.
        """
        scale = np.ones(self.M)
        if w2 is not None:
            target = self.m_leafy * np.sqrt(w2[0] * w2[2])
            scale[self.modal] = target[self.modal] / self.K_E[self.modal]
            scale = np.maximum(scale, 1e-300)
        seg = scale[self.seg_obj]
        self.k = self.k_E * seg
        self.k_blocks = [self.k[a:b] for a, b in self.blocks]
        self.K = self.K_E * scale
        self.B_K = self.B @ sparse.diags(np.tile(1.0 / self.K, 2))  # B per unit p̈ (see base_acceleration)

    # ------------------------------------------------------------------ per step
    def base_acceleration(self, p_acc: np.ndarray) -> np.ndarray:
        """(2, M) local (u, w) acceleration of each object's load point as its base moves.

        Parameters
        ----------
        p_acc : (2, M) float
            d²L′/dt² of the bending oscillators now (rows u, w), from their state at the start
            of the step (no lag): the load point accelerates by (p̈_w, 0, p̈_u)/K, local (mode w
            bends along u, mode u along w), and carries every object growing on it (``B``).
        """
        return (self.B_K @ p_acc[::-1].ravel()).reshape(2, self.M)

    def inward(self, F_own: np.ndarray, F_tip: np.ndarray, held: np.ndarray, g_extra: np.ndarray,
               response: tuple[np.ndarray, np.ndarray], g: np.ndarray) -> np.ndarray:
        """The loads of the whole tree and the oscillators' inputs (Eqs. 2–5 on the load path).

        Each object's input is the equivalent load of its subtree's static loads plus the
        dynamic excess x = L′ − E of every object growing on it. The oscillators respond
        linearly over the step, L′ = p_free + c·g, so the excesses solve
        x = p_free + c·g_extra + (c − 1)·E, with E the equivalent load of the subtree's own
        loads and its descendants' excesses: one pass from the outermost level in, where each
        level's subtrees are whole when it is reached.

        Parameters
        ----------
        F_own : (3, M) float
            Each object's own load (drag), local.
        F_tip : (3, M) float
            Loads at the load points (pulls), local.
        held : (H,) int
            The objects whose ``F_tip`` is not zero.
        g_extra : (3, M) float
            Added to the oscillators' inputs only (base excitation): not transmitted.
        response : ((3, M), (3, M)) float
            The oscillators' free output p_free and gain c over the step (rows u, v, w).
        g : (3, M) float
            Filled with the oscillators' inputs.

        Returns
        -------
        slots : (6, A) float
            What the children transmit at each attach node (``att_nodes``), rest-world:
            force and first moment about the origin.
        """
        ws = self.ws
        Z = np.einsum("dck,ck->dk", self.own_map, F_own, out=ws.get("Z", (6, self.M)))  # F, S = X × F
        if len(held):
            Ft = self._to_world(F_tip[:, held], held)
            Z[:3, held] += Ft
            Z[3:, held] += cross(self.Xl[:, held], Ft)
        p_free, gain = response
        x = np.multiply(gain, g_extra, out=ws.get("x", (3, self.M)))
        x += p_free
        c1 = gain - 1.0
        slots = np.empty((6, len(self.att_nodes)))
        for lvl in self.up:  # outermost first: a level's subtrees are whole when it is reached
            sl = lvl["sl"]
            Zs, xs, E = Z[:, sl], x[:, sl], g[:, sl]
            np.einsum("cdk,dk->ck", lvl["Pe"], Zs, out=E)  # the subtree's equivalent load
            if "first" in lvl:  # (roots transmit nothing)
                xs += c1[:, sl] * E
                Zs += np.einsum("dck,ck->dk", lvl["Q"], xs)
                into = slots[:, lvl["slots"]]
                np.add.reduceat(Zs if lvl["perm"] is None else Zs[:, lvl["perm"]], lvl["first"], axis=1, out=into)
                Z[:, lvl["owners"]] += np.add.reduceat(into, lvl["ofirst"], axis=1)
        g += g_extra
        return slots

    def segment_forces(self, F_own: np.ndarray, F_tip: np.ndarray, dT: np.ndarray, Lv: np.ndarray,
                       slots: np.ndarray) -> tuple[list[tuple], np.ndarray]:
        """Per bending block, the equivalent force on each segment and its moment at the lever;
        per segment, the twist.

        Joint i carries the moment Mᵢ of everything beyond it: its share of the object's own
        load, the loads at the load point ``F_tip`` (pulls and the dynamic excess) and the
        children at nodes after i. Eq. 8 then solves for the equivalent force
        Fᵢ = (F·ŝ)ŝ + (Mᵢ × ŝ)/ℓᵢ at the lever ℓᵢ, whose moment at rest is Mᵢ. The torsion
        Tᵢ = Mᵢ·ŝ (plus the object's dynamic excess ``dT``) twists segment i by Eq. 11's
        saturating law with the segment's own torsional compliance cᵢ:
        γᵢ = ½π·sgn Tᵢ·(1 − exp(−(2/π)·cᵢ|Tᵢ|)), so a small twist is cᵢTᵢ, the largest a
        quarter turn. A leaf's petiole twists under its torsional mode's output ``Lv`` (L′_v)
        alone: the torque of the lamina's normal force turns with the lamina, and taken
        unfiltered it would flip the leaf from side to side every step.

        Returns
        -------
        blocks : list of (fu, fv, fw, a, r)
            For :meth:`BendingPlan.bend`'s ``blocks``.
        gamma : (n_flat,) float
            Twist of every segment, in the bending pass's flat order.
        """
        S = len(self.seg_obj)
        x = np.concatenate([F_own.ravel(), F_tip.ravel(), dT, Lv, slots.ravel()])
        out = (self.seg_map @ x).reshape(4, S)
        Feq, torsion = out[:3], out[3]
        a = np.sqrt(dot(Feq, Feq))
        a *= self.lever
        gamma = saturating_twist(torsion, self.twist_rate, -0.5 * np.pi)
        r = self.lever_per_len
        blocks = [(Feq[0, lo:hi], Feq[1, lo:hi], Feq[2, lo:hi], a[lo:hi], r[lo:hi]) for lo, hi in self.blocks]
        return blocks, gamma
