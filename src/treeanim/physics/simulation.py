"""The whole-tree simulation (docs/design.md §6): wind → loads → oscillators → bending → hierarchy."""

from __future__ import annotations

import math
import numbers
import sys
from collections.abc import Iterable

import numpy as np

from ..model.geometry import arc_length, lamina_frames, object_lengths, polygon_centroid, segment_lengths
from ..model.params import SCALAR_KEYS, SCALAR_MAX, PhysicsParams
from ..model.tree import KINDS, Tree
from .aero import Drag
from .bending import BendingPlan, rest_frames, saturating_twist
from .checks import finite_float, finite_vector3
from .falling import FallingLeaves
from .hierarchy import CompositionPlan
from .leaves import LeafTwist
from .loadpath import LoadPath
from .modal import ModalDraws, ModalParameters, derive_modes, mean_diameters
from .oscillator import euler_step, exact_coefficients, exact_step
from .physical import MODAL_MODELS, physical_modes
from .rotation import Workspace, matrix_to_quat, qrot
from .wind import DEFAULT_BOUNDS

__all__ = ["Simulation", "trace_tips", "INTEGRATORS", "MAX_PULL", "MAX_STEP", "MAX_FREQUENCY", "MAX_ZETA",
           "MAX_TRACE_VALUES"]

#: Oscillator integrators (see :mod:`treeanim.physics.oscillator`).
INTEGRATORS = ("exact", "euler")

#: Time constant (s) of the low-pass filter on base accelerations (base excitation). It keeps
#: the finite-difference acceleration finite and smooth at any dt and delays it by ~10 ms.
ACCEL_TAU = 0.01

#: E (Pa) that shapes a branch's stiffness along its length before :meth:`LoadPath.tune` sets
#: its magnitude from the branch's frequency and mass (any value gives the same tree).
NOMINAL_WOOD_MODULUS = 6e9

#: Largest pull force accepted (N): far beyond any hand on a tree (the bending stays finite
#: and keeps lengths far above it; the cap keeps absurd inputs out).
MAX_PULL = 1e9
#: The longest step (s): any shorter one is stable; far longer ones overflow the oscillators'
#: coefficients (and no animation steps by years).
MAX_STEP = 1e6
#: The highest modal frequency (Hz) and damping ratio accepted: far beyond any plant (and any
#: step rate), small enough that (2πf)² and 2ζω stay finite.
MAX_FREQUENCY = 1e4
MAX_ZETA = 1e3
#: Velocities and accelerations are differences over a step of at least this (s): over a
#: shorter one (a step of 1e-320 s) the change in position is rounding noise.
MIN_RATE_STEP = 1e-6

#: Largest number of floats :func:`trace_tips` records ((steps + 1) × (3·objects + 1)),
#: about 1 GB of float64.
MAX_TRACE_VALUES = 125_000_000


def _check_params(p: PhysicsParams, kinds: Iterable[str]) -> None:
    """Raise ValueError naming the field if ``p`` cannot drive a simulation of these kinds."""
    if not isinstance(p, PhysicsParams):
        raise ValueError(f"physics must be a PhysicsParams, got {type(p).__name__}")
    positive = ("ei_max", "wood_density", "leaf_density", "lamina_thickness",
                "leaf_youngs_modulus", "blade_youngs_modulus", "air_density", "reconfiguration_speed",
                "wood_youngs_modulus")
    for name in SCALAR_KEYS:
        x = finite_float(f"physics.{name}", getattr(p, name))
        if not (x > 0 if name in positive else x >= 0) or x > SCALAR_MAX[name]:
            raise ValueError(f"physics.{name} must be {'>' if name in positive else '>='} 0 and at most "
                             f"{SCALAR_MAX[name]:g}, got {x!r}")
    for season in ("summer", "winter"):
        sm = getattr(p, season)
        for kind in kinds:
            r = sm.of(kind)
            if r is None:
                if getattr(p, "winter" if season == "summer" else "summer").of(kind) is None:
                    raise ValueError(f"physics: no f/zeta range for kind {kind!r}, which the tree has")
                continue
            for i in (0, 1):
                f = finite_float(f"physics.{season}.{kind}.f", r.f[i])
                z = finite_float(f"physics.{season}.{kind}.zeta", r.zeta[i])
                if f <= 0:
                    raise ValueError(f"physics.{season}.{kind}.f must be > 0, got {r.f!r}")
                if z < 0:
                    raise ValueError(f"physics.{season}.{kind}.zeta must be >= 0, got {r.zeta!r}")


class Simulation:
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
        Base excitation in the paper's model: every object also feels −(acceleration of its
        base node) × its mass, so a swinging trunk shakes its twigs. False restores the paper's
        independent objects. The load path always couples (its loads go down the tree, so the
        motion must come back up: one without the other feeds energy into a gusty crown).
    load_path : bool
        True (default): the tree is one structure (docs/design.md §12, :mod:`~treeanim.physics.loadpath`):
        every object carries its children's loads down to the trunk, drag is quadratic in the
        air-relative wind with foliage reconfiguration (:mod:`~treeanim.physics.aero`), joints
        are as stiff as a tapered cantilever of the preset's Young's modulus, and pulls build
        up critically damped. False: the paper's model exactly (each object feels only the
        linear load on its own area), as the notes below describe.
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
        Objects to draw: those present plus, with the load path, the leaves that fell while
        the simulation ran — they tumble down and lie on the ground (:mod:`.falling`), posed in
        ``positions`` and ``rotations``. The paper's model (``load_path=False``) drops them
        out of sight, as ``present``.
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
    """

    def __init__(self, tree: Tree, wind=None, season: float = 0.0, seed: int = 0,
                 integrator: str = "exact", coupling: bool = True, load_path: bool = True,
                 modes: str | None = None):
        if not isinstance(tree, Tree):
            raise ValueError(f"tree must be a treeanim Tree, got {type(tree).__name__}")
        if isinstance(seed, bool) or not isinstance(seed, numbers.Integral) or seed < 0:
            raise ValueError(f"seed must be a non-negative integer, got {seed!r}")
        self._tree = tree
        self._seed = int(seed)
        self._integrator = self._check_integrator(integrator)
        self._coupling = bool(coupling)
        self._load_path = bool(load_path)
        self._modal = self._check_modal(tree.modes if modes is None else modes)
        season = self._check_season(season)
        kinds = [k for k in KINDS if np.any(tree.kind == k)]
        self._kinds = kinds
        _check_params(tree.physics, kinds)

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
        self._coef_cache: dict[float, tuple] = {}
        self._wind = None
        self.wind = wind
        self.reset()

    # ------------------------------------------------------------------ set-up
    def _geometry(self) -> None:
        """Per-object rest frames, lever arms, areas and volumes (fixed for the tree)."""
        tree = self._tree
        X = np.asarray(tree.rest_positions, float)
        start = np.asarray(tree.object_start)
        count = np.asarray(tree.object_count)
        tip = start + count - 1
        M = self._M
        frames = rest_frames(tree)  # (M, 3, 3): columns u, v, w
        u, v, w = frames[:, :, 0], frames[:, :, 1], frames[:, :, 2]
        self._u, self._v, self._w = u.T.copy(), v.T.copy(), w.T.copy()
        self._bplan = BendingPlan(tree, frames)
        self._cplan = CompositionPlan(tree, self._bplan, matrix_to_quat(frames))

        kind = tree.kind
        leaf = kind == "leaf"
        length = object_lengths(tree)
        dmean = mean_diameters(tree)
        p0pn = X[tip] - X[start]
        r = np.einsum("ij,ij->i", u, p0pn)  # Eq. 3: r = u · P0Pn
        lam_area = np.zeros(M)
        load_point = X[tip].copy()  # where each object's own load acts (load path)
        if tree.lamina is not None and np.any(leaf):
            leaves = np.flatnonzero(leaf)
            unit_area = float(tree.lamina.area)
            cx, cy = polygon_centroid(tree.lamina.outline)
            L = np.asarray(tree.lamina_length, float)[leaves, None]
            lam_area[leaves] = unit_area * L[:, 0] ** 2
            # The lamina sits on the petiole's tip, in the frame the mesh and picking use.
            tipn, lu, lv, _ = lamina_frames(tree, leaves)
            centroid = X[tipn] + L * (cx * lu + cy * lv)
            r[leaves] = np.linalg.norm(centroid - X[start[leaves]], axis=1)
            load_point[leaves] = centroid
        self._lever = r
        self._area = length * dmean + lam_area
        # Volumes: tapered segments (frusta ≈ cylinders of the mean diameter).
        seg = segment_lengths(tree)
        dseg = 0.5 * (tree.node_diameter[1:] + tree.node_diameter[:-1])
        dseg = np.append(dseg, 0.0)
        self._round_volume = np.add.reduceat(0.25 * np.pi * dseg**2 * seg, start)
        self._flat_area = np.add.reduceat(dseg * seg, start)  # blades: width × length
        self._lam_area = lam_area
        self._nseg = (count - 1).astype(float)
        self._sample_node = start + count // 2  # the middle node
        self._sample_ofs = self._bplan.ofs_of_node[self._sample_node]
        self._tip_node = tip
        self._rest_P = X.T.copy()
        # Base excitation: unique attach nodes of the non-root objects.
        self._nonroot = np.flatnonzero(tree.parent >= 0)
        att = np.asarray(tree.attach_node)[self._nonroot]
        self._att_nodes, att_inv = np.unique(att, return_inverse=True)
        # Per object, its base's column in the acceleration array (roots: the zero column).
        self._att_col = np.full(M, len(self._att_nodes), np.int64)
        self._att_col[self._nonroot] = att_inv
        self._ws = Workspace()
        o = self._bplan.order
        self._neg_half_pi_over_n_ord = -0.5 * np.pi / self._nseg[o]
        self._rest_bounds = (X.min(axis=0), X.max(axis=0))
        # The load path (docs/design.md §12): its plan, the drag, and each object's true middle (half
        # its arc length, on segment j at fraction t) where it samples the wind.
        self._lp = LoadPath(tree, frames, self._bplan, load_point)
        self._drag = Drag(kind, np.where(leaf, lam_area, length * dmean))
        arc = arc_length(tree)
        half = 0.5 * length
        below = np.add.reduceat((arc <= np.repeat(half, count)).astype(np.int64), start)
        j = np.clip(below - 1, 0, count - 2)
        t = np.clip((half - arc[start + j]) / np.maximum(seg[start + j], 1e-300), 0.0, 1.0)
        self._mid_a = self._bplan.ofs_of_node[start + j]
        self._mid_b = self._bplan.ofs_of_node[start + j + 1]
        self._mid_t = t
        self._leaves = np.flatnonzero(leaf)
        self._leaf_tip_flat = self._bplan.flat_of_node[tip[leaf]]
        lp = self._lp
        self._leaf_twist = LeafTwist(np.searchsorted(self._leaves, lp.seg_obj[lp.leaf_seg]),
                                     np.asarray(tree.lamina_length, float)[self._leaves], self._seed)
        self._fallen = FallingLeaves(tree.object_start, tree.object_count, tree.rest_w, self._seed)

    def _derive_physics(self) -> None:
        """Stiffness, gains, masses and twist constants from ``self._physics``."""
        p = self._physics
        kind = self._tree.kind
        gain = np.select([kind == "branch", kind == "leaf"], [p.wind_gain_branch, p.wind_gain_leaf],
                         p.wind_gain_blade)
        self._gain_area = gain * self._area
        mass = np.where(kind == "branch", p.wood_density * self._round_volume, 0.0)
        mass = np.where(kind == "leaf", p.leaf_density * (self._round_volume + self._lam_area * p.lamina_thickness),
                        mass)
        mass = np.where(kind == "blade", p.leaf_density * self._flat_area * p.lamina_thickness, mass)
        self._mass = mass
        self._k = self._bplan.stiffness(p.ei_max, p.stiffness_exponent)
        # Eq. 11's c0, per unit of the object's root stiffness k₀ (see the class notes).
        c0 = np.where(kind == "leaf", p.leaf_twist_c0, p.twist_c0)
        k_root = np.empty(self._M)
        k_root[self._bplan.order] = self._k[0]
        self._c0k = c0 / np.maximum(k_root, 1e-300)
        self._c0k_ord = self._c0k[self._bplan.order]
        if self._load_path:
            self._derive_load_path()

    def _derive_load_path(self) -> None:
        """The load path's drag, stiffness shapes and masses (physics and present leaves)."""
        p = self._physics
        self._drag.derive(p, self._present)
        branch = self._tree.kind == "branch"
        E = np.select([branch, self._tree.kind == "leaf"], [NOMINAL_WOOD_MODULUS, p.leaf_youngs_modulus],
                      p.blade_youngs_modulus)
        self._lp.derive(E, p.stiffness_exponent, self._drag.half_rho_cda, self._drag.foliage,
                        self._mass * self._present, branch)
        self._mode_snap = None  # the branches' stiffness follows the modes: re-tune on the next step

    def _derive_modes(self) -> None:
        present = self._present if self._load_path else None  # Eq. 21 with the leaves still on
        m = derive_modes(self._tree, self._physics, self._season, self._draws, present)
        if self._modal == "physical":
            self._drag.derive(self._physics, self._present)
            m = physical_modes(self._tree, self._physics, m, self._mass * self._present, self._drag.half_rho_cda)
        if hasattr(self, "_modes"):
            # Keep the user's references valid: overwrite in place when possible.
            cur = self._modes
            if isinstance(cur.f, np.ndarray) and cur.f.shape == m.f.shape and cur.f.flags.writeable:
                cur.f[...] = m.f
            else:
                cur.f = m.f
            if isinstance(cur.zeta, np.ndarray) and cur.zeta.shape == m.zeta.shape and cur.zeta.flags.writeable:
                cur.zeta[...] = m.zeta
            else:
                cur.zeta = m.zeta
        else:
            self._modes = m
        self._mode_snap = None  # force re-validation and new coefficients

    # ------------------------------------------------------------------ validation
    @staticmethod
    def _check_integrator(name) -> str:
        if name not in INTEGRATORS:
            raise ValueError(f"integrator must be one of {INTEGRATORS}, got {name!r}")
        return str(name)

    @staticmethod
    def _check_modal(name) -> str:
        if name not in MODAL_MODELS:
            raise ValueError(f"modes must be one of {MODAL_MODELS}, got {name!r}")
        return str(name)

    @staticmethod
    def _check_season(season) -> float:
        s = finite_float("season", season)
        if not 0.0 <= s <= 1.0:
            raise ValueError(f"season must be in [0, 1], got {season!r}")
        return s

    def _check_object(self, i) -> int:
        if isinstance(i, bool) or not isinstance(i, numbers.Integral):
            raise ValueError(f"object index i must be an integer, got {i!r}")
        if not 0 <= int(i) < self._M:
            raise ValueError(f"object index i={i} is out of range: the tree has {self._M} objects")
        return int(i)

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
        badf = ~((fa > 0) & (fa <= MAX_FREQUENCY))
        if badf.any():
            j, c = np.argwhere(badf)[0]
            raise ValueError(f"modes.f must be > 0 and at most {MAX_FREQUENCY:g} Hz: object {j} mode {'uvw'[c]} "
                             f"is {fa[j, c]!r}")
        badz = ~((za >= 0) & (za <= MAX_ZETA))
        if badz.any():
            j, c = np.argwhere(badz)[0]
            raise ValueError(f"modes.zeta must be in [0, {MAX_ZETA:g}]: object {j} mode {'uvw'[c]} is {za[j, c]!r}")
        f3, z3 = fa.T.copy(), za.T.copy()
        self._mode_snap = (f, z, fa.copy(), za.copy(), f3, z3)
        self._coef_cache.clear()
        w = 2.0 * np.pi * f3
        self._w2, self._two_zeta_w = w * w, 2.0 * z3 * w  # ω² and 2ζω of every mode
        if self._load_path:
            self._lp.tune(self._w2)
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
        if self._load_path:  # leaves dropped now fall from where they are; regrown ones are back
            fell = np.flatnonzero(self._present & ~present)
            if len(fell):
                self._fallen.detach(fell, self.positions, self.rotations)
            self._fallen.remove(np.flatnonzero(present & ~self._present))
            self._pos_out = self._rot_out = self._shown_out = None
        self._present = present
        self._derive_modes()
        if self._load_path:
            self._derive_load_path()

    @property
    def present(self) -> np.ndarray:
        """(M,) bool: objects shown at the current season (fallen leaves False)."""
        return self._present

    @property
    def shown(self) -> np.ndarray:
        """(M,) bool: objects to draw, the present ones and the fallen leaves (see the class)."""
        if not len(self._fallen):
            return self._present
        if self._shown_out is None:
            self._shown_out = self._present | self._fallen.shown(self._M)
            self._shown_out.setflags(write=False)
        return self._shown_out

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
        _check_params(params, self._kinds)
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

    @property
    def coupling(self) -> bool:
        """Whether base excitation is on (settable)."""
        return self._coupling

    @coupling.setter
    def coupling(self, on: bool) -> None:
        self._coupling = bool(on)

    @property
    def load_path(self) -> bool:
        """Whether the tree is one structure (docs/design.md §12) or the paper's independent objects
        (settable; switching restarts from rest, keeping time, season and physics)."""
        return self._load_path

    @load_path.setter
    def load_path(self, on: bool) -> None:
        on = bool(on)
        if on == self._load_path:
            return
        self._load_path = on
        if on:
            self._derive_load_path()
        self._derive_modes()
        time = self._time
        self.reset()
        self._time = time

    @property
    def wind(self):
        """The wind field or None (settable; a wind on its default bounds is fitted to the tree)."""
        return self._wind

    @wind.setter
    def wind(self, wind) -> None:
        if wind is not None:
            if not callable(getattr(wind, "sample", None)):
                raise ValueError(f"wind must have a sample(points, t) method, got {type(wind).__name__}")
            self._fit_wind(wind)
        self._wind = wind

    def _fit_wind(self, wind) -> None:
        """Fit a wind that has no bounds of its own (None or the default) to the rest box."""
        if not (hasattr(wind, "fit") or hasattr(wind, "bounds")):
            return  # a field that needs no bounds
        b = getattr(wind, "bounds", None)
        if b is not None:
            try:
                own = not np.allclose(np.asarray(b, float), DEFAULT_BOUNDS)
            except (TypeError, ValueError):
                own = True
            if own:
                return
        lo, hi = self._rest_bounds
        box = (tuple(map(float, lo)), tuple(map(float, hi)))
        if hasattr(wind, "fit"):
            wind.fit(box)
        else:
            wind.bounds = box

    @property
    def rest_positions(self) -> np.ndarray:
        """(N, 3) rest node positions (the tree's)."""
        return self._tree.rest_positions

    def _node_frames(self) -> np.ndarray:
        if self._fn is None:
            self._fn = self._cplan.node_frames(self._frame)
        return self._fn

    def _recycled(self, attr: str, shape: tuple[int, ...]) -> np.ndarray:
        """The array in ``attr`` if nobody outside holds it any more (so overwriting it is
        invisible), else a new one: outputs stay fresh arrays for whoever keeps them, without a
        new allocation (and its page faults) every frame for whoever does not."""
        old = getattr(self, attr)
        setattr(self, attr, None)
        if old is not None and old.shape == shape and sys.getrefcount(old) <= _UNSHARED_REFS:
            old.setflags(write=True)
            return old
        return np.empty(shape)

    @property
    def positions(self) -> np.ndarray:
        """(N, 3) deformed world node positions (read-only; built on first access after a step).

        An array you keep is never changed by later steps.
        """
        if self._pos_out is None:
            buf = self._recycled("_pos_buf", (self._N, 3))
            pos = self._cplan.positions(self._bplan.o, self._node_frames(), self._base, out=buf)
            self._fallen.pose(pos)
            pos.setflags(write=False)
            self._pos_out = self._pos_buf = pos
        return self._pos_out

    @property
    def rotations(self) -> np.ndarray:
        """(N, 3, 3) world rotations relative to rest of the segment leaving each node.

        See the class notes for the convention. Read-only; built on first access after a step.
        An array you keep is never changed by later steps.
        """
        if self._rot_out is None:
            buf = self._recycled("_rot_buf", (self._N, 3, 3))
            rot = self._cplan.rotations(self._bplan.q, self._node_frames(), out=buf)
            self._fallen.pose(None, rot)
            rot.setflags(write=False)
            self._rot_out = self._rot_buf = rot
        return self._rot_out

    @property
    def loads(self) -> np.ndarray:
        """(M, 3) the local loads L = (L_u, L_v, L_w) of the last step (N), a copy."""
        return self._L.T.copy()

    @property
    def modal_loads(self) -> np.ndarray:
        """(M, 3) the oscillator outputs L′ = (L′_u, L′_v, L′_w) (N; N·m for v), a copy."""
        return self._p.T.copy()

    @property
    def pulls(self) -> dict[int, np.ndarray]:
        """Held objects and their world forces (a copy)."""
        return {i: f.copy() for i, f in self._pulls.items()}

    def tip_position(self, i: int) -> np.ndarray:
        """Deformed world position of object ``i``'s tip node.

        Parameters
        ----------
        i : int
            Object index.

        Returns
        -------
        numpy.ndarray, (3,) float

        Raises
        ------
        ValueError
            Unknown object index.
        """
        i = self._check_object(i)
        return self._tip_positions(np.array([i]))[0]

    def _tip_positions(self, objs: np.ndarray) -> np.ndarray:
        """(K, 3) deformed tip positions of objects ``objs`` (no validation)."""
        o = self._bplan.o[:, self._bplan.ofs_of_node[self._tip_node[objs]]]
        return (self._base[:, objs] + qrot(self._frame[:, objs], o)).T

    def compliance(self, i: int, k: int, s: float, offset=(0.0, 0.0, 0.0)) -> float:
        """Metres a point of object ``i`` moves per newton of a force on it (small bends, rest
        pose), for a pull controller's spring.

        The point is carried by segment ``k`` at ``s`` (0 … 1) along it, plus ``offset`` (a
        point on a leaf's lamina lies beyond the petiole's tip). The paper's model sums Eq. 10's
        hinges; the load path scales the compliance 1/K at the object's load point by the
        cube of the point's share of the lever (a cantilever's x³ law).
        """
        i = self._check_object(int(i))
        tree = self._tree
        nodes = tree.object_nodes(i)
        X = tree.rest_positions[nodes]
        seg = np.diff(X, axis=0)
        anchor = X[k] + s * seg[k] + np.asarray(offset, float)
        if self._load_path:
            self._modes_arrays()  # the stiffness follows the modes
            share = np.linalg.norm(anchor - X[0]) / max(float(self._lp.lever0[i]), 1e-12)
            return float(min(share, 4.0) ** 3 / self._lp.K[i])
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
        self._g_prev = np.zeros((3, M))  # the oscillators' last inputs (load path)
        self._c_air = np.zeros(M)  # the air's damping of the last step (load path)
        self._sample_prev = self._sample_pos.copy()
        self._sample_vel = np.zeros((3, M))
        self._leaf_twist.reset()
        self._fallen.clear()
        self._shown_out = None
        self._spread = None  # the low-passed loads along the objects (load path)
        self._pulls.clear()
        self._pos_out = None
        self._rot_out = None
        self._fn = None

    def step(self, dt: float) -> None:
        """Advance the simulation by ``dt`` seconds (docs/design.md §6; §12 with the load path).

        One step is a pipeline of stages: wind → aerodynamic loads → (load path and)
        oscillators → bending → hierarchy.

        Parameters
        ----------
        dt : float
            Step length in seconds, > 0 and at most :data:`MAX_STEP`. Any such length is
            stable: the exact integrator has no step limit; Euler sub-steps (and clamps very
            long steps, see :mod:`treeanim.physics.oscillator`).

        Raises
        ------
        ValueError
            ``dt`` not in (0, MAX_STEP], invalid ``modes`` (f not in (0, MAX_FREQUENCY], ζ not
            in [0, MAX_ZETA], wrong shape), or a wind whose ``sample`` returns the wrong
            shape or non-finite values. The state is left unchanged.
        """
        dt = finite_float("dt", dt)
        if not 0 < dt <= MAX_STEP:
            raise ValueError(f"dt must be > 0 and at most {MAX_STEP:g} s, got {dt!r}")
        f3, z3 = self._modes_arrays()
        U = self._wind_at_samples(self._time)
        if self._load_path:
            self._step_load_path(U, f3, z3, dt)
            if len(self._fallen):
                self._fallen.step(self._wind_at_points(self._time), dt)
        else:
            self._step_paper(U, f3, z3, dt)
        self._dt_prev = dt
        self._time += dt
        self._pos_out = None
        self._rot_out = None
        self._fn = None

    # ------------------------------------------------------------------ stages
    def _wind_at_samples(self, t: float) -> np.ndarray | None:
        """Stage 1: the wind (M, 3) at every object's sample point (previous pose), or None."""
        if self._wind is None:
            return None
        pts = self._ws.get("pts", (self._M, 3))
        pts[...] = self._sample_pos.T
        U = np.asarray(self._wind.sample(pts, t), dtype=float)
        if U.shape != (self._M, 3):
            raise ValueError(f"wind.sample returned shape {U.shape}, expected {(self._M, 3)}")
        if not np.isfinite(U).all():
            raise ValueError("wind.sample returned non-finite velocities (NaN or inf)")
        return U

    def _wind_at_points(self, t: float):
        """``points (n, 3) -> (n, 3)`` the wind at time ``t`` (non-finite values zeroed), or None."""
        if self._wind is None:
            return None
        return lambda pts: np.nan_to_num(np.asarray(self._wind.sample(pts, t), float), posinf=0.0, neginf=0.0)

    def _oscillator_coefficients(self, f3: np.ndarray, z3: np.ndarray, dt: float) -> tuple:
        """The exact integrator's coefficients for ``dt`` (cached while the modes are unchanged)."""
        coef = self._coef_cache.get(dt)
        if coef is None:
            if len(self._coef_cache) > 8:
                self._coef_cache.clear()
            coef = self._coef_cache[dt] = exact_coefficients(f3, z3, dt)
        return coef

    def _step_paper(self, U, f3: np.ndarray, z3: np.ndarray, dt: float) -> None:
        """The paper's step (docs/design.md §6): linear loads on each object's own area, Eqs. 2–12."""
        M = self._M
        ws = self._ws
        mul = np.multiply
        # 2. World force on each object: wind (Eq. 19 × area × gain), pulls, base excitation.
        Fw = ws.get("Fw", (3, M))
        if U is not None:
            mul(U.T, self._gain_area, out=Fw)
        else:
            Fw.fill(0.0)
        for i, f in self._pulls.items():
            Fw[:, i] += f
        if self._coupling and len(self._nonroot):
            inertia = np.take(self._att_a, self._att_col, axis=1, out=ws.get("inertia", (3, M)))
            inertia *= self._mass
            Fw -= inertia
        # Local loads L = (U·u, U·v, U·w) in the previous-step frame, carried by the parent
        # (Eqs. 12, 19): the inverse of the object's frame applied to the world force.
        L = qrot(self._frame, Fw, conj=True, out=self._L, ws=ws)

        # 3. Oscillators (Eqs. 2–5), signed loads, unit static gain.
        g = ws.get("g", (3, M))
        g[0] = L[2]  # g_u = L_w
        mul(self._lever, L[2], out=g[1])  # g_v = r·L_w
        g[2] = L[0]  # g_w = L_u
        if self._integrator == "exact":
            exact_step(self._p, self._pd, g, self._oscillator_coefficients(f3, z3, dt))
        else:
            euler_step(self._p, self._pd, g, f3, z3, dt)
        if self._pulls:  # held objects sit at the static deflection of their load (§8)
            held = np.fromiter(self._pulls, dtype=np.int64)
            self._p[:, held] = g[:, held]
            self._pd[:, held] = 0.0

        # 4. Force in the local rest frame (Eq. 6): (L′_w, 0, L′_u); twist (Eq. 11).
        po = np.take(self._p, self._bplan.order, axis=1, out=ws.get("po", (3, M)))
        gamma = saturating_twist(po[1], self._c0k_ord, self._neg_half_pi_over_n_ord)  # Eq. 11
        # 5. Bend every object in its local rest frame (Eqs. 7–10).
        bp = self._bplan
        bp.bend(po[2], po[0], gamma, self._k, predict=self._predict(dt))
        self._compose()
        self._paper_base_motion(dt)

    def _predict(self, dt: float) -> float:
        """The bending solver's extrapolation ratio dt/dt_prev (0 on the first step)."""
        return 0.0 if self._dt_prev is None else min(dt / self._dt_prev, 2.0)

    def _compose(self) -> None:
        """Stage 6: compose the hierarchy (Eq. 12), then the objects' frames and sample points."""
        bp, ws, M = self._bplan, self._ws, self._M
        P = self._P
        self._cplan.compose_structural(bp.q, bp.o, self._Fw, P)  # Eq. 12
        self._cplan.object_frames(self._Fw, P, out=(self._frame, self._base))
        if self._load_path:  # the true middle: half the arc length along the bent object
            so = np.take(bp.o, self._mid_b, axis=1, out=ws.get("so", (3, M)))
            so -= np.take(bp.o, self._mid_a, axis=1, out=ws.get("so2", (3, M)))
            so *= self._mid_t
            so += np.take(bp.o, self._mid_a, axis=1, out=ws.get("so2", (3, M)))
        else:
            so = np.take(bp.o, self._sample_ofs, axis=1, out=ws.get("so", (3, M)))
        qrot(self._frame, so, out=self._sample_pos, ws=ws)
        self._sample_pos += self._base

    def _paper_base_motion(self, dt: float) -> None:
        """Base accelerations for the next step's excitation, low-passed (finite at any dt)."""
        if len(self._att_nodes):
            x = self._P[:, self._att_nodes]
            vel = (x - self._att_x) / max(dt, MIN_RATE_STEP)
            h = max(dt if self._dt_prev is None else 0.5 * (dt + self._dt_prev), MIN_RATE_STEP)
            a_raw = (vel - self._att_v) / h
            alpha = -math.expm1(-dt / ACCEL_TAU)
            acc = self._att_a[:, :-1]
            acc += alpha * (a_raw - acc)
            self._att_x = x
            self._att_v = vel

    def _step_load_path(self, U, f3: np.ndarray, z3: np.ndarray, dt: float) -> None:
        """The whole-tree step (docs/design.md §12): aerodynamic loads → load path with the
        oscillators (Eqs. 2–5) → bending (Eqs. 7–11 generalised) → hierarchy (Eq. 12)."""
        held = np.fromiter(self._pulls, dtype=np.int64)  # the objects being pulled
        F_own, c_air = self._aero_loads(U)
        F_pull = self._pull_loads(held)
        g_extra = self._base_excitation()
        p_free, pd_free, gain, gain_d = self._oscillator_response(f3, z3, dt, held)
        g = self._g_prev
        slots = self._lp.inward(F_own, F_pull, held, g_extra, (p_free, gain), g)
        self._advance(g, p_free, pd_free, gain, gain_d, c_air, dt, held)
        self._c_air = c_air
        self._L = g.copy()
        F_own, F_tip, dT, slots = self._distributed_loads(F_own, F_pull, slots, g - g_extra, dt)
        blocks, gamma = self._lp.segment_forces(F_own, F_tip, dT, self._p[1], slots)
        leaf = self._lp.leaf_seg  # leaves turn at a bounded speed, and flutter
        gamma[leaf] = self._leaf_twist.step(gamma[leaf], self._drag.leaf_speed, self._drag.leaf_incidence,
                                            self._physics.leaf_flutter, dt)
        self._bplan.bend(None, None, gamma, self._lp.k_blocks, predict=self._predict(dt), blocks=blocks)
        self._sample_prev[...] = self._sample_pos
        self._compose()
        self._sample_vel = (self._sample_pos - self._sample_prev) / max(dt, MIN_RATE_STEP)

    def _distributed_loads(self, F_own, F_pull, slots, E, dt) -> tuple[np.ndarray, ...]:
        """Stage 4 (load path): the loads along each object, low-passed at its own frequency.

        An object's oscillators filter the equivalent load at its load point (E′); how the load
        spreads along it would otherwise follow the wind and its children from step to step
        with no inertia at all, and a lamina's force, which turns with the lamina, would flip
        the twig it bends from side to side within one step. So the own loads, pulls and
        children's loads (``slots``) reach the segments through a first-order low-pass at the
        object's bending frequency, and the load point takes the rest, E′ − Ē, with Ē the
        same low-pass of the static equivalent load E (E′ the oscillators' output, advanced):
        the segments still carry E′ in all.

        Returns (own loads, load-point loads, torsion excess, slots) for
        :meth:`LoadPath.segment_forces`.
        """
        a = -np.expm1(-dt * np.sqrt(np.sqrt(self._w2[0] * self._w2[2])))
        new = (F_own, F_pull, slots, E)
        if self._spread is None:
            self._spread = [v.copy() for v in new]
        else:
            for bar, v, alpha in zip(self._spread, new, (a, a, a[self._lp.slot_owner], a)):
                bar += alpha * (v - bar)
        F_bar, P_bar, S_bar, E_bar = self._spread
        dE = self._p - E_bar  # E′ − Ē, rows of the modes u, v, w
        F_tip = P_bar.copy()
        F_tip[0] += dE[2]  # mode w bends along u, mode u along w
        F_tip[2] += dE[0]
        return F_bar, F_tip, dE[1], S_bar

    def _aero_loads(self, U) -> tuple[np.ndarray, np.ndarray]:
        """Stage 2 (load path): the drag, local, and the air's damping on each object's mode.

        The drag of the air-relative wind, F(U − v), is split as F(U) − c·v: the drag of the
        wind itself, here, and the damping c = ∂F/∂v = ρ C A |U − v| (2 × ½ρCA|U_rel|, on the
        object's mode and, through Q, on what it carries), which the oscillators take
        implicitly (:meth:`_advance`) — stable however light a twig and strong the wind.
        """
        lam_q = np.take(self._bplan.q, self._leaf_tip_flat, axis=1)
        if U is None:
            F, rel = np.zeros((3, self._M)), -self._sample_vel
        else:
            F = self._drag.loads(U.T, self._frame, lam_q)
            rel = U.T - self._sample_vel
        speed = np.sqrt(np.einsum("ij,ij->j", rel, rel))
        lp = self._lp
        c_air = lp.Q_foliage * self._drag.reconfigured(speed)
        c_air += lp.Q_wood
        c_air *= 2.0 * speed
        return F, c_air

    def _pull_loads(self, held: np.ndarray) -> np.ndarray:
        """(3, M) the pulls at the objects' load points ``held``, local (carried frames)."""
        F = np.zeros((3, self._M))
        if len(held):
            world = np.array([self._pulls[i] for i in held]).T
            F[:, held] = qrot(self._frame[:, held], world, conj=True)
        return F

    def _base_excitation(self) -> np.ndarray:
        """(3, M) oscillator inputs −m_eff·a of the moving bases (always on in the load path:
        loads go down the tree and motion comes back up, or a gust sets it ringing), with the
        effective mass m_eff = K/(2πf)² of each bending mode (a branch's modal mass, since
        its K follows from it; for leaves and blades at most their modal mass)."""
        g = np.zeros((3, self._M))
        w2 = self._w2
        # p̈ = ω²(g − p) − (2ζω + ω²c/K) ṗ: Eq. 2 in load units, with the air's damping c of
        # the last step (in a gale it holds a light twig back far more than its own ζ does)
        acc = self._g_prev - self._p
        acc *= w2
        damp = self._air_damping(self._c_air)
        damp += self._two_zeta_w
        acc -= damp * self._pd
        a_u, a_w = self._lp.base_acceleration(acc)
        K = self._lp.K
        m = self._lp.m_modal
        g[0] = np.minimum(K / w2[0], m)
        g[0] *= -a_w  # mode u moves along w
        g[2] = np.minimum(K / w2[2], m)
        g[2] *= -a_u
        return g

    def _oscillator_response(self, f3: np.ndarray, z3: np.ndarray, dt: float,
                             held: np.ndarray) -> tuple[np.ndarray, ...]:
        """Stage 3 (load path): the oscillators over the step (Eqs. 2–5) are linear in their
        input g: L′ = p_free + c·g, L̇′ = pd_free + c_d·g. The ``held`` objects are critically
        damped (§8). Returns (p_free, pd_free, c, c_d), each (3, M)."""

        def exact(coef, p, pd):  # y(dt) = A·y + B·ẏ, ẏ(dt) = C·y + D·ẏ with y = p − g
            A, B, C, D = coef
            return A * p + B * pd, C * p + D * pd, 1.0 - A, -C

        p, pd = self._p, self._pd
        if self._integrator == "exact":
            out = exact(self._oscillator_coefficients(f3, z3, dt), p, pd)
        else:  # the free response, then the response to a unit input from rest
            out = p.copy(), pd.copy(), np.zeros_like(p), np.zeros_like(pd)
            euler_step(out[0], out[1], np.zeros_like(p), f3, z3, dt)
            euler_step(out[2], out[3], np.ones_like(p), f3, z3, dt)
        if len(held):
            zc = np.maximum(z3[:, held], 1.0)
            zc[1] = z3[1, held]
            for arr, val in zip(out, exact(exact_coefficients(f3[:, held], zc, dt), p[:, held], pd[:, held])):
                arr[:, held] = val
        return out

    def _air_damping(self, c_air: np.ndarray) -> np.ndarray:
        """(3, M) the air's damping rate ω²c/K on every mode (the bending modes only: row v 0)."""
        damp = self._w2 * (c_air / self._lp.K)
        damp[1] = 0.0
        return damp

    def _advance(self, g, p_free, pd_free, gain, gain_d, c_air, dt, held) -> None:
        """Set the oscillators' state after the step under the input g, with the air's damping
        split off and implicit: ṗ /= 1 + ω²c·dt/K (stable however light a twig)."""
        np.multiply(gain, g, out=self._p)
        self._p += p_free
        np.multiply(gain_d, g, out=self._pd)
        self._pd += pd_free
        damp = self._air_damping(c_air)
        damp[:, held] = 0.0  # a held object approaches its pull critically damped, as it is
        damp *= dt
        damp += 1.0
        self._pd /= damp


def _unshared_refs() -> int:
    """sys.getrefcount of an array held only by an attribute, seen as in _recycled (measured,
    since the count of a lone object differs between Python versions)."""

    class Holder:
        pass

    h = Holder()
    h.a = np.empty(1)
    old = getattr(h, "a")
    h.a = None
    return sys.getrefcount(old)


_UNSHARED_REFS = _unshared_refs()


def trace_tips(sim: Simulation, objects, duration: float, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """Step ``sim`` for ``duration`` seconds and record the tip positions of ``objects``.

    Parameters
    ----------
    sim : Simulation
    objects : int or sequence of int
        Object indices (integers in range).
    duration : float
        Seconds to simulate (> 0, finite).
    dt : float
        Step (> 0, finite).

    Returns
    -------
    times : (T + 1,) float
        Sample times, starting at the current time.
    tips : (T + 1, K, 3) float
        Tip positions (the first row before any step).

    Raises
    ------
    ValueError
        A non-integer or out-of-range object index, a non-finite or non-positive
        ``duration`` or ``dt``, or more than :data:`MAX_TRACE_VALUES` values to record
        (T = round(duration / dt) steps). Nothing is stepped then.
    """
    objs = np.atleast_1d(np.asarray(objects, dtype=object))
    if objs.ndim != 1:
        raise ValueError(f"objects must be an index or a flat sequence of indices, got shape {objs.shape}")
    try:
        objs = np.array([sim._check_object(o) for o in objs], dtype=np.int64)
    except ValueError as e:
        raise ValueError(f"objects: {e}") from None
    duration = finite_float("duration", duration)
    dt = finite_float("dt", dt)
    if duration <= 0:
        raise ValueError(f"duration must be > 0, got {duration!r}")
    if dt <= 0:
        raise ValueError(f"dt must be > 0, got {dt!r}")
    steps = duration / dt
    per_row = 3 * len(objs) + 1
    if not steps * per_row <= MAX_TRACE_VALUES:  # also catches steps = inf
        raise ValueError(
            f"duration / dt = {steps:.3g} steps is too many to record for {len(objs)} object(s) "
            f"(at most {MAX_TRACE_VALUES} values); use a shorter duration or a longer dt")
    n = int(round(steps))
    out = np.empty((n + 1, len(objs), 3))
    times = np.empty(n + 1)
    out[0] = sim._tip_positions(objs)
    times[0] = sim.time
    for k in range(n):
        sim.step(dt)
        out[k + 1] = sim._tip_positions(objs)
        times[k + 1] = sim.time
    return times, out
