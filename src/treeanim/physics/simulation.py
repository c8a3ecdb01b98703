"""The simulation's public façade (docs/design.md §9): one :class:`Simulation`, whose mechanics
come from a model in the registry :data:`MODELS`:

* ``"tree"`` (the default, :mod:`~treeanim.physics.tree_sim`): the whole tree as one structure
  of beam-theory joints, solved implicitly by articulated-body sweeps, real air, leaves that
  reconfigure on their petioles (docs/design.md §12);
* ``"paper"`` (:mod:`~treeanim.physics.paper_sim`): Hu, Chiba & He (2012) exactly — independent
  curved beams driven by modal oscillators (Eqs. 1–12, 19–22).

The façade validates every input at the boundary (one clear ``ValueError`` line, the state
unchanged) and hands the rest to the model.
"""

from __future__ import annotations

import numbers

import numpy as np

from ..model.scene import object_trees
from ..model.tree import Tree
from ..validate import finite_float, finite_vector3, float_within, object_index
from .lod import check_levels
from .paper_sim import MAX_FREQUENCY, MAX_PULL, MAX_STEP, MAX_ZETA, PaperSim
from .tree_sim import GRAB_STIFFNESS, MAX_GRAB_STIFFNESS, TreeSim
from .wind import fit_to_tree

__all__ = ["Simulation", "MODELS", "MAX_PULL", "MAX_STEP", "MAX_FREQUENCY", "MAX_ZETA"]

#: The models a Simulation can run, by name: each keeps its own static model and state and
#: steps it (``step(dt)``, ``get_state()``/``set_state()``, the pose, pulls).
MODELS = {"tree": TreeSim, "paper": PaperSim}

# What belongs to one model only, and why the other has none.
_PAPER_ONLY = {
    "modes": "the tree model's frequencies come from beam theory",
    "modal": "the tree model's frequencies come from beam theory",
    "integrator": "the tree model is one implicit step",
    "coupling": "the tree model is one structure",
    "loads": "the tree model has no modal loads",
    "modal_loads": "the tree model has no modal loads",
    "compliance": "the tree model's grab is solved inside its step (drag)",
}
_TREE_ONLY = {
    "energy": "the paper's oscillators have no mechanical energy",
    "structure": "the paper's objects are independent",
    "point_position": "the paper's model has no drag",
    "active_dof": "the paper's objects are independent",
}


class Simulation:
    """A tree animated by wind, pulls and drags.

    Parameters
    ----------
    tree : Tree
        The tree (a preset, a TreeQSM scan, or any Tree from :func:`treeanim.model.build.assemble`).
    wind : WindField or None
        Anything with ``sample(points (K, 3), t) -> (K, 3)`` m/s. A wind still on its default
        bounds is fitted to the tree's rest box. None: calm.
    season : float
        0 (summer) … 1 (winter): drops leaves (and, for the paper, interpolates its modal ranges).
    seed : int
        Seed of the model's random numbers (the paper's Eqs. 20–22; the leaves' flutter and fall).
    model : {'tree', 'paper'}
        The mechanics (see the module; None means 'tree'). Settable as ``model`` (restarts
        from rest).
    integrator, coupling, modes :
        The paper model's options (:class:`~treeanim.physics.paper_sim.PaperSim`).

    Attributes
    ----------
    positions : (N, 3) float, read-only
        Posed world node positions.
    rotations : (N, 3, 3) float, read-only
        World rotation *relative to rest* of the segment leaving node j (an object's tip: its
        last segment's). A rest point x rigidly on node j is drawn at
        ``positions[j] + rotations[j] @ (x − rest_positions[j])``.
    present, shown : (M,) bool
        Objects on the tree; objects to draw (the tree model adds the leaves that fell while it
        ran, which tumble down and rest on the ground).
    state : object with ``copy()``
        A copy of everything that changes over time; assigning one taken from this simulation
        restores it exactly.
    energy : float
        (tree) Kinetic plus elastic energy (J): in calm air it falls (see docs/design.md §12).
    """

    def __init__(self, tree: Tree, wind=None, season: float = 0.0, seed: int = 0, model: str | None = None,
                 integrator: str = "exact", coupling: bool = True, modes: str | None = None):
        if not isinstance(tree, Tree):
            raise ValueError(f"tree must be a treeanim Tree, got {type(tree).__name__}")
        if isinstance(seed, bool) or not isinstance(seed, numbers.Integral) or seed < 0:
            raise ValueError(f"seed must be a non-negative integer, got {seed!r}")
        self._tree = tree
        self._seed = int(seed)
        self._paper_opts = {"integrator": integrator, "coupling": coupling, "modes": modes}
        self._model = self._check_model("tree" if model is None else model)
        self._impl = self._make(self._model, wind, self._check_season(season), tree.physics)

    def _make(self, model: str, wind, season: float, physics):
        opts = self._paper_opts if model == "paper" else {}
        impl = MODELS[model](self._tree, None, season=season, seed=self._seed, **opts)
        if physics is not self._tree.physics:
            impl.physics = physics
        self._fit_wind(wind)
        impl.wind = wind
        return impl

    # ------------------------------------------------------------------ validation
    @staticmethod
    def _check_model(name) -> str:
        if name not in MODELS:
            raise ValueError(f"model must be one of {tuple(MODELS)}, got {name!r}")
        return str(name)

    @staticmethod
    def _check_season(season) -> float:
        return float_within("season", season, 0.0, 1.0)

    def _check_object(self, i) -> int:
        return object_index(i, self._tree.n_objects)

    def _fit_wind(self, wind) -> None:
        """Check ``wind`` and fit one still on its default bounds to the tree's rest box."""
        if wind is None:
            return
        if not callable(getattr(wind, "sample", None)):
            raise ValueError(f"wind must have a sample(points, t) method, got {type(wind).__name__}")
        fit_to_tree(wind, self._tree.rest_positions)

    # ------------------------------------------------------------------ the model
    @property
    def model(self) -> str:
        """'tree' or 'paper' (settable: restarts from rest, keeping time, season, physics and wind)."""
        return self._model

    @model.setter
    def model(self, name: str) -> None:
        name = self._check_model(name)
        if name == self._model:
            return
        old = self._impl
        for k in ("integrator", "coupling", "modal"):
            if hasattr(old, k):
                self._paper_opts["modes" if k == "modal" else k] = getattr(old, k)
        impl = self._make(name, old.wind, old.season, old.physics)
        if old.time:
            impl.set_state(_shifted(impl.get_state(), old.time))
        self._impl, self._model = impl, name

    def __getattr__(self, name):
        # the paper's own options and readings, on the paper model only
        if name in _PAPER_ONLY or name in _TREE_ONLY:
            impl = self.__dict__.get("_impl")
            if impl is not None and hasattr(type(impl), name):
                return getattr(impl, name)
            why = _PAPER_ONLY.get(name) or _TREE_ONLY[name]
            other = "paper" if name in _PAPER_ONLY else "tree"
            raise AttributeError(f"{name!r} belongs to model={other!r} ({why})")
        raise AttributeError(f"'Simulation' object has no attribute {name!r}")

    def __setattr__(self, name, value):
        if name in ("modes", "modal", "integrator", "coupling"):
            if self._model != "paper":
                raise AttributeError(f"{name!r} belongs to model='paper' ({_PAPER_ONLY[name]})")
            setattr(self._impl, name, value)
            return
        super().__setattr__(name, value)

    @property
    def tree(self) -> Tree:
        """The simulated tree."""
        return self._tree

    @property
    def seed(self) -> int:
        """The seed."""
        return self._seed

    @property
    def time(self) -> float:
        """Simulated time (s)."""
        return self._impl.time

    @property
    def rest_positions(self) -> np.ndarray:
        """(N, 3) rest node positions."""
        return self._tree.rest_positions

    @property
    def season(self) -> float:
        """0 (summer) … 1 (winter) (settable)."""
        return self._impl.season

    @season.setter
    def season(self, value) -> None:
        self._impl.season = self._check_season(value)

    @property
    def physics(self):
        """The PhysicsParams (settable, checked; re-derives what depends on them)."""
        return self._impl.physics

    @physics.setter
    def physics(self, params) -> None:
        self._impl.physics = params

    @property
    def wind(self):
        """The wind field or None (settable; a wind on its default bounds is fitted to the tree)."""
        return self._impl.wind

    @wind.setter
    def wind(self, wind) -> None:
        self._fit_wind(wind)
        self._impl.wind = wind

    @property
    def present(self) -> np.ndarray:
        """(M,) bool: objects on the tree at the current season."""
        return self._impl.present

    @property
    def present_nodes(self) -> np.ndarray:
        """(N,) bool: nodes of the present objects."""
        return np.repeat(self._impl.present, self._tree.object_count)

    @property
    def shown(self) -> np.ndarray:
        """(M,) bool: objects to draw."""
        return self._impl.shown

    @property
    def positions(self) -> np.ndarray:
        """(N, 3) posed world node positions (read-only; an array you keep never changes)."""
        return self._impl.positions

    @property
    def rotations(self) -> np.ndarray:
        """(N, 3, 3) world rotations relative to rest (read-only; see the class)."""
        return self._impl.rotations

    @property
    def state(self):
        """A copy of the time-varying state (assign one taken from this simulation to restore it)."""
        return self._impl.get_state()

    @state.setter
    def state(self, st) -> None:
        self._impl.set_state(st)

    # ------------------------------------------------------------------ stepping
    def step(self, dt: float) -> None:
        """Advance by ``dt`` seconds, in one step whatever its length.

        Parameters
        ----------
        dt : float
            > 0 and at most :data:`MAX_STEP`. The tree model is implicit (stable at any step);
            the paper's oscillators are integrated exactly.

        Raises
        ------
        ValueError
            ``dt`` out of range, invalid paper modes, or a wind whose ``sample`` fails or returns
            the wrong shape or non-finite values. The state is then unchanged.
        """
        dt = finite_float("dt", dt)
        if not 0 < dt <= MAX_STEP:
            raise ValueError(f"dt must be > 0 and at most {MAX_STEP:g} s, got {dt!r}")
        self._impl.step(dt)

    def reset(self) -> None:
        """Back to rest at time 0, nothing held."""
        self._impl.reset()

    # ------------------------------------------------------------------ levels of detail
    def set_detail(self, levels) -> None:
        """Simulate each tree of a scene at a level of detail (tree model; docs/design.md §17).

        Parameters
        ----------
        levels : int or sequence of int
            One per tree (or one for all): 0 everything; 1 the leaves and twigs ride rigidly;
            2 only the trunk and limbs sway (a grass blade, as at 1, on its base joint); 3 the
            tree stands still
            (:data:`~treeanim.physics.lod.MAX_DETAIL`). A tree holding a pull or a drag stays at
            0. A switch moves no node: what freezes keeps its shape on its parent, what thaws
            starts from its rigid ride. :func:`~treeanim.physics.lod.choose_detail` picks levels
            from a camera.

        Raises
        ------
        ValueError
            Not one integer in 0..3 per tree, or the paper model.
        """
        n = int(object_trees(self._tree).max(initial=0)) + 1
        levels = check_levels(levels, n)
        if self._model != "tree":
            raise ValueError("detail levels need model='tree' (the paper's objects are independent)")
        self._impl.set_detail(levels)

    @property
    def detail(self) -> np.ndarray:
        """(T,) int: the level each tree is stepped at (all 0 on the paper's model)."""
        d = getattr(self._impl, "detail", None)
        return np.zeros(int(object_trees(self._tree).max(initial=0)) + 1, np.int64) if d is None else d

    # ------------------------------------------------------------------ interaction
    def pull(self, i: int, force_xyz) -> None:
        """Hold object ``i``'s tip with a constant world force (N), for traces (docs/design.md §8).

        Raises
        ------
        ValueError
            Unknown object, or a non-finite or malformed force, or one over :data:`MAX_PULL`.
        """
        i = self._check_object(i)
        f = finite_vector3("force_xyz", force_xyz)
        if float(np.max(np.abs(f))) > MAX_PULL or float(np.linalg.norm(f)) > MAX_PULL:
            raise ValueError(f"force_xyz must have a magnitude of at most {MAX_PULL:g} N, got {f.tolist()}")
        self._impl.pull(i, f)

    def drag(self, i: int, target, s: float = 1.0, stiffness: float = GRAB_STIFFNESS) -> None:
        """Drag the point at fraction ``s`` of object ``i``'s length (from its base) toward the
        world ``target`` through a stiff spring solved inside the step (tree model).

        The held shape is the static balance of the spring and the tree, the same at any frame
        rate; the spring bends no joint past what green wood bears and its target stays above
        the ground. Call again to move the target; :meth:`release` lets go. A leaf is held where
        it hangs from its twig. Several objects may be dragged at once (:attr:`drags`).

        Parameters
        ----------
        stiffness : float
            The spring in units of the tree's own stiffness at the point, in (0,
            :data:`~treeanim.physics.tree_sim.MAX_GRAB_STIFFNESS`]: a small drag moves the point
            stiffness / (1 + stiffness) of the way to the target (the default, 50: 98 %).

        Raises
        ------
        ValueError
            Unknown object, a non-finite target, ``s`` outside [0, 1], a stiffness out of
            range, or the paper model (whose objects are independent: use :meth:`pull`).
        """
        i = self._check_object(i)
        t = finite_vector3("target", target)
        s = finite_float("s", s)
        if not 0.0 <= s <= 1.0:
            raise ValueError(f"s must be in [0, 1], got {s!r}")
        stiffness = finite_float("stiffness", stiffness)
        if not 0.0 < stiffness <= MAX_GRAB_STIFFNESS:
            raise ValueError(f"stiffness must be in (0, {MAX_GRAB_STIFFNESS:g}], got {stiffness!r}")
        if self._model != "tree":
            raise ValueError("drag needs model='tree' (the paper's objects are independent: use pull)")
        self._impl.drag(i, t, s, stiffness)

    @property
    def drags(self) -> dict[int, tuple[np.ndarray, float]]:
        """The drags held (tree model): object → (target (3,), the spring in N/m); empty on
        the paper's model."""
        return getattr(self._impl, "drags", {})

    def release(self, i: int | None = None) -> None:
        """Let go of object ``i`` (its pull and drag), or of everything when None."""
        if i is not None:
            i = self._check_object(i)
        self._impl.release(i)

    @property
    def pulls(self) -> dict[int, np.ndarray]:
        """Held objects and their forces (a copy)."""
        return self._impl.pulls

    def tip_position(self, i: int) -> np.ndarray:
        """Posed world position of object ``i``'s tip node, (3,)."""
        return self.tip_positions([self._check_object(i)])[0]

    def tip_positions(self, objects) -> np.ndarray:
        """(K, 3) posed world positions of the tips of ``objects`` (indices, already checked)."""
        objs = np.asarray(objects, np.int64)
        if isinstance(self._impl, PaperSim):  # its tips need no whole pose
            return self._impl._tip_positions(objs)
        t = self._tree
        return self._impl.positions[t.object_start[objs] + t.object_count[objs] - 1].copy()


def _shifted(state, time: float):
    """``state`` with its clock set to ``time``."""
    st = state.copy()
    if hasattr(st, "tree"):
        st.tree.time = time
    else:
        st.time = time
    return st
