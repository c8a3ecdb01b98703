"""Curved-beam bending (Eqs. 7–11, DESIGN §5), vectorised across objects.

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

from .rotation import Workspace, qmul, qrot

#: Newton stops when |Δφ| is below this (radians).
NEWTON_TOL = 1e-7
#: Halley iterations run on every segment; from the previous step's angle (a warm start) two
#: usually converge. Segments not converged by then continue alone (Newton, then bisection), so
#: the tolerance always holds.
NEWTON_FIXED = 3
#: Further Newton iterations for the stragglers before bisection takes over.
NEWTON_EXTRA = 12


def _residual(phi, nn, dot, k):
    """h(φ) = nn·cos φ − dot·sin φ − kφ, hp = −h′(φ), m = h + kφ = −h″(φ), t = tan(φ/2)."""
    t = np.tan(0.5 * phi)
    t2 = t * t
    r = 1.0 + t2
    np.divide(1.0, r, out=r)
    omt = 1.0 - t2
    m = nn * omt
    m -= (dot + dot) * t
    m *= r  # nn cos φ − dot sin φ = a sin(θ₀ − φ) >= 0
    hp = (nn + nn) * t
    hp += dot * omt
    hp *= r
    hp += k  # a cos(θ₀ − φ) + k
    h = k * phi
    np.subtract(m, h, out=h)
    return h, hp, m, t


def solve_bend_angle(nn: np.ndarray, dot: np.ndarray, k: np.ndarray, theta0: np.ndarray,
                     phi0: np.ndarray | None = None, tol: float = NEWTON_TOL,
                     fixed: int = NEWTON_FIXED) -> tuple[np.ndarray, np.ndarray]:
    """Solve |F||s| sin(θ₀ − φ) = k φ for φ ∈ [0, θ₀] (Eqs. 8–9), vectorised.

    With a = |F||s|, ``a·sin θ₀ = |s × F|`` (``nn``) and ``a·cos θ₀ = s·F`` (``dot``), the
    residual is h(φ) = nn·cos φ − dot·sin φ − k φ: concave on [0, θ₀] with h(0) >= 0 >=
    h(θ₀), so the root is unique. ``fixed`` safeguarded iterations of Halley's method (Newton
    with the curvature term, cubically convergent; iterates clipped to [0, θ₀]) run on every
    entry; entries whose last correction is still >= ``tol`` continue alone with plain Newton
    (monotone from the right of the root) and finally bisection on [0, θ₀], so the tolerance
    always holds.

    Parameters
    ----------
    nn, dot : (K,) float
        |s × F| and s·F (N·m).
    k : (K,) float
        Segment stiffness (N·m/rad), >= 0.
    theta0 : (K,) float
        ∠(F, s) in [0, π].
    phi0 : (K,) float, optional
        Start (e.g. the previous step's angles); default: the Newton step from 0.
    tol : float
        Convergence: the last correction is below ``tol``.
    fixed : int
        Iterations run on every entry.

    Returns
    -------
    phi : (K,) float
        φ in [0, θ₀] (the last evaluated iterate, whose correction is < tol).
    t : (K,) float
        tan(φ/2).
    """
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        if phi0 is None:
            den = k + dot
            phi = nn / den
            phi[~((den > 0) & (phi < theta0))] = 0.0
            phi = np.minimum(phi, theta0)
        else:
            phi = np.minimum(np.maximum(phi0, 0.0), theta0)
        for it in range(max(int(fixed), 1)):
            h, hp, m, t = _residual(phi, nn, dot, k)
            # Halley: φ + 2 h hp / (2 hp² + h m)   (h′ = −hp, h″ = −m)
            den = hp * hp
            den += den
            m *= h
            den += m
            new = h * hp
            new += new
            new /= den
            new += phi
            np.maximum(new, 0.0, out=new)
            np.minimum(new, theta0, out=new)  # NaN stays NaN and is caught below
            if it + 1 < fixed:
                phi = new
        new -= phi
        np.abs(new, out=new)
        bad = ~(new < tol)
        if bad.any():
            idx = np.flatnonzero(bad)
            p, tt = _stragglers(phi[idx], nn[idx], dot[idx], k[idx], theta0[idx], tol)
            phi = phi.copy()
            phi[idx] = p
            t = t.copy()
            t[idx] = tt
    return phi, t


def _stragglers(phi, nn, dot, k, theta0, tol):
    """Newton then bisection for the few entries the fixed iterations did not converge."""
    done = np.zeros(len(phi), bool)
    t = np.tan(0.5 * phi)
    # Newton from the right end of the bracket converges monotonically (h concave); start
    # from the current iterate where it lies right of the root, else from θ₀.
    h, _, _, _ = _residual(phi, nn, dot, k)
    phi = np.where(h <= 0, phi, theta0)
    for _ in range(NEWTON_EXTRA):
        h, hp, _, t = _residual(phi, nn, dot, k)
        new = np.clip(phi + h / hp, 0.0, theta0)
        done |= np.abs(new - phi) < tol
        if done.all():
            return phi, t
        phi = np.where(done, phi, new)
        phi = np.where(np.isfinite(phi), phi, 0.5 * theta0)
    # Bisection on [0, θ₀] (h(0) >= 0 >= h(θ₀)) for the rest: always converges.
    lo = np.zeros_like(phi)
    hi = theta0.copy()
    todo = ~done
    for _ in range(64):
        mid = 0.5 * (lo + hi)
        h, _, _, _ = _residual(mid, nn, dot, k)
        pos = h > 0
        lo = np.where(todo & pos, mid, lo)
        hi = np.where(todo & ~pos, mid, hi)
        if np.all(hi - lo < tol):
            break
    phi = np.where(todo, 0.5 * (lo + hi), phi)
    return phi, np.tan(0.5 * phi)


class BendingPlan:
    """Per-segment-index index arrays of a tree, precomputed once, and the bent state.

    Attributes
    ----------
    order : (M,) int
        Objects by decreasing segment count (stable); ``order[:counts[i]]`` have a segment i.
    counts : list of int
        Objects having a segment i, for i = 0 … max segments − 1.
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
        Bend angles (the warm start of the next solve).
    """

    def __init__(self, tree):
        X = np.asarray(tree.rest_positions, float)
        start = np.asarray(tree.object_start)
        nseg = np.asarray(tree.object_count) - 1
        self.M = len(start)
        self.N = len(X)
        self.order = np.argsort(-nseg, kind="stable")
        max_n = int(nseg.max()) if self.M else 0
        self.counts = [int(np.count_nonzero(nseg > i)) for i in range(max_n)]
        self.offsets = [int(x) for x in np.concatenate([[0], np.cumsum(self.counts)])]
        self.n_flat = S = self.offsets[-1]

        flat_of_node = np.empty(self.N, np.int64)
        ofs_of_node = np.full(self.N, S, np.int64)
        self.seg = []  # (3, K_i) rest segment vectors
        self.seg_len2 = []  # (K_i,) |sᵢ|²
        self.frac = []  # (K_i,) (n − i)/n of Eq. 7
        self.taper = []  # (K_i,) D_i of Eq. 10
        diam = np.asarray(tree.node_diameter, float)
        d_root = diam[start]
        d_tip = diam[start + nseg]
        for i, K in enumerate(self.counts):
            objs = self.order[:K]
            nodes = start[objs] + i
            flat = self.offsets[i] + np.arange(K)
            flat_of_node[nodes] = flat
            ofs_of_node[nodes + 1] = flat
            last = nseg[objs] == i + 1
            flat_of_node[nodes[last] + 1] = flat[last]  # tip nodes: their last segment
            s = (X[nodes + 1] - X[nodes]).T.copy()
            self.seg.append(s)
            self.seg_len2.append(np.einsum("ik,ik->k", s, s))
            n = nseg[objs].astype(float)
            self.frac.append((n - i) / n)
            t = i / np.maximum(n - 1, 1)
            self.taper.append(d_root[objs] - (d_root[objs] - d_tip[objs]) * t)
        self.flat_of_node = flat_of_node
        self.ofs_of_node = ofs_of_node
        self.ws = Workspace()
        self.d_max = float(diam.max()) if self.N else 1.0
        # Rest offsets of every node from its object's base, accumulated like the bent ones.
        self.rest_o = np.zeros((3, S + 1))
        for i, s in enumerate(self.seg):
            a, b = self.offsets[i], self.offsets[i + 1]
            self.rest_o[:, a:b] = s if i == 0 else self.rest_o[:, self.offsets[i - 1]:self.offsets[i - 1] + (b - a)] + s
        self.reset()

    def reset(self) -> None:
        """Back to the unbent rest state."""
        S = self.n_flat
        self.q = np.zeros((4, S + 1))
        self.q[0] = 1.0
        self.o = self.rest_o.copy()
        self.phi = np.zeros(S)
        self.phi_old = np.zeros(S)
        self.phi_start = np.zeros(S)

    def stiffness(self, ei_max: float, exponent: float) -> list[np.ndarray]:
        """kᵢ = EI_max (Dᵢ/D_max)^m per block (Eq. 10)."""
        return [ei_max * np.maximum(d / self.d_max, 0.0) ** exponent for d in self.taper]

    def bend(self, F: np.ndarray, gamma: np.ndarray, v: np.ndarray, k: list[np.ndarray],
             predict: float = 0.0) -> None:
        """Bend every object; update ``q``, ``o`` and ``phi``.

        Parameters
        ----------
        F : (3, M) float
            Force on each object in world rest coordinates, in ``order``.
        gamma : (M,) float
            Twist per segment about v (Eq. 11), in ``order``; applied as Rot(v, −γ).
        v : (3, M) float
            Rest v axes, in ``order``.
        k : list of (K_i,) float
            Stiffness per block, from :meth:`stiffness`.
        predict : float
            The solver starts from φ + predict·(φ − φ_previous): 0 restarts from the last
            angles, dt/dt_prev extrapolates linearly in time (a better start, fewer iterations).
        """
        M = len(gamma)
        # Start of the angle solve: linear extrapolation of the last two solutions.
        phi_start = self.phi_start
        np.subtract(self.phi, self.phi_old, out=phi_start)
        phi_start *= predict
        phi_start += self.phi
        self.phi_old, self.phi = self.phi, self.phi_old
        ws = self.ws
        mul = np.multiply
        twist = bool(np.any(gamma))
        if twist:  # Rot(v, −γ) as a quaternion: (cos γ/2, −sin γ/2 · v)
            th = np.tan(0.25 * gamma)
            ch = 1.0 / np.sqrt(1.0 + th * th)
            qv = ws.get("qv", (4, M))
            qv[0] = ch
            mul(v, -(th * ch), out=qv[1:])
        prev = None
        prev_o = None
        for i, K in enumerate(self.counts):
            a, b = self.offsets[i], self.offsets[i + 1]
            s = self.seg[i]
            # T = Rot(v, −γ)·C_{i−1};  s′ = T sᵢ
            sp = ws.get("sp", (3, K))
            if i == 0:
                if twist:
                    T = qv
                    qrot(T, s, out=sp, ws=ws)
                else:
                    T = None
                    sp[...] = s
            else:
                if twist:
                    T = qmul(qv[:, :K], prev[:, :K], out=ws.get("T", (4, K)), ws=ws)
                else:
                    T = prev[:, :K]
                qrot(T, s, out=sp, ws=ws)
            Fi = mul(F[:, :K], self.frac[i], out=ws.get("Fi", (3, K)))  # Eq. 7
            # Bend axis N = s′ × F (turns s′ towards F); |N| = a sin θ₀, s′·F = a cos θ₀.
            Nv = ws.get("N", (3, K))
            tmp = ws.get("tmp", (K,))
            n0, n1, n2 = Nv
            mul(sp[1], Fi[2], out=n0)
            n0 -= mul(sp[2], Fi[1], out=tmp)
            mul(sp[2], Fi[0], out=n1)
            n1 -= mul(sp[0], Fi[2], out=tmp)
            mul(sp[0], Fi[1], out=n2)
            n2 -= mul(sp[1], Fi[0], out=tmp)
            nn = mul(n0, n0)
            nn += mul(n1, n1, out=tmp)
            nn += mul(n2, n2, out=tmp)
            np.sqrt(nn, out=nn)
            dot = mul(sp[0], Fi[0])
            dot += mul(sp[1], Fi[1], out=tmp)
            dot += mul(sp[2], Fi[2], out=tmp)
            theta0 = np.arctan2(nn, dot)
            phi, t = solve_bend_angle(nn, dot, k[i], theta0, phi_start[a:b])  # Eqs. 8–9
            # No bend where the force is zero or (anti)parallel to the segment.
            f2 = mul(Fi[0], Fi[0])
            f2 += mul(Fi[1], Fi[1], out=tmp)
            f2 += mul(Fi[2], Fi[2], out=tmp)
            f2 *= self.seg_len2[i]
            f2 *= 1e-24
            ok = mul(nn, nn, out=tmp) > f2
            phi *= ok
            t *= ok
            inv = np.divide(1.0, nn, out=np.zeros_like(nn), where=ok)
            self.phi[a:b] = phi
            # Bend quaternion (cos φ/2, sin φ/2 · N/|N|);  Cᵢ = q_bend ⊗ T
            t2 = t * t
            ch2 = 1.0 + t2
            np.divide(1.0, ch2, out=ch2)  # cos²(φ/2)
            ch = np.sqrt(ch2)
            sh = mul(t, ch)
            sh *= inv  # sin(φ/2) / |N|
            dst = self.q[:, a:b]
            if T is None:
                dst[0] = ch
                mul(Nv, sh, out=dst[1:])
            else:
                qb = ws.get("qb", (4, K))
                qb[0] = ch
                mul(Nv, sh, out=qb[1:])
                qmul(qb, T, out=dst, ws=ws)
            # Bent segment Cᵢsᵢ = cos φ·s′ + sin φ·(N̂ × s′), N̂ × s′ = (F|s|² − s′(s′·F))/|N|
            c_phi = 1.0 - t2
            c_phi *= ch2
            s_phi = mul(t, ch2)
            s_phi *= inv
            s_phi += s_phi
            oo = self.o[:, a:b]
            v3 = ws.get("v3", (3, K))
            mul(Fi, self.seg_len2[i], out=oo)
            oo -= mul(sp, dot, out=v3)
            oo *= s_phi
            oo += mul(sp, c_phi, out=v3)
            if prev_o is not None:
                oo += prev_o[:, :K]  # accumulate along the object
            prev = dst
            prev_o = oo
