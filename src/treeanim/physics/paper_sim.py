"""The paper's tree simulation (Hu, Chiba & He 2012; docs/design.md §6): wind → loads →
oscillators → bending → hierarchy, every object driven by the load on its own area."""

from __future__ import annotations

import numbers

import numpy as np

from ..model.params import MODE_PARAMS, PhysicsParams, check_physics
from ..model.scene import Scene
from ..model.tree import KINDS, Tree
from ..validate import finite_float, finite_vector3, float_within, object_index
from .derived import Derived
from .modal import ModalDraws, ModalParameters
from .oscillator import INTEGRATORS
from .paper_state import PaperState, Snapshot
from .physical import MODAL_MODELS
from .pose import Pose
from .stages import Stages
from .wind import fit_to_tree

__all__ = ["PaperSim", "PaperState", "MAX_PULL", "MAX_STEP", "MAX_FREQUENCY", "MAX_ZETA"]

#: Largest pull force accepted (N): far beyond any hand on a tree (the bending stays finite
#: and keeps lengths far above it; the cap keeps absurd inputs out).
MAX_PULL = 1e9
#: The longest step (s): any shorter one is stable; far longer ones overflow the oscillators'
#: coefficients (and no animation steps by years).
MAX_STEP = 1e6
#: The highest modal frequency (Hz) and damping ratio accepted: far beyond any plant (and any
#: step rate), small enough that (2πf)² and 2ζω stay finite. Each object's modes are checked
#: against the same declarations as a preset's ranges (:data:`~treeanim.model.params.MODE_PARAMS`).
MAX_FREQUENCY = MODE_PARAMS["f"].hi
MAX_ZETA = MODE_PARAMS["zeta"].hi

class PaperSim(Derived, Stages, Pose, Snapshot):
    """A tree animated by wind and by pulls (Hu, Chiba & He 2012; docs/design.md §5–§8).

    Parameters
    ----------
    tree : Tree
        The tree (any preset, or a Tree built with :func:`treeanim.model.build.assemble`).
    wind : WindField or None
        Anything with ``sample(points (K, 3), t) -> (K, 3)`` m/s. If it still has the default
        bounds, they are fitted to the tree's rest bounding box (``wind.fit``). None: calm.
    season : float
        0 (summer) … 1 (winter): interpolates the modal ranges and drops leaves.
    seed : int
        Seed of the random numbers of Eqs. 20–22 (degenerate ranges, mode noise).
    integrator : {'exact', 'euler'}
        Oscillator integrator (:mod:`treeanim.physics.oscillator`).
    coupling : bool
        Base excitation: every object also feels −(acceleration of its base node) × its mass,
        so a swinging trunk shakes its twigs. False restores the paper's independent objects.
    modes : {'paper', 'physical'} or None
        Where the modal f and ζ come from: 'paper' maps the preset's ranges (Eqs. 20–22);
        'physical' gives every branch its first bending frequency as a tapered cantilever
        carrying what grows on it, and damping from its wood and the drag of what it moves
        (:mod:`~treeanim.physics.physical`; leaves and blades keep the paper's). None: the
        tree's own ``modes`` ('paper' for the presets). Settable as ``modal``.

    Attributes
    ----------
    positions : (N, 3) float, read-only
        Deformed world node positions.
    rotations : (N, 3, 3) float, read-only
        World rotation *relative to rest* of the segment leaving node j; an object's tip node
        carries its last segment's rotation. A rest point x rigidly attached to node j is drawn
        at ``positions[j] + rotations[j] @ (x − rest_positions[j])``. A leaf's lamina is
        attached to its petiole's tip node (it follows the petiole's bend and twist); a
        child's base follows its parent's attach node. At rest, ``positions ==
        rest_positions`` and ``rotations`` are identities (to ~1e-12).
    modes : ModalParameters
        ``modes.f`` and ``modes.zeta``, (M, 3) arrays, columns (u, v, w), writable; read at
        every step. Setting ``season`` or ``physics`` re-derives them (Eqs. 20–22).
    present : (M,) bool, read-only
        Objects on the tree at the current season (fallen leaves are False); ``present_nodes``
        is the same per node. Absent leaves are still simulated (cheap), carrying no load.
    shown : (M,) bool, read-only
        Objects to draw: ``present`` (fallen leaves drop out of sight).
    season : float
        Settable, in [0, 1].
    physics : PhysicsParams
        Settable (e.g. ``dataclasses.replace(sim.physics, ei_max=...)``); re-derives the
        modes, stiffnesses, gains and masses.
    time : float
        Simulated time (s).

    Notes
    -----
    One :meth:`step` (docs/design.md §6):

    1. wind U at each object's middle node (previous-step pose);
    2. local load L = (U·u, U·v, U·w) in the object's previous-step world frame (the rest
       frame carried by its parent, Eq. 12) × exposed area × the kind's gain (Eq. 19), plus
       any pull, plus −mass × base acceleration (``coupling``);
    3. oscillators (Eqs. 2–5): q̈ + 4πζf q̇ + 4π²f² q = g, g_u = L_w, g_v = r·L_w, g_w = L_u,
       L′ = 4π²f² q (unit static gain: L′ settles at the load);
    4. force in the rest frame F = L′_w·u + L′_u·w (Eq. 6) — net effect: a static load along w
       bends the object along w, a load along u bends it along u — and twist from L′_v
       (Eq. 11);
    5. bending of every object in its rest frame (Eqs. 7–10);
    6. composition down the hierarchy (Eq. 12).

    Twist (Eq. 11): γ = 0.5π·sgn(L′_v)(1 − exp(−c0·|L′_v|/k₀))/n per segment, with c0 the
    preset's ``twist_c0`` (``leaf_twist_c0`` for leaves) taken per unit of the object's root
    stiffness k₀ = EI_max (D_r/D_max)^m, so that one constant serves trunks and twigs alike;
    it turns each segment about v by −γ (see :mod:`treeanim.physics.bending` for the sign).

    The lever arm r is u·P0Pn for branches and blades (Eq. 3); for a leaf it is the distance
    from the petiole's base to the lamina's centroid, so the wind on the lamina twists the
    petiole. Exposed area: length × mean diameter; a leaf adds its lamina
    (``tree.lamina.area × lamina_length²``). Mass: density × volume (a lamina is
    ``lamina_thickness`` thick).

    :meth:`get_state` takes a snapshot of the motion (:class:`PaperState`) and :meth:`set_state`
    restores it: the steps after it are then bit for bit those that followed the snapshot.
    """

    def __init__(self, tree: Tree, wind=None, season: float = 0.0, seed: int = 0,
                 integrator: str = "exact", coupling: bool = True, modes: str | None = None):
        if not isinstance(tree, Tree):
            raise ValueError(f"tree must be a treeanim Tree, got {type(tree).__name__}")
        if isinstance(tree, Scene) and tree.n_trees > 1:
            raise ValueError(f"the paper's model takes one tree (its modal ranges span the tree); the scene "
                             f"{tree.name!r} has {tree.n_trees}: use the tree model")
        if isinstance(seed, bool) or not isinstance(seed, numbers.Integral) or seed < 0:
            raise ValueError(f"seed must be a non-negative integer, got {seed!r}")
        self._tree = tree
        self._seed = int(seed)
        self.integrator = integrator
        self._coupling = bool(coupling)
        self._modal = self._check_modal(tree.modes if modes is None else modes)
        season = self._check_season(season)
        kinds = [k for k in KINDS if np.any(tree.kind == k)]
        self._kinds = kinds
        check_physics(tree.physics, kinds)

        M, N = tree.n_objects, tree.n_nodes
        self._M, self._N = M, N
        self._draws = ModalDraws.draw(M, self._seed)
        self._geometry()

        self._physics = tree.physics
        self._season = season
        self._present = tree.leaves_present(season)
        self._present.setflags(write=False)
        self._derive_physics()
        self._derive_modes()

        self._pulls: dict[int, np.ndarray] = {}
        self._pos_buf = self._rot_buf = None
        self._wind = None
        self.wind = wind
        self.reset()

    # ------------------------------------------------------------------ validation
    @staticmethod
    def _check_integrator(name) -> str:
        if name not in INTEGRATORS:
            raise ValueError(f"integrator must be one of {tuple(INTEGRATORS)}, got {name!r}")
        return str(name)

    @staticmethod
    def _check_modal(name) -> str:
        if name not in MODAL_MODELS:
            raise ValueError(f"modes must be one of {MODAL_MODELS}, got {name!r}")
        return str(name)

    @staticmethod
    def _check_season(season) -> float:
        return float_within("season", season, 0.0, 1.0)

    def _check_object(self, i) -> int:
        return object_index(i, self._M)

    def _modes_arrays(self) -> tuple[np.ndarray, np.ndarray]:
        """Validated (3, M) copies of modes.f and modes.zeta (cached while unchanged)."""
        f, z = self._modes.f, self._modes.zeta
        snap = self._mode_snap
        if snap is not None and f is snap[0] and z is snap[1] and np.array_equal(f, snap[2]) \
                and np.array_equal(z, snap[3]):
            return snap[4], snap[5]
        shape = (self._M, 3)
        try:
            fa = np.asarray(f, dtype=float)
        except (TypeError, ValueError):
            raise ValueError(f"modes.f must be a ({self._M}, 3) array of numbers") from None
        try:
            za = np.asarray(z, dtype=float)
        except (TypeError, ValueError):
            raise ValueError(f"modes.zeta must be a ({self._M}, 3) array of numbers") from None
        if fa.shape != shape:
            raise ValueError(f"modes.f must have shape {shape}, got {fa.shape}")
        if za.shape != shape:
            raise ValueError(f"modes.zeta must have shape {shape}, got {za.shape}")
        for name, a in (("f", fa), ("zeta", za)):
            param = MODE_PARAMS[name]
            bad = ~(((a > param.lo) if param.lo_open else (a >= param.lo)) & (a <= param.hi))
            if bad.any():
                j, c = np.argwhere(bad)[0]
                raise ValueError(f"modes.{name} must be {param.expected}: object {j} mode {'uvw'[c]} is {a[j, c]!r}")
        f3, z3 = fa.T.copy(), za.T.copy()
        self._mode_snap = (f, z, fa.copy(), za.copy(), f3, z3)
        self._osc.clear()
        return f3, z3

    # ------------------------------------------------------------------ properties
    @property
    def tree(self) -> Tree:
        """The simulated tree."""
        return self._tree

    @property
    def seed(self) -> int:
        """Seed of the modal random numbers."""
        return self._seed

    @property
    def time(self) -> float:
        """Simulated time in seconds."""
        return self._time

    @property
    def modes(self) -> ModalParameters:
        """(M, 3) natural frequencies ``f`` and damping ratios ``zeta`` (columns u, v, w)."""
        return self._modes

    @property
    def season(self) -> float:
        """0 (summer) … 1 (winter). Setting it re-derives the modes and the present leaves."""
        return self._season

    @season.setter
    def season(self, value) -> None:
        s = self._check_season(value)
        self._season = s
        present = self._tree.leaves_present(s)
        present.setflags(write=False)
        self._present = present
        self._derive_modes()

    @property
    def present(self) -> np.ndarray:
        """(M,) bool: objects shown at the current season (fallen leaves False)."""
        return self._present

    @property
    def shown(self) -> np.ndarray:
        """(M,) bool: objects to draw, ``present`` itself (fallen leaves drop out of sight)."""
        return self._present

    @property
    def present_nodes(self) -> np.ndarray:
        """(N,) bool: nodes of the present objects."""
        return np.repeat(self._present, self._tree.object_count)

    @property
    def physics(self) -> PhysicsParams:
        """The physical parameters. Setting new ones re-derives the modes, stiffness and gains."""
        return self._physics

    @physics.setter
    def physics(self, params: PhysicsParams) -> None:
        check_physics(params, self._kinds)
        old = self._physics
        self._physics = params
        try:
            self._derive_physics()
            self._derive_modes()
        except Exception:
            self._physics = old
            self._derive_physics()
            raise

    @property
    def modal(self) -> str:
        """Where the modes come from: 'paper' or 'physical' (settable; re-derives them)."""
        return self._modal

    @modal.setter
    def modal(self, name: str) -> None:
        self._modal = self._check_modal(name)
        self._derive_modes()

    @property
    def integrator(self) -> str:
        """'exact' or 'euler' (settable)."""
        return self._integrator

    @integrator.setter
    def integrator(self, name: str) -> None:
        self._integrator = self._check_integrator(name)
        self._osc = INTEGRATORS[self._integrator]()

    @property
    def coupling(self) -> bool:
        """Whether base excitation is on (settable)."""
        return self._coupling

    @coupling.setter
    def coupling(self, on: bool) -> None:
        self._coupling = bool(on)

    @property
    def wind(self):
        """The wind field or None (settable; a wind on its default bounds is fitted to the tree)."""
        return self._wind

    @wind.setter
    def wind(self, wind) -> None:
        if wind is not None:
            if not callable(getattr(wind, "sample", None)):
                raise ValueError(f"wind must have a sample(points, t) method, got {type(wind).__name__}")
            fit_to_tree(wind, self._tree.rest_positions)
        self._wind = wind

    def compliance(self, i: int, k: int, s: float, offset=(0.0, 0.0, 0.0)) -> float:
        """Metres a point of object ``i`` moves per newton of a force on it (small bends, rest
        pose), for a pull controller's spring.

        The point is carried by segment ``k`` at ``s`` (0 … 1) along it, plus ``offset`` (a
        point on a leaf's lamina lies beyond the petiole's tip): the sum over Eq. 10's hinges
        up to the point.
        """
        i = self._check_object(int(i))
        tree = self._tree
        nodes = tree.object_nodes(i)
        X = tree.rest_positions[nodes]
        seg = np.diff(X, axis=0)
        anchor = X[k] + s * seg[k] + np.asarray(offset, float)
        L = np.linalg.norm(seg, axis=1)
        n = len(L)
        stiff = np.concatenate(self._k)[self._bplan.flat_of_node[nodes[:-1]]]  # Eq. 10's k, as the bending uses it
        phi = (n - np.arange(n)) / n * L / np.maximum(stiff, 1e-30)  # Eq. 7's fractions
        lever = np.linalg.norm(anchor - X[: k + 1], axis=1)
        return float(np.sum(phi[: k + 1] * lever))

    # ------------------------------------------------------------------ interaction
    def pull(self, i: int, force_xyz) -> None:
        """Hold object ``i`` with a constant world force (N) at its tip (docs/design.md §8).

        While held, the object follows the static deflection of its current load (no
        oscillation of its own modes); :meth:`release` lets it swing freely from there. Pulling
        an object again replaces its force; several objects may be held at once.

        Parameters
        ----------
        i : int
            Object index.
        force_xyz : array_like of 3 floats
            World force in newtons: finite, magnitude at most :data:`MAX_PULL`.

        Raises
        ------
        ValueError
            Unknown object index, or a non-finite, malformed or too large force (state
            unchanged).
        """
        i = self._check_object(i)
        f = finite_vector3("force_xyz", force_xyz)
        # Components first, so that the norm's squares cannot overflow.
        if float(np.max(np.abs(f))) > MAX_PULL or float(np.linalg.norm(f)) > MAX_PULL:
            raise ValueError(f"force_xyz must have a magnitude of at most {MAX_PULL:g} N, got {f.tolist()}")
        self._pulls[i] = f

    def release(self, i: int | None = None) -> None:
        """Let go of object ``i`` (or of every held object when None).

        Parameters
        ----------
        i : int or None
            Object index; None releases every held object.

        Raises
        ------
        ValueError
            Unknown object index.
        """
        if i is None:
            self._pulls.clear()
            return
        i = self._check_object(i)
        self._pulls.pop(i, None)

    # ------------------------------------------------------------------ state
    def reset(self) -> None:
        """Back to rest at time 0: oscillators at zero, the rest pose, no pulls."""
        M, N = self._M, self._N
        self._time = 0.0
        self._p = np.zeros((3, M))  # L′ (Eq. 5), rows u, v, w
        self._pd = np.zeros((3, M))  # its rate
        self._L = np.zeros((3, M))  # last local loads
        self._bplan.reset()
        self._P = self._rest_P.copy()  # valid at structural nodes and roots' bases
        Fw = np.zeros((4, N + 1))  # world segment frames (structural nodes); column N: identity
        Fw[0, N] = 1.0
        Fw[:, :N] = self._cplan.q0[:, self._tree.node_object]
        self._Fw = Fw
        # The rest pose as the composition computes it (equal to the rest positions up to
        # round-off), so that a tree at rest sees exactly zero base velocity.
        self._frame, self._base, self._sample_pos = np.empty((4, M)), np.empty((3, M)), np.empty((3, M))
        self._compose()
        U = len(self._att_nodes)
        self._att_x = self._P[:, self._att_nodes].copy()
        self._att_v = np.zeros((3, U))
        self._att_a = np.zeros((3, U + 1))  # column U: zero, for roots
        self._dt_prev = None
        self._pulls.clear()
        self._pos_out = None
        self._rot_out = None
        self._fn = None

    def step(self, dt: float) -> None:
        """Advance the simulation by ``dt`` seconds (docs/design.md §6).

        One step is a pipeline of stages: wind → loads → oscillators → bending → hierarchy
        (:mod:`~treeanim.physics.stages`).

        Parameters
        ----------
        dt : float
            Step length in seconds, > 0 and at most :data:`MAX_STEP`. Any such length is
            stable: the exact integrator has no step limit; Euler sub-steps (and clamps very
            long steps, see :mod:`treeanim.physics.oscillator`).

        Raises
        ------
        ValueError
            ``dt`` not in (0, MAX_STEP], invalid ``modes`` (f or ζ outside
            :data:`~treeanim.model.params.MODE_PARAMS`, wrong shape), or a wind whose ``sample`` returns the wrong
            shape or non-finite values. The state is left unchanged.
        """
        dt = finite_float("dt", dt)
        if not 0 < dt <= MAX_STEP:
            raise ValueError(f"dt must be > 0 and at most {MAX_STEP:g} s, got {dt!r}")
        f3, z3 = self._modes_arrays()
        U = self._wind_at_samples(self._time)
        self._step_paper(U, f3, z3, dt)
        self._dt_prev = dt
        self._time += dt
        self._pos_out = None
        self._rot_out = None
        self._fn = None
