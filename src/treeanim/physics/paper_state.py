"""Snapshots of the paper's model (:class:`PaperState`), taken and restored by the
:class:`Snapshot` mixin of :class:`~treeanim.physics.paper_sim.PaperSim`."""

from __future__ import annotations

import dataclasses

import numpy as np

from ..validate import finite_float, finite_vector3

__all__ = ["PaperState", "Snapshot"]

#: PaperSim's time-varying arrays (attribute ``_name``) and its bending plan's (``BendingPlan.name``).
_SIM_ARRAYS = ("p", "pd", "L", "P", "Fw", "frame", "base", "sample_pos", "att_x", "att_v", "att_a")
_BEND_ARRAYS = ("q", "o", "phi", "rho", "rho_old", "rho_start")


@dataclasses.dataclass
class PaperState:
    """A snapshot of a :class:`PaperSim`'s motion (:meth:`PaperSim.get_state`).

    Everything a step reads or writes that changes over time; not the settings (tree, wind,
    season, physics, modes, modal model, integrator, coupling), which stay the simulation's.

    Attributes
    ----------
    time : float
        Simulated time (s).
    dt_prev : float or None
        The last step's length (None before the first step): the base accelerations'
        difference and the bending solver's extrapolation read it.
    p, pd, L : (3, M) float
        The oscillators' outputs L′ and their rates (Eq. 5), and the last local loads.
    bend_q, bend_o : (4, S + 1), (3, S + 1) float
        The bending's segment rotations and bent offsets (:class:`~treeanim.physics.bending.BendingPlan`).
    bend_phi, bend_rho, bend_rho_old, bend_rho_start : (S,) float
        Bend angles and the fractions φ/θ₀ the next solve starts from.
    P, Fw : (3, N), (4, N + 1) float
        World positions and segment frames of the structural nodes (Eq. 12).
    frame, base, sample_pos : (4, M), (3, M), (3, M) float
        Each object's carried frame, base and wind sample point.
    att_x, att_v, att_a : (3, U), (3, U), (3, U + 1) float
        Position, velocity and low-passed acceleration of the attach nodes (base excitation).
    pulls : dict of int to (3,) float
        Held objects and their world forces.
    """

    time: float
    dt_prev: float | None
    p: np.ndarray
    pd: np.ndarray
    L: np.ndarray
    P: np.ndarray
    Fw: np.ndarray
    frame: np.ndarray
    base: np.ndarray
    sample_pos: np.ndarray
    att_x: np.ndarray
    att_v: np.ndarray
    att_a: np.ndarray
    bend_q: np.ndarray
    bend_o: np.ndarray
    bend_phi: np.ndarray
    bend_rho: np.ndarray
    bend_rho_old: np.ndarray
    bend_rho_start: np.ndarray
    pulls: dict[int, np.ndarray]

    def copy(self) -> PaperState:
        """A deep copy (no array shared with this one)."""
        return PaperState(**{f.name: _copied(getattr(self, f.name)) for f in dataclasses.fields(self)})


def _copied(x):
    """A deep copy of a state field: arrays and dicts of arrays copied, scalars as they are."""
    if isinstance(x, np.ndarray):
        return x.copy()
    if isinstance(x, dict):
        return {int(i): np.array(f, dtype=float) for i, f in x.items()}
    return x


class Snapshot:
    """``get_state`` / ``set_state`` of the paper's model."""

    def get_state(self) -> PaperState:
        """A snapshot of the motion, to come back to with :meth:`set_state`.

        Returns
        -------
        PaperState
            Deep copies of everything that changes from step to step (time, oscillators,
            bending, pose, base motion, pulls); later steps leave it as it is.
        """
        bp = self._bplan
        return PaperState(time=self._time, dt_prev=self._dt_prev, pulls=_copied(self._pulls),
                          **{n: getattr(self, "_" + n).copy() for n in _SIM_ARRAYS},
                          **{"bend_" + n: getattr(bp, n).copy() for n in _BEND_ARRAYS})

    def set_state(self, state: PaperState) -> None:
        """Restore a snapshot of :meth:`get_state`: the next steps are bit for bit those that
        followed when it was taken (given the same settings, wind and inputs).

        The settings (wind, season, physics, modes, integrator, coupling) are not part of the
        snapshot and stay as they are. ``state`` itself is copied, so it can be restored again.

        Parameters
        ----------
        state : PaperState
            From this simulation or another of the same tree.

        Raises
        ------
        ValueError
            Not a PaperState, or one of another tree (array shapes differ), or a malformed
            time, step or pull (the simulation unchanged).
        """
        if not isinstance(state, PaperState):
            raise ValueError(f"state must be a PaperState from get_state(), got {type(state).__name__}")
        bp = self._bplan
        new = {}
        for owner, names, prefix in ((self, _SIM_ARRAYS, "_"), (bp, _BEND_ARRAYS, "")):
            for n in names:
                field = n if owner is self else "bend_" + n
                cur = getattr(owner, prefix + n)
                try:
                    a = np.array(getattr(state, field), dtype=float)
                except (TypeError, ValueError):
                    raise ValueError(f"state.{field} must be an array of numbers") from None
                if a.shape != cur.shape:
                    raise ValueError(f"state.{field} has shape {a.shape}, expected {cur.shape} "
                                     f"(a state of another tree?)")
                new[owner, prefix + n] = a
        time = finite_float("state.time", state.time)
        dt_prev = None if state.dt_prev is None else finite_float("state.dt_prev", state.dt_prev)
        if not isinstance(state.pulls, dict):
            raise ValueError(f"state.pulls must be a dict, got {type(state.pulls).__name__}")
        pulls = {self._check_object(i): finite_vector3("state.pulls force", f) for i, f in state.pulls.items()}
        for (owner, attr), a in new.items():
            setattr(owner, attr, a)
        self._time = time
        self._dt_prev = dt_prev
        self._pulls.clear()
        self._pulls.update(pulls)
        self._pos_out = None
        self._rot_out = None
        self._fn = None
