"""Curved-beam bending (Eqs. 7–11, docs/design.md §5), vectorised across objects.

Every object bends in its own rest frame (world rest coordinates), independently of its
parent's motion; :mod:`treeanim.physics.hierarchy` then carries the result up the tree. For
segment i = 0 … n−1, root to tip:

* Fᵢ = F·(n − i)/n (Eq. 7);
* sᵢ′ = sᵢ turned by all rotations so far (the twist of this segment included);
* θ₀ = ∠(Fᵢ, sᵢ′), and φ ∈ [0, θ₀] solves |Fᵢ||sᵢ| sin(θ₀ − φ) = kᵢ φ (Eqs. 8–9) by
  safeguarded Newton/Halley iterations with a bisection fallback, to |Δφ| < 1e-7 rad;
* kᵢ = EI_max (Dᵢ/D_max)^m, Dᵢ the linear taper from the object's root diameter D_r to its tip
  diameter D_t, D_max the thickest diameter in the tree (Eq. 10);
* the twist γ (Eq. 11, computed by the caller) about the rest v axis;
* Cᵢ = Rot(Nᵢ, φᵢ)·Rot(v, −γ)·Cᵢ₋₁ with Nᵢ along sᵢ′ × Fᵢ (the bend turns the segment towards
  the force; no bend where |Nᵢ| ≈ 0).

Only rotations are applied, so segment lengths are kept exactly in any load.

**Sign of the twist.** With u = v × w (Eq. 1) the moment of a load L_w·w at the lever arm
r·u about v is −r·L_w, so a positive L′_v = r·L_w (Eq. 3 with unit gain) must turn the object
by −γ about v for the twist to carry the tip *with* the load, as a real torque does (turning by
+γ would swing a curved branch's tip against the pull). The rotation is therefore
Rot(v, −γ); everything else follows the paper.

**Layout.** The loop runs over the segment index, never over objects: objects are processed in
order of decreasing segment count (:attr:`BendingPlan.order`), so those with more than i
segments are a prefix of that order and the i-th pass works on contiguous slices. Rotations are
unit quaternions; block i of the flat (4, S) array ``q`` holds segment i of every object that
has one, and block i of the flat (3, S) array ``o`` the bent offset of node i + 1 from the
object's base, Σ_{j<=i} Cⱼ sⱼ (accumulated per object, so no round-off crosses objects).
"""

from __future__ import annotations

import numpy as np

from ..model.geometry import perpendicular
from .bend_angle import solve_bend_angle
from .rotation import Workspace, qmul, qrot

# Rot(v, −γ) ⊗ C = cos·C + sin·(−C_y, C_z, C_w, −C_x): rows and signs of the second term.
_SWAP = np.array([2, 3, 0, 1])
_SWAP_SIGN = np.array([-1.0, 1.0, 1.0, -1.0])[:, None]

#: Above this bound on |F||s| (N·m) the squares in |N| = |s′ × F| could overflow: |N| is then
#: computed with hypot (slower, never needed by any physical load).
_SQUARE_SAFE = 1e150


def rest_frames(tree) -> np.ndarray:
    """(M, 3, 3) rest frames: columns (u, v, w) of every object (Eq. 1; leaves: Fig. 6).

    v = P0P1/|P0P1|; w = the tree's ``rest_w`` made exactly perpendicular to v (Eq. 1's
    P0Pn × v for branches and blades, the lamina normal for leaves; any perpendicular if it is
    parallel to v); u = v × w.

    Parameters
    ----------
    tree : Tree

    Returns
    -------
    numpy.ndarray, (M, 3, 3) float
        Columns u, v, w of each object's frame, world rest coordinates.
    """
    X = np.asarray(tree.rest_positions, float)
    start = np.asarray(tree.object_start)
    M = len(start)
    v = X[start + 1] - X[start]
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    w = np.asarray(tree.rest_w, float).reshape(M, 3).copy()
    w -= np.einsum("ij,ij->i", w, v)[:, None] * v
    wn = np.linalg.norm(w, axis=1)
    bad = ~(wn > 1e-9)
    if np.any(bad):
        w[bad] = perpendicular(v[bad])
        wn[bad] = 1.0
    w /= wn[:, None]
    u = np.cross(v, w)  # Eq. 1: u = v × w
    return np.stack([u, v, w], axis=2)


class BendingPlan:
    """Per-segment-index index arrays of a tree, precomputed once, and the bent state.

    Attributes
    ----------
    order : (M,) int
        Objects by decreasing segment count (stable); ``order[:counts[i]]`` have a segment i.
    counts : list of int
        Objects having a segment i, for i = 0 … max segments − 1.
    seg_obj, seg_index : (S,) int
        Object and segment index of every flat slot.
    offsets : list of int
        Start of block i in the flat segment arrays.
    n_flat : int
        Total segments S.
    flat_of_node : (N,) int
        Flat slot of the segment leaving each node; an object's tip node points at its last
        segment (so its rotation is the last segment's).
    ofs_of_node : (N,) int
        Slot of each node's bent offset in ``o``: the slot of the segment arriving at it, or S
        (zero) for an object's base node.
    q : (4, S + 1) float
        Cumulative local rotation of every segment (quaternions); column S is the identity.
    o : (3, S + 1) float
        Bent offsets from the object's base, in world rest coordinates; column S is zero.
    phi : (S,) float
        Bend angles.
    rho : (S,) float
        φ/θ₀, the warm start of the next solve.
    """

    def __init__(self, tree, frames: np.ndarray):
        X = np.asarray(tree.rest_positions, float)
        start = np.asarray(tree.object_start)
        nseg = np.asarray(tree.object_count) - 1
        self.M = M = len(start)
        self.N = len(X)
        self.order = np.argsort(-nseg, kind="stable")  # by decreasing segment count
        max_n = int(nseg.max()) if M else 0
        # Block i: segment i of the objects having one (a prefix of ``order``).
        self.counts = [int(np.count_nonzero(nseg > i)) for i in range(max_n)]
        block_objs = [self.order[:K] for K in self.counts]
        self.offsets = [int(x) for x in np.concatenate([[0], np.cumsum(self.counts)])]
        self.n_flat = S = self.offsets[-1]
        self.seg_obj = np.concatenate(block_objs) if S else np.zeros(0, np.int64)
        self.seg_index = np.repeat(np.arange(max_n), self.counts)
        R = np.asarray(frames, float)  # (M, 3, 3) local → world rest

        flat_of_node = np.empty(self.N, np.int64)
        ofs_of_node = np.full(self.N, S, np.int64)
        self.seg = []  # (3, K_i) rest segment vectors in each object's local frame
        self.seg_len2 = []  # (K_i,) |sᵢ|²
        self.frac = []  # (K_i,) (n − i)/n of Eq. 7
        self.frac_len = []  # (K_i,) (n − i)/n · |sᵢ|
        self.taper = []  # (K_i,) D_i of Eq. 10
        diam = np.asarray(tree.node_diameter, float)
        d_root = diam[start]
        d_tip = diam[start + nseg]
        self.rest_o = np.zeros((3, S + 1))  # rest offsets from the object's base, as the bent
        for i, objs in enumerate(block_objs):
            K = len(objs)
            nodes = start[objs] + i
            flat = self.offsets[i] + np.arange(K)
            flat_of_node[nodes] = flat
            ofs_of_node[nodes + 1] = flat
            last = nseg[objs] == i + 1
            flat_of_node[nodes[last] + 1] = flat[last]  # tip nodes: their last segment
            sw = X[nodes + 1] - X[nodes]
            s = np.einsum("kji,kj->ik", R[objs], sw)  # Rᵀ s: local (u, v, w) components
            if i == 0:  # the first segment lies on v by definition (Eq. 1)
                s = np.stack([np.zeros(K), np.linalg.norm(sw, axis=1), np.zeros(K)])
            s = np.ascontiguousarray(s)
            self.seg.append(s)
            self.seg_len2.append(np.einsum("ik,ik->k", s, s))
            n = nseg[objs].astype(float)
            self.frac.append((n - i) / n)
            self.frac_len.append(self.frac[-1] * np.sqrt(self.seg_len2[-1]))  # |Fᵢ||sᵢ| / |F|
            t = i / np.maximum(n - 1, 1)
            self.taper.append(d_root[objs] - (d_root[objs] - d_tip[objs]) * t)
            self.rest_o[:, flat] = s if i == 0 else self.rest_o[:, self.offsets[i - 1]:self.offsets[i - 1] + K] + s
        self.max_seg = max((float(np.sqrt(x.max())) for x in self.seg_len2 if len(x)), default=0.0)
        self.flat_of_node = flat_of_node
        self.ofs_of_node = ofs_of_node
        self.ws = Workspace()
        self.d_max = float(diam.max()) if self.N else 1.0
        self.reset()

    def reset(self) -> None:
        """Back to the unbent rest state."""
        S = self.n_flat
        self.q = np.zeros((4, S + 1))
        self.q[0] = 1.0
        self.o = self.rest_o.copy()
        self.phi = np.zeros(S)
        self.rho = np.zeros(S)
        self.rho_old = np.zeros(S)
        self.rho_start = np.zeros(S)

    def stiffness(self, ei_max: float, exponent: float) -> list[np.ndarray]:
        """kᵢ = EI_max (Dᵢ/D_max)^m per block (Eq. 10).

        Parameters
        ----------
        ei_max : float
            EI_max (N·m/rad).
        exponent : float
            m.

        Returns
        -------
        list of (K_i,) float
        """
        return [ei_max * np.maximum(d / self.d_max, 0.0) ** exponent for d in self.taper]

    def bend(self, Fu: np.ndarray, Fw: np.ndarray, gamma: np.ndarray, k: list[np.ndarray],
             predict: float = 0.0) -> None:
        """Bend every object in its local rest frame; update ``q``, ``o`` and ``phi``.

        In the local frame (u, v, w) the force of Eq. 6 is (L′_w, 0, L′_u), the twist is a
        rotation about the v axis (0, 1, 0), and the first segment lies on v.

        Parameters
        ----------
        Fu, Fw : (M,) float
            u and w components of the force on each object (L′_w and L′_u), in ``order``;
            segment i feels F·(n − i)/n at the lever |sᵢ| (Eq. 7).
        gamma : (M,) float
            Twist per segment about v (Eq. 11), in ``order``: one value per object (every
            segment twists alike); applied as Rot(v, −γ).
        k : list of (K_i,) float
            Stiffness per block, from :meth:`stiffness`.
        predict : float
            The solver starts from ρ·θ₀ with ρ = φ/θ₀ extrapolated as ρ + predict·(ρ −
            ρ_previous): 0 restarts from the last fractions, dt/dt_prev extrapolates linearly
            in time (a better start, fewer iterations).
        """
        # Start of the angle solve: the bend as a fraction ρ = φ/θ₀ of the angle to the force
        # (nearly constant from step to step even where θ₀ moves), extrapolated linearly.
        rho_start = self.rho_start
        np.subtract(self.rho, self.rho_old, out=rho_start)
        rho_start *= predict
        rho_start += self.rho
        np.clip(rho_start, 0.0, 1.0, out=rho_start)
        self.rho_old, self.rho = self.rho, self.rho_old
        ws = self.ws
        mul = np.multiply
        # Rot(v, −γ) = (cos γ/2, 0, −sin γ/2, 0)
        th = np.tan(0.5 * gamma)  # tan(γ/2): cos(γ/2) = 1/√(1+th²), sin(γ/2) = th·cos(γ/2)
        cv = th * th
        cv += 1.0
        np.sqrt(cv, out=cv)
        np.divide(1.0, cv, out=cv)
        sv = th
        sv *= cv
        np.negative(sv, out=sv)
        Fmag = np.hypot(Fu, Fw)  # |F| per object
        # |N| <= |F||s|: below the bound the plain sum of squares cannot overflow.
        safe = not (Fmag.max(initial=0.0) * self.max_seg > _SQUARE_SAFE)
        prev = None
        prev_o = None
        for i, K in enumerate(self.counts):
            a, b = self.offsets[i], self.offsets[i + 1]
            fu = mul(Fu[:K], self.frac[i], out=ws.get("fu", (K,)))  # Eq. 7
            fw = mul(Fw[:K], self.frac[i], out=ws.get("fw", (K,)))
            amag = mul(Fmag[:K], self.frac_len[i], out=ws.get("amag", (K,)))  # a = |Fᵢ||sᵢ|
            tmp = ws.get("tmp", (K,))
            c_, s_ = cv[:K], sv[:K]
            sp, T, n, nn, dot, theta0 = self._moment(i, K, (fu, fw), prev, c_, s_, safe, tmp)
            phi, t = solve_bend_angle(nn, dot, k[i][:K], theta0, mul(rho_start[a:a + K], theta0),
                                      a=amag)  # Eqs. 8–9
            # No bend where the force is zero or (anti)parallel to the segment.
            ok = nn > mul(amag, 1e-12, out=ws.get("eps", (K,)))
            phi *= ok
            t *= ok
            inv = np.maximum(nn, 1e-300)  # 1/|N|; where no bend, t = 0 zeroes its uses
            np.divide(1.0, inv, out=inv)
            self.phi[a:a + K] = phi
            np.divide(phi, np.maximum(theta0, 1e-300), out=self.rho[a:a + K])
            dst = self.q[:, a:a + K]
            t2, ch2 = self._rotation(i, K, n, t, inv, T, c_, s_, dst, tmp)
            oo = self.o[:, a:a + K]
            self._bent_segment(i, sp, (fu, fw), t, t2, ch2, inv, dot, oo, tmp)
            if i > 0:
                oo += prev_o[:, :K]  # accumulate along the object
            prev = self.q[:, a:b]
            prev_o = self.o[:, a:b]

    def _twisted(self, C, c_, s_):
        """T = Rot(v, −γ) ⊗ C = cos(γ/2)·C + sin(γ/2)·(−C_y, C_z, C_w, −C_x) (c_, s_: the halves)."""
        T = self.ws.get("T", C.shape)
        np.take(C, _SWAP, axis=0, out=T)
        T *= _SWAP_SIGN
        T *= s_
        T += np.multiply(C, c_, out=self.ws.get("T2", C.shape))
        return T

    def _moment(self, i, K, f, prev, c_, s_, safe, tmp):
        """Segment i twisted by Rot(v, −γ) after its parent's rotation: the moment
        N = s′ × F of its force (Eq. 8), |N|, s′·F and the angle θ₀ from s′ to F.

        Returns (s′, T, (n0, n1, n2), |N|, s′·F, θ₀) with T = Rot(v, −γ) ⊗ C_{i−1}
        (None for the first segment, whose s′ = s₀ = (0, l, 0) and n1 = None)."""
        mul, ws = np.multiply, self.ws
        fu, fw = f
        s = self.seg[i][:, :K]
        if i == 0:
            # s′ = s₀ = (0, l, 0):  N = s′ × F = (l·F_w, 0, −l·F_u), s′·F = 0 (F has no v part)
            l = s[1]
            n0 = mul(l, fw)
            n2 = mul(l, fu)
            np.negative(n2, out=n2)
            if safe:
                nn = mul(n0, n0)
                nn += mul(n2, n2, out=tmp)
                np.sqrt(nn, out=nn)
            else:
                nn = np.hypot(n0, n2)
            return s, None, (n0, None, n2), nn, np.zeros(K), np.full(K, 0.5 * np.pi)
        T = self._twisted(prev[:, :K], c_, s_)  # Rot(v, −γ) ⊗ C_{i−1}
        sp = qrot(T, s, out=ws.get("sp", (3, K)), ws=ws)
        sx, sy, sz = sp
        n0 = mul(sy, fw)
        n1 = mul(sz, fu)
        n1 -= mul(sx, fw, out=tmp)
        n2 = mul(sy, fu)
        np.negative(n2, out=n2)
        if safe:
            nn = mul(n0, n0)
            nn += mul(n1, n1, out=tmp)
            nn += mul(n2, n2, out=tmp)
            np.sqrt(nn, out=nn)
        else:
            nn = np.hypot(np.hypot(n0, n1), n2)
        dot = mul(sx, fu)
        dot += mul(sz, fw, out=tmp)
        return sp, T, (n0, n1, n2), nn, dot, np.arctan2(nn, dot)

    def _rotation(self, i, K, n, t, inv, T, c_, s_, dst, tmp):
        """Segment i's rotation Cᵢ into ``dst``: the bend quaternion (cos φ/2, sin φ/2 · N/|N|)
        with t = tan(φ/2), after T (the first segment: after Rot(v, −γ) = (c_, 0, s_, 0)).
        Returns (t², cos²(φ/2))."""
        mul = np.multiply
        n0, n1, n2 = n
        t2 = t * t
        ch2 = 1.0 + t2
        np.divide(1.0, ch2, out=ch2)  # cos²(φ/2)
        ch = np.sqrt(ch2)
        sh = mul(t, ch)
        sh *= inv  # sin(φ/2) / |N|
        b0 = ch
        b1 = mul(n0, sh)
        b3 = mul(n2, sh)
        if i == 0:  # C₀ = q_bend ⊗ Rot(v, −γ), with q_bend = (b0, b1, 0, b3)
            mul(b0, c_, out=dst[0])
            mul(b1, c_, out=dst[1])
            dst[1] -= mul(b3, s_, out=tmp)
            mul(b0, s_, out=dst[2])
            mul(b1, s_, out=dst[3])
            dst[3] += mul(b3, c_, out=tmp)
        else:
            qb = self.ws.get("qb", (4, K))
            qb[0] = b0
            qb[1] = b1
            mul(n1, sh, out=qb[2])
            qb[3] = b3
            qmul(qb, T, out=dst, ws=self.ws)  # Cᵢ = q_bend ⊗ T
        return t2, ch2

    def _bent_segment(self, i, sp, f, t, t2, ch2, inv, dot, oo, tmp) -> None:
        """The bent segment Cᵢsᵢ = cos φ·s′ + sin φ·(N̂ × s′) into ``oo``, with
        N̂ × s′ = (F|s|² − s′(s′·F))/|N|."""
        mul = np.multiply
        fu, fw = f
        c_phi = 1.0 - t2
        c_phi *= ch2
        s_phi = mul(t, ch2)
        s_phi *= inv
        s_phi += s_phi
        l2 = self.seg_len2[i][:len(t)]
        s_phi *= l2  # sin φ · |s|² / |N|
        mul(sp, c_phi, out=oo)
        oo[0] += mul(fu, s_phi, out=tmp)
        oo[2] += mul(fw, s_phi, out=tmp)
        if i > 0:
            s_phi /= l2
            s_phi *= dot
            oo -= mul(sp, s_phi, out=self.ws.get("v3", sp.shape))
