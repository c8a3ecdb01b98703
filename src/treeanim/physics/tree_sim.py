"""The ``tree`` model: one mechanical structure of the whole tree, solved implicitly
(docs/design.md §12): :class:`TreeSim` keeps the model (:class:`~.structure.Structure`), the
state (:class:`~.treestep.TreeState` and the fallen leaves) and steps it with
:func:`~.treestep.step`.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from ..model.params import PhysicsParams, check_physics
from ..model.scene import object_trees
from ..model.tree import KINDS, Tree
from . import treestep
from .falling import FallingLeaves
from .lod import Parts, Reduced
from .structure import Structure
from .treestep import Grab, TreeState, Work

__all__ = ["TreeSim", "SimState", "WOOD_RUPTURE", "GRAB_STIFFNESS", "MAX_GRAB_STIFFNESS"]

#: Green wood's modulus of rupture (Pa; cherry, oak, maple 55–65 MPa green, Wood Handbook
#: FPL-GTR-190 Table 5-3a, less for the knots of a branch): a grab never bends a joint on the way
#: to the root harder than this, so a hand can bend a trunk but not fold it.
WOOD_RUPTURE = 5.0e7
#: A grab's spring, in units of the tree's own stiffness at the grabbed point: the point covers
#: GRAB_STIFFNESS/(1 + GRAB_STIFFNESS) of a small drag (98 %), far stiffer than the branch.
GRAB_STIFFNESS = 50.0
#: The stiffest grab :meth:`TreeSim.drag` takes, in the same units (a stiffer spring holds the
#: point no closer and only stiffens the step's equations).
MAX_GRAB_STIFFNESS = 1e4
#: The ground: a grab's target is kept this far above it (m).
GROUND_CLEARANCE = 0.02


@dataclass
class SimState:
    """Everything of a :class:`TreeSim` that changes over time (``copy()`` is deep)."""

    tree: TreeState
    fallen: FallingLeaves

    def copy(self) -> "SimState":
        """A deep copy."""
        return SimState(self.tree.copy(), self.fallen.copy())


class TreeSim:
    """The whole-tree model behind :class:`~treeanim.physics.simulation.Simulation` (``model="tree"``).

    Parameters
    ----------
    tree : Tree
    wind : object with ``sample(points, t)`` or None
    season : float in [0, 1]
    seed : int
        Seed of the leaves' flutter phases and falling.
    """

    def __init__(self, tree: Tree, wind=None, season: float = 0.0, seed: int = 0):
        self._tree = tree
        self._seed = int(seed)
        self._kinds = [k for k in KINDS if np.any(tree.kind == k)]
        check_physics(tree.physics, self._kinds)
        self._physics = tree.physics
        self._season = float(season)
        self._present = tree.leaves_present(self._season)
        self._present.setflags(write=False)
        self._s = Structure.build(tree, self._physics, self._present)
        self._work = Work(len(self._s.parent))
        self._st = TreeState.rest(self._s, self._seed)
        self._fallen = FallingLeaves(tree.object_start, tree.object_count, tree.rest_w, self._seed)
        self._pulls: dict[int, tuple[int, np.ndarray, np.ndarray, np.ndarray]] = {}  # body, offset, applied, asked
        self._grabs: dict[int, tuple[Grab, float, float]] = {}  # object -> grab, s, stiffness
        self.wind = wind
        self._pos = self._rot = None
        self._levels = np.zeros(int(object_trees(tree).max(initial=0)) + 1, np.int64)  # asked
        self._detail = self._levels.copy()  # stepped: the held trees at full detail
        self._parts = Parts(tree, self._s)
        self._lod: Reduced | None = None

    # ------------------------------------------------------------------ model
    @property
    def structure(self) -> Structure:
        """The static model (bodies, joints, leaves)."""
        return self._s

    def _rebuild(self) -> None:
        self._s = Structure.build(self._tree, self._physics, self._present)
        self._parts = Parts(self._tree, self._s)
        self._work.theta_h = None  # the joints' θ follow their frequencies
        for i, (g, s, stiffness) in list(self._grabs.items()):  # their springs follow the stiffness
            self.drag(i, g.target, s, stiffness)
        self._relevel(force=True)

    @property
    def season(self) -> float:
        """0 (summer) … 1 (winter)."""
        return self._season

    @season.setter
    def season(self, s: float) -> None:
        present = self._tree.leaves_present(s)
        present.setflags(write=False)
        fell = np.flatnonzero(self._present & ~present)
        if len(fell):
            self._fallen.detach(fell, self.positions, self.rotations)
        self._fallen.remove(np.flatnonzero(present & ~self._present))
        self._season = s
        self._present = present
        self._rebuild()
        self._pos = self._rot = None

    @property
    def physics(self) -> PhysicsParams:
        """The physical parameters (settable; re-derives the structure)."""
        return self._physics

    @physics.setter
    def physics(self, p: PhysicsParams) -> None:
        check_physics(p, self._kinds)
        self._physics = p
        self._rebuild()

    @property
    def present(self) -> np.ndarray:
        """(M,) bool: objects on the tree (fallen leaves False)."""
        return self._present

    @property
    def shown(self) -> np.ndarray:
        """(M,) bool: objects to draw, the present ones and the fallen leaves."""
        if not len(self._fallen):
            return self._present
        out = self._present | self._fallen.shown(self._tree.n_objects)
        out.setflags(write=False)
        return out

    # ------------------------------------------------------------------ state
    @property
    def time(self) -> float:
        """Simulated time (s)."""
        return self._st.time

    def get_state(self) -> SimState:
        """A copy of the state."""
        return SimState(self._st, self._fallen).copy()

    def set_state(self, state: SimState) -> None:
        """Restore a state taken by :meth:`get_state` of this simulation."""
        if not isinstance(state, SimState) or state.tree.Q.shape != self._st.Q.shape:
            raise ValueError("state must come from get_state() of a simulation of this tree")
        s = state.copy()
        self._st.assign(s.tree)
        self._fallen = s.fallen
        self._pos = self._rot = None
        self._relevel(force=True)

    def reset(self) -> None:
        """Back to rest at time 0, nothing held, no leaf fallen."""
        self._st = TreeState.rest(self._s, self._seed)
        self._fallen.clear()
        self._pulls.clear()
        self._grabs.clear()
        self._pos = self._rot = None
        self._relevel(force=True)

    @property
    def energy(self) -> float:
        """Kinetic energy of every part plus the elastic energy of every joint (J)."""
        return treestep.energy(self._s, self._st)

    # ------------------------------------------------------------------ levels of detail
    def set_detail(self, levels: np.ndarray) -> None:
        """Each tree's detail level (physics/lod.py; already validated by the façade). A tree
        holding a pull or a drag stays at full detail."""
        self._levels = np.array(levels, np.int64)
        self._relevel()

    @property
    def detail(self) -> np.ndarray:
        """(T,) the detail level each tree is stepped at (a copy)."""
        return self._detail.copy()

    @property
    def active_dof(self) -> int:
        """The degrees of freedom a step solves: three a joint and a petiole."""
        s = self._s
        return 3 * (len(s.parent) + len(s.leaf_body)) if self._lod is None else self._lod.dof

    def _relevel(self, force: bool = False) -> None:
        """Step at the levels asked, the held trees at full detail."""
        held = [*self._pulls, *self._grabs]
        detail = self._levels.copy()
        detail[object_trees(self._tree)[held]] = 0
        if not force and np.array_equal(detail, self._detail):
            return
        was, self._detail = None if force else self._detail, detail  # (force: a new state or structure)
        self._lod = Reduced(self._parts, self._s, self._st, detail, self._work, was, self._lod) if detail.any() else None
        self._pos = self._rot = None

    # ------------------------------------------------------------------ stepping
    def step(self, dt: float) -> None:
        """Advance by ``dt`` seconds (already validated by the façade). Atomic: a wind that
        fails leaves the state as it was (the winds are sampled before anything moves)."""
        s, st, red = self._s, self._st, self._lod
        t = st.time
        pulls = [(b, ofs, f) for b, ofs, f, _ in self._pulls.values()]
        grabs = [g for g, _, _ in self._grabs.values()]
        work = self._work
        if red is not None:  # the active part; the held trees are whole, so their bodies are in it
            s, st, work, at = red.s, red.gather(st), red.work, red.body_index
            pulls = [(at[b], ofs, f) for b, ofs, f in pulls]
            grabs = [dataclasses.replace(g, body=at[g.body]) for g in grabs]
        U = self._sample(treestep.sample_points(s, st), t)
        if len(self._fallen):
            self._fallen.step(None if self.wind is None else (lambda p: self._sample(p, t)), dt)
        treestep.step(s, st, st, U, dt, work, pulls, grabs, self._physics.leaf_flutter)
        if red is not None:
            red.scatter(self._st, self._s)
        self._pos = self._rot = None

    def _sample(self, points: np.ndarray, t: float) -> np.ndarray:
        if self.wind is None:
            return np.zeros_like(points)
        U = np.asarray(self.wind.sample(points, t), float)
        if U.shape != points.shape:
            raise ValueError(f"wind.sample returned shape {U.shape}, expected {points.shape}")
        if not np.all(np.isfinite(U)):
            raise ValueError("wind.sample returned non-finite values")
        return U

    # ------------------------------------------------------------------ pose
    @property
    def positions(self) -> np.ndarray:
        """(N, 3) posed node positions (read-only; a fresh array after each step)."""
        if self._pos is None:
            self._pose()
        return self._pos

    @property
    def rotations(self) -> np.ndarray:
        """(N, 3, 3) world rotations relative to rest of the segment leaving each node."""
        if self._rot is None:
            self._pose()
        return self._rot

    def _pose(self) -> None:
        N, red = self._tree.n_nodes, self._lod
        if red is not None and red.last is not None:  # the still trees' nodes are where they were
            pos, rot = red.last[0].copy(), red.last[1].copy()
            treestep.pose(self._s, self._st, self._tree.rest_positions, pos, rot, red.moving)
        else:
            pos, rot = np.empty((N, 3)), np.empty((N, 3, 3))
            treestep.pose(self._s, self._st, self._tree.rest_positions, pos, rot)
        if len(self._fallen):
            self._fallen.pose(pos, rot)
        pos.setflags(write=False)
        rot.setflags(write=False)
        self._pos, self._rot = pos, rot
        if red is not None:
            red.last = pos, rot

    # ------------------------------------------------------------------ interaction
    def _point(self, i: int, s: float) -> tuple[int, np.ndarray]:
        """(body, rest offset from its joint) of the point at fraction s along object i's
        length (a leaf: its petiole's base on its twig)."""
        st = self._s
        b0 = int(st.body_of_obj[i])
        if b0 < 0:  # a leaf: the point it hangs from
            l = int(np.searchsorted(st.leaf_obj, i))
            return int(st.leaf_body[l]), st.leaf_base0[l].copy()
        n = int(self._tree.object_count[i]) - 1
        L = st.length[b0:b0 + n]
        x = s * L.sum()
        k = int(min(np.searchsorted(np.cumsum(L), x, side="left"), n - 1))
        t = (x - (L[:k].sum())) / max(L[k], 1e-12)
        return b0 + k, min(max(t, 0.0), 1.0) * L[k] * st.axis[b0 + k]

    def pull(self, i: int, force: np.ndarray) -> None:
        """Hold object ``i``'s tip with a constant world ``force`` (validated by the façade),
        at most what its wood bears: a larger pull would break a joint on the way to the root
        (:data:`WOOD_RUPTURE`), so it is held at that force, in its direction."""
        b, ofs = self._point(i, 1.0)
        force = np.asarray(force, float).copy()
        n = float(np.linalg.norm(force))
        f_max = self._strength(b, ofs)[1]
        self._pulls[i] = (b, ofs, force * (f_max / n) if n > f_max else force, force)
        self._relevel()

    @property
    def pulls(self) -> dict[int, np.ndarray]:
        """Held objects and the forces asked of them (a copy)."""
        return {i: f.copy() for i, (_, _, _, f) in self._pulls.items()}

    def _strength(self, b: int, ofs: np.ndarray) -> tuple[float, float, float]:
        """At the point ``ofs`` (rest, from body b's joint): the tree's compliance (m/N, every
        joint on the way to the root bending), the largest force no joint on the way breaks
        under (N) and the slowest swing of a joint on the way (rad/s)."""
        st = self._s
        X = self._tree.rest_positions
        p = X[st.node[b]] + ofs
        compliance, f_max, w, j = 0.0, np.inf, np.inf, b
        while j >= 0:
            w = min(w, float(st.omega_j[j]))
            r = p - X[st.node[j]]
            lever = float(np.linalg.norm(r))
            kb = float(np.trace(st.K[j]) - st.axis[j] @ st.K[j] @ st.axis[j]) / 2.0
            compliance += lever**2 / max(kb, 1e-30)
            if lever > 1e-9:
                f_max = min(f_max, WOOD_RUPTURE * np.pi * st.diameter[j] ** 3 / 32.0 / lever)
            j = int(st.parent[j])
        return compliance, f_max, w

    def drag(self, i: int, target: np.ndarray, s: float = 1.0, stiffness: float = GRAB_STIFFNESS) -> None:
        """Hold the point at fraction ``s`` along object ``i`` with a stiff spring toward the
        world ``target`` (kept :data:`GROUND_CLEARANCE` above the ground), solved inside the
        step; call again to move the target. ``stiffness``: the spring in units of the tree's
        own stiffness at the point (validated by the façade). Several objects may be held at
        once, each by a drag of its own."""
        b, ofs = self._point(i, s)
        target = np.asarray(target, float).copy()
        target[1] = max(target[1], GROUND_CLEARANCE)
        compliance, f_max, w = self._strength(b, ofs)
        k = stiffness / max(compliance, 1e-30)
        # its damper critical in the slowest swing the point moves in (the tree's, for a limb):
        # the mass the spring sees there, 1/(compliance·ω²), at least what the body carries (all
        # of it where the point cannot move: at a root's joint the compliance is 0)
        m, cw = float(self._s.subtree_mass[b]), compliance * w * w
        if cw > 0.0:
            m = max(m, 1.0 / cw)
        g = Grab(body=b, offset=ofs, target=target, k=k, c=2.0 * np.sqrt(k * m), f_max=float(f_max), mass=m)
        self._grabs[i] = (g, s, float(stiffness))
        self._relevel()

    @property
    def drags(self) -> dict[int, tuple[np.ndarray, float]]:
        """The drags held: object → (target (3,), spring N/m) (copies)."""
        return {i: (g.target.copy(), g.k) for i, (g, _, _) in self._grabs.items()}

    def release(self, i: int | None = None) -> None:
        """Let go of object ``i``'s pull and drag (None: of everything)."""
        if i is None:
            self._pulls.clear()
            self._grabs.clear()
        else:
            self._pulls.pop(i, None)
            self._grabs.pop(i, None)
        self._relevel()

    def tip_position(self, i: int) -> np.ndarray:
        """Posed world position of object ``i``'s tip node."""
        return self.positions[int(self._tree.object_start[i] + self._tree.object_count[i] - 1)].copy()

    def point_position(self, i: int, s: float = 1.0) -> np.ndarray:
        """Posed world position of the point at fraction ``s`` along object ``i`` (a leaf: the
        point it hangs from), as :meth:`drag` holds it."""
        b, ofs = self._point(i, s)
        return self._st.P[b] + self._st.R[b] @ ofs

