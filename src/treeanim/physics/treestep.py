"""The ``tree`` stepper: the whole tree as one structure, solved implicitly (docs/design.md §12).

:class:`TreeState` is everything that changes over time (copyable, ``state.copy()``);
:class:`~treeanim.physics.structure.Structure` is the static model; :func:`step` reads a state
and writes the next one. One step:

1. the wind at every segment's middle (the pose at the start), a leaf taking its twig's;
2. the air's force on every segment, ½ρC_d·d·ℓ|U⊥|U⊥ of the wind normal to it relative to the
   segment's own motion, and the leaves' forces of the last step (summed per twig), with the
   damping and turn stiffness of both implicit; pulls (constant forces) and grabs (stiff
   springs to targets, implicit);
3. the articulated-body step (:func:`~treeanim.physics.articulated.articulated_step`);
4. the new pose of every body, kept above the ground (:func:`~treeanim.physics.kinematics.ground_contact`);
5. every leaf's flutter and petiole joint (:func:`~treeanim.physics.leafjoint.leaf_step`), its
   force, air damping and turn stiffness summed per twig for the twig's next step.
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from typing import Sequence

import numpy as np

from .articulated import add_point, articulated_step, rot_log, theta_of
from .compiled import njit
from .kinematics import forward_kinematics, ground_contact
from .leafjoint import leaf_step, pose_nodes
from .scalar import inv_cbrt
from .structure import Structure

__all__ = ["TreeState", "Grab", "step", "pose", "energy", "sample_points"]


@dataclass
class TreeState:
    """The tree stepper's state: joints, the bodies' pose (derived, kept), leaves, time."""

    time: float
    Q: np.ndarray       # (B, 3, 3) joint rotations
    w: np.ndarray       # (B, 3) joint angular velocities (parent's rest axes)
    R: np.ndarray       # (B, 3, 3) world rotations relative to rest
    P: np.ndarray       # (B, 3) joint positions
    Om: np.ndarray      # (B, 3) angular velocities
    V: np.ndarray       # (B, 3) joint-point velocities
    th: np.ndarray      # (L, 3) petiole joints (twist, bend, bend)
    thd: np.ndarray     # (L, 3)
    leaf_F: np.ndarray  # (B, 6) the leaves' spatial force of the last step on each twig
    leaf_C: np.ndarray  # (B, 6, 6) their air damping there, Σ PᵀCP (N·s/m; times h in the step)
    leaf_K: np.ndarray  # (B, 3, 3) their stiffness against the twig's turn (N·m; times h²)
    phase: np.ndarray   # (L,) flutter phase (rad)
    twist: np.ndarray   # (L,) the flutter's twist (rad)
    kick: np.ndarray    # (B,) h·|Δw|, each joint's last change of velocity as radians a step (articulated._whirl_theta)

    @classmethod
    def rest(cls, s: Structure, seed: int = 0) -> "TreeState":
        """The tree at rest at time 0."""
        B, L = len(s.parent), len(s.leaf_body)
        st = cls(time=0.0, Q=np.tile(np.eye(3), (B, 1, 1)), w=np.zeros((B, 3)), R=np.empty((B, 3, 3)),
                 P=np.empty((B, 3)), Om=np.empty((B, 3)), V=np.empty((B, 3)),
                 th=np.zeros((L, 3)), thd=np.zeros((L, 3)), leaf_F=np.zeros((B, 6)),
                 leaf_C=np.zeros((B, 6, 6)), leaf_K=np.zeros((B, 3, 3)),
                 phase=np.random.default_rng([int(seed), 0x1EAF]).uniform(0, 2 * np.pi, L), twist=np.zeros(L),
                 kick=np.zeros(B))
        forward_kinematics(s.parent, s.r0, st.Q, st.w, st.R, st.P, st.Om, st.V)
        return st

    def copy(self) -> "TreeState":
        """A deep copy."""
        return TreeState(**{f.name: (v.copy() if isinstance(v := getattr(self, f.name), np.ndarray) else v)
                            for f in fields(self)})

    def assign(self, other: "TreeState") -> None:
        """Become a copy of ``other`` (arrays overwritten in place)."""
        for f in fields(self):
            v = getattr(other, f.name)
            if isinstance(v, np.ndarray):
                getattr(self, f.name)[...] = v
            else:
                setattr(self, f.name, v)


@dataclass
class Grab:
    """A point of a body held by a stiff spring toward a world target (solved in the step).

    ``offset`` is the point's rest offset from the body's joint; ``k`` (N/m) and ``c`` (N·s/m)
    the spring and its damper; ``f_max`` (N) the largest force it exerts (what the wood bears);
    ``mass`` (kg) what the spring moves, for its θ.
    """

    body: int
    offset: np.ndarray
    target: np.ndarray
    k: float
    c: float
    f_max: float
    mass: float


def sample_points(s: Structure, st: TreeState) -> np.ndarray:
    """(B, 3) world points where the wind is sampled: the segments' middles. A leaf takes its
    twig segment's wind: the wind varies over metres (its integral scale is the canopy's
    height), a leaf sits centimetres from its twig."""
    out = np.empty_like(st.P)
    _midpoints(st.P, st.R, s.mid0, out)
    return out


@njit(cache=True, fastmath=True, error_model="numpy")
def _midpoints(P, R, mid0, out):
    for b in range(P.shape[0]):
        for i in range(3):
            out[b, i] = P[b, i] + R[b, i, 0] * mid0[b, 0] + R[b, i, 1] * mid0[b, 1] + R[b, i, 2] * mid0[b, 2]


@njit(cache=True, fastmath=True, error_model="numpy")
def _air_forces(h, R, Om, V, mid0, axis, cda, U, lump_cd, lump_cl, lump_cauchy, lump_x0, leaf_F, leaf_C, leaf_K, F,
                kap):
    """The air's force on every segment (across it), on what rides rigidly on it at a coarser
    level of detail (:func:`_lump_force`) and the leaves' forces, with their implicit
    damping terms κ as points (see :func:`~treeanim.physics.articulated.articulated_step`) and
    the segments' and leaves' turn stiffness (:func:`_turn_stiffness`; the leaves' summed per
    twig by :func:`~treeanim.physics.leafjoint.leaf_step`)."""
    B = R.shape[0]
    Ka = np.empty((3, 3))
    for b in range(B):
        rx = R[b, 0, 0] * mid0[b, 0] + R[b, 0, 1] * mid0[b, 1] + R[b, 0, 2] * mid0[b, 2]
        ry = R[b, 1, 0] * mid0[b, 0] + R[b, 1, 1] * mid0[b, 1] + R[b, 1, 2] * mid0[b, 2]
        rz = R[b, 2, 0] * mid0[b, 0] + R[b, 2, 1] * mid0[b, 1] + R[b, 2, 2] * mid0[b, 2]
        ax = R[b, 0, 0] * axis[b, 0] + R[b, 0, 1] * axis[b, 1] + R[b, 0, 2] * axis[b, 2]
        ay = R[b, 1, 0] * axis[b, 0] + R[b, 1, 1] * axis[b, 1] + R[b, 1, 2] * axis[b, 2]
        az = R[b, 2, 0] * axis[b, 0] + R[b, 2, 1] * axis[b, 1] + R[b, 2, 2] * axis[b, 2]
        vx = V[b, 0] + Om[b, 1] * rz - Om[b, 2] * ry
        vy = V[b, 1] + Om[b, 2] * rx - Om[b, 0] * rz
        vz = V[b, 2] + Om[b, 0] * ry - Om[b, 1] * rx
        ux, uy, uz = U[b, 0] - vx, U[b, 1] - vy, U[b, 2] - vz
        d = ux * ax + uy * ay + uz * az
        ux -= d * ax
        uy -= d * ay
        uz -= d * az
        un = np.sqrt(ux * ux + uy * uy + uz * uz)
        c = cda[b] * un
        fx, fy, fz = c * ux, c * uy, c * uz
        F[b, 0] = ry * fz - rz * fy
        F[b, 1] = rz * fx - rx * fz
        F[b, 2] = rx * fy - ry * fx
        F[b, 3], F[b, 4], F[b, 5] = fx, fy, fz
        # −∂F/∂v = c_d|U⊥|(1 − aaᵀ + Û⊥Û⊥ᵀ)
        q = 1.0 / un if un > 0.0 else 0.0
        add_point(kap, b, h * c, -h * c, ax, ay, az, h * c, ux * q, uy * q, uz * q, rx, ry, rz)
        if c > 0.0:
            _turn_stiffness(b, h, cda[b], un, ux, uy, uz, d, ax, ay, az, rx, ry, rz, fx, fy, fz, Om, F, kap, Ka)
        if lump_cd[b] > 0.0 or lump_cl[b] > 0.0:
            _lump_force(b, h, R, Om, V, U, lump_cd[b], lump_cl[b], lump_cauchy[b], lump_x0[b], F, kap, Ka)
        # the leaves' force, damping and turn stiffness (backward Euler, as _add_turn's;
        # symmetric, their upper triangles kept)
        for i in range(3):
            F[b, i] += leaf_F[b, i]
            F[b, 3 + i] += leaf_F[b, 3 + i]
            for j in range(3):
                k = leaf_K[b, min(i, j), max(i, j)]
                F[b, i] -= h * k * Om[b, j]
                kap[b, i, j] += h * h * k
        for i in range(6):
            for j in range(6):
                kap[b, i, j] += h * leaf_C[b, min(i, j), max(i, j)]


@njit(cache=True, fastmath=True, error_model="numpy")
def _lump_force(b, h, R, Om, V, U, cd, cl, cauchy, x0, F, kap, Ka):
    """The drag of the twigs and leaves riding rigidly on body b (physics/lod.py): isotropic,
    c(s)·s·u with u the wind relative to the point x where it acts and s = |u|, c(s) = cd +
    cl/∛(1 + cauchy·s²) (the leaves folding as :func:`~.leafjoint.leaf_step`'s do); its
    damping −∂f/∂v ≈ c·s(1 + ûûᵀ) and its lever's turn stiffness (x·f)1 − x fᵀ implicit."""
    x = R[b, 0, 0] * x0[0] + R[b, 0, 1] * x0[1] + R[b, 0, 2] * x0[2]
    y = R[b, 1, 0] * x0[0] + R[b, 1, 1] * x0[1] + R[b, 1, 2] * x0[2]
    z = R[b, 2, 0] * x0[0] + R[b, 2, 1] * x0[1] + R[b, 2, 2] * x0[2]
    ux = U[b, 0] - (V[b, 0] + Om[b, 1] * z - Om[b, 2] * y)
    uy = U[b, 1] - (V[b, 1] + Om[b, 2] * x - Om[b, 0] * z)
    uz = U[b, 2] - (V[b, 2] + Om[b, 0] * y - Om[b, 1] * x)
    s = np.sqrt(ux * ux + uy * uy + uz * uz)
    if s <= 0.0:
        return
    cs = (cd + cl * inv_cbrt(1.0 + cauchy * s * s)) * s
    fx, fy, fz = cs * ux, cs * uy, cs * uz
    F[b, 0] += y * fz - z * fy
    F[b, 1] += z * fx - x * fz
    F[b, 2] += x * fy - y * fx
    F[b, 3] += fx
    F[b, 4] += fy
    F[b, 5] += fz
    add_point(kap, b, h * cs, h * cs, ux / s, uy / s, uz / s, 0.0, 0.0, 0.0, 0.0, x, y, z)
    xf = x * fx + y * fy + z * fz
    r = (x, y, z)
    f = (fx, fy, fz)
    for i in range(3):
        for j in range(3):
            Ka[i, j] = (xf if i == j else 0.0) - r[i] * f[j]
    _add_turn(b, h, Ka, Om, F, kap)


@njit(cache=True, fastmath=True, error_model="numpy", inline="always")
def _turn_stiffness(b, h, cda, un, ux, uy, uz, ua, ax, ay, az, rx, ry, rz, fx, fy, fz, Om, F, kap, Ka):
    """The drag's stiffness against the segment's own turn, taken implicitly (backward Euler).

    Turning a segment by δφ turns its axis and its middle (δa = δφ × a, δr = δφ × r), so the
    cross-flow drag F = c|U⊥|U⊥ and its moment τ = r × F change by K·δφ. A light, soft part in
    a strong wind (a grass blade: drag a hundred times its springs) must take this implicitly
    (:func:`_add_turn`). (ux, uy, uz) is U⊥ and ``ua`` the air's speed along the axis.
    """
    for k in range(3):
        dx, dy, dz = (1.0 if k == 0 else 0.0), (1.0 if k == 1 else 0.0), (1.0 if k == 2 else 0.0)
        dax, day, daz = dy * az - dz * ay, dz * ax - dx * az, dx * ay - dy * ax
        drx, dry, drz = dy * rz - dz * ry, dz * rx - dx * rz, dx * ry - dy * rx
        uda = ux * dax + uy * day + uz * daz
        dnx, dny, dnz = -uda * ax - ua * dax, -uda * ay - ua * day, -uda * az - ua * daz
        q = (ux * dnx + uy * dny + uz * dnz) / un
        dfx, dfy, dfz = cda * (un * dnx + ux * q), cda * (un * dny + uy * q), cda * (un * dnz + uz * q)
        Ka[0, k] = -((dry * fz - drz * fy) + (ry * dfz - rz * dfy))
        Ka[1, k] = -((drz * fx - drx * fz) + (rz * dfx - rx * dfz))
        Ka[2, k] = -((drx * fy - dry * fx) + (rx * dfy - ry * dfx))
    _add_turn(b, h, Ka, Om, F, kap)


@njit(cache=True, fastmath=True, error_model="numpy", inline="always")
def _add_turn(b, h, Ka, Om, F, kap):
    """Take a turn stiffness Ka of body b implicitly (backward Euler): its symmetric part,
    made positive by Gershgorin's shift, joins the body's rotational inertia as h²K and its
    moment as −hKω."""
    for i in range(3):
        for j in range(i + 1, 3):
            m = 0.5 * (Ka[i, j] + Ka[j, i])
            Ka[i, j] = m
            Ka[j, i] = m
    shift = 0.0
    for i in range(3):
        g = Ka[i, i] - abs(Ka[i, (i + 1) % 3]) - abs(Ka[i, (i + 2) % 3])
        shift = max(shift, -g)
    for i in range(3):
        Ka[i, i] += shift
    for i in range(3):
        F[b, i] -= h * (Ka[i, 0] * Om[b, 0] + Ka[i, 1] * Om[b, 1] + Ka[i, 2] * Om[b, 2])
        for j in range(3):
            kap[b, i, j] += h * h * Ka[i, j]


class Work:
    """Scratch arrays of one structure's step (allocated once)."""

    _ARRAYS = ("F", "kap", "IA", "pA", "Dinv", "U", "Ur", "u", "acc")

    def __init__(self, B: int):
        self.F = np.zeros((B, 6))
        self.kap = np.zeros((B, 6, 6))
        self.IA = np.empty((B, 6, 6))
        self.pA = np.empty((B, 6))
        self.Dinv = np.empty((B, 3, 3))
        self.U = np.empty((B, 6, 3))
        self.Ur = np.empty((B, 3, 6))
        self.u = np.empty((B, 3))
        self.acc = np.empty((B, 6))  # each body's change of spatial velocity over the step
        self.theta = None
        self.theta_h = None

    def head(self, B: int) -> "Work":
        """Scratch of a structure of B bodies (at most this one's) in this one's first rows
        (never used at the same time as this one)."""
        w = Work(0)
        for name in self._ARRAYS:
            setattr(w, name, getattr(self, name)[:B])
        return w


def step(s: Structure, st: TreeState, out: TreeState, wind: np.ndarray, dt: float, work: Work,
         pulls: list[tuple[int, np.ndarray, np.ndarray]] = (), grabs: Sequence[Grab] = (),
         leaf_flutter: float = 0.0) -> None:
    """Advance ``st`` by ``dt`` into ``out`` (which may be ``st`` itself).

    Parameters
    ----------
    s : Structure
    st, out : TreeState
    wind : (B, 3) float
        The wind at :func:`sample_points` of ``st`` (m/s).
    dt : float
        Step length (s), any length: the step is implicit.
    work : Work
    pulls : list of (body, rest offset from its joint (3,), world force (3,))
        Constant forces.
    grabs : sequence of Grab
        The points held by springs (each solved inside the step).
    leaf_flutter : float
        The largest flutter angle of a lamina about its midrib (rad), reached edge-on in a strong wind.
    """
    if out is not st:
        out.assign(st)
    w = work
    w.F[:] = 0.0
    w.kap[:] = 0.0
    Ub = np.ascontiguousarray(wind)
    _air_forces(dt, out.R, out.Om, out.V, s.mid0, s.axis, s.cda, Ub, s.lump_cd, s.lump_cl, s.lump_cauchy, s.lump_x0,
                out.leaf_F, out.leaf_C, out.leaf_K, w.F, w.kap)
    for b, ofs, f in pulls:
        _point_force(b, out.R[b] @ ofs, np.asarray(f, float), dt, out, w)
    for g in grabs:
        _grab_force(s, g, out, dt, w)
    tb, tt = _thetas(s, dt, work)
    articulated_step(dt, tb, tt, s.axis, s.parent, s.r0, s.m0, s.h0, s.J0, s.kb, s.kt, s.dk, out.R, out.P, out.Q, out.w,
                     out.kick, out.Om, out.V, w.F, w.kap, w.IA, w.pA, w.Dinv, w.U, w.Ur, w.u, w.acc)
    ground_contact(s.parent, s.r0, s.seg0, s.floor, out.Q, out.w, out.R, out.P, out.Om, out.V)
    leaf_step(dt, s.leaf_on, s.leaf_body, s.leaf_base0, s.leaf_rc0, s.leaf_geometry, s.leaf_E, s.leaf_k,
              s.leaf_J, s.leaf_d, s.leaf_cna, s.leaf_cswing, s.leaf_roll2, s.leaf_cauchy, s.leaf_size,
              out.R, out.P, out.Om, out.V, Ub, float(leaf_flutter), out.phase, out.twist, out.th, out.thd,
              out.leaf_F, out.leaf_C, out.leaf_K)
    out.time = st.time + dt


def _thetas(s: Structure, h: float, w: Work) -> np.ndarray:
    """Each joint's θ for its bends and its twist at step h (kept while h is)."""
    if w.theta_h != h:
        w.theta = (theta_of(h * s.omega_j), theta_of(h * s.omega_t))
        w.theta_h = h
    return w.theta


def _grab_force(s: Structure, g: Grab, st: TreeState, h: float, w: Work) -> None:
    """The grab's spring −k(x − target) − (c + θhK)v, capped at f_max (then a pull of f_max
    toward the target, stiff only across its direction, as f_max/|x − target|), its implicit
    part as κ (θ of the joint the body moves by)."""
    b = g.body
    theta = float(_thetas(s, h, w)[0][b])  # the θ its body moves by (a stiffer one would not match the update)
    r = st.R[b] @ g.offset
    x = st.P[b] + r
    v = st.V[b] + np.cross(st.Om[b], r)
    gap = x - g.target
    fs = -g.k * gap
    n = float(np.linalg.norm(fs))
    # the spring's stiffness K = α·1 + β·ddᵀ, taken implicitly
    alpha, beta, d = g.k, 0.0, np.zeros(3)
    if n > g.f_max:  # beyond what the wood bears: a pull of f_max toward the target, whose
        fs *= g.f_max / n  # direction still turns as the point moves across it
        d = gap / np.linalg.norm(gap)
        alpha = g.f_max / float(np.linalg.norm(gap))
        beta = -alpha
    Kv = alpha * v + beta * (d @ v) * d
    _point_force(b, r, fs, h, st, w)
    f = -g.c * v - theta * h * Kv
    w.F[b, :3] += np.cross(r, f)
    w.F[b, 3:] += f
    q = (h * theta) ** 2
    add_point(w.kap, b, h * g.c + q * alpha, q * beta, d[0], d[1], d[2], 0.0, 0.0, 0.0, 0.0, r[0], r[1], r[2])


def _point_force(b: int, r: np.ndarray, f: np.ndarray, h: float, st: TreeState, w: Work) -> None:
    """A force ``f`` (world) at ``r`` from body b's joint, and its stiffness against the body's
    turn, taken implicitly (:func:`_add_turn`): turning by δφ swings the lever, δτ = (δφ × r) × f,
    so K = −∂τ/∂φ = (r·f)·1 − r fᵀ. A hard sideways pull on a light limb is many times stiffer
    than the limb's own springs (taken explicitly, a 20-body-weight pull on a tulip poplar limb
    diverged at 1/30 s steps)."""
    w.F[b, :3] += np.cross(r, f)
    w.F[b, 3:] += f
    Ka = float(r @ f) * np.eye(3) - np.outer(r, f)
    _add_turn(b, h, Ka, st.Om, w.F, w.kap)


def pose(s: Structure, st: TreeState, rest: np.ndarray, pos: np.ndarray, rot: np.ndarray, parts=None) -> None:
    """Write the posed nodes: ``pos`` (N, 3) and rest-relative rotations ``rot`` (N, 3, 3), of
    the ``parts`` (bodies, leaves) only where given (the other nodes left as they are)."""
    bodies, leaves = (np.arange(len(s.parent)), np.arange(len(s.leaf_body))) if parts is None else parts
    pose_nodes(bodies, leaves, s.node, s.tip, s.tip_node, rest, st.R, st.P, s.leaf_nodes, s.leaf_first, s.leaf_body,
               s.leaf_E, st.th, s.leaf_on, pos, rot)


@njit(cache=True, fastmath=True, error_model="numpy")
def _logs(Q, out):
    for b in range(Q.shape[0]):
        rot_log(Q[b], out[b])


def energy(s: Structure, st: TreeState) -> float:
    """Kinetic energy of every body and leaf plus the elastic energy of every joint (J)."""
    m = s.m0
    hw = np.einsum("bij,bj->bi", st.R, s.h0)
    Jw = np.einsum("bij,bjk,blk->bil", st.R, s.J0, st.R)
    om, v = st.Om, st.V
    ke = 0.5 * (np.einsum("bi,bij,bj->b", om, Jw, om) + m * np.einsum("bi,bi->b", v, v)) \
        + np.einsum("bi,bi->b", v, np.cross(om, hw))
    th = np.empty((len(m), 3))
    _logs(st.Q, th)
    pe = 0.5 * np.einsum("bi,bij,bj->b", th, s.K, th)
    lk = 0.5 * np.sum(s.leaf_J * st.thd**2 + s.leaf_k * st.th**2, axis=1) * s.leaf_on
    return float(ke.sum() + pe.sum() + lk.sum())
