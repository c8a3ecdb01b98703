"""Holding branches (issue 31): the grab's strength and pins.

The mouse's grab (:mod:`treeanim.physics.pull`) is a spring; :attr:`~ViewerHold.grab_strength`
scales it (1, the default: on the tree model :data:`~treeanim.physics.tree_sim.GRAB_STIFFNESS`
times the tree's own stiffness at the grabbed point, so a small drag is covered up to 98 %; on
the paper's model a loop gain of :data:`~treeanim.physics.pull.GAIN`). A weaker grab leaves the
branch short of the cursor: the point covers at most s/(1 + s) of a small drag, s the spring in
units of the tree's stiffness there, taken with every joint's lever across the pull (the most
compliant way: a pull along some levers meets a stiffer tree), and less of a drag whose force
would pass what the wood bears (the spring's force is held there).

A **pin** keeps a drag of the tree model after the mouse lets go: P (or letting go with Shift
held) pins the drag in progress where its target is; the branch stays bent, held by the
simulation (:meth:`Simulation.drag <treeanim.physics.simulation.Simulation.drag>` holds several
points at once), until :meth:`~ViewerHold.unpin` lets it go (the panel's list, Shift+P for all,
R). Pins are the viewer's controls, not the simulation's state: scrubbing back through the
timeline keeps them. Mixed into :class:`treeanim.app.viewer.Viewer`.
"""

from __future__ import annotations

import math

import numpy as np

from ..physics.pull import GAIN, TreeDrag
from ..physics.tree_sim import GRAB_STIFFNESS

__all__ = ["ViewerHold", "GRAB_STRENGTHS"]

#: The grab strength's range (× the default spring): on the tree model 0.1× … 1000× the tree's
#: stiffness at the point, a small drag covered 9 % … 99.9 %.
GRAB_STRENGTHS = (0.1 / GRAB_STIFFNESS, 20.0)


class ViewerHold:
    """The grab's strength and the pins of a :class:`~treeanim.app.viewer.Viewer`.

    Attributes
    ----------
    grab_strength : float
        The grab's spring × its default (the next grab's; :meth:`set_grab_strength`).
    pins : list of TreeDrag
        The pinned drags, oldest first.
    """

    def _init_hold(self) -> None:
        self.grab_strength = 1.0
        self.pins: list[TreeDrag] = []

    def set_grab_strength(self, strength: float) -> None:
        """The grab's spring × its default, clamped to :data:`GRAB_STRENGTHS` (ValueError: not
        a number); a drag in progress (the tree model) takes it at once, a spring pull the next
        time."""
        strength = float(strength)
        if math.isnan(strength):
            raise ValueError("grab strength: expected a number, got nan")
        self.grab_strength = min(max(strength, GRAB_STRENGTHS[0]), GRAB_STRENGTHS[1])
        if isinstance(self.grab, TreeDrag):
            self.grab.stiffness = GRAB_STIFFNESS * self.grab_strength
            self.grab.sent = None  # handed to the simulation before the next step

    def held_share(self) -> float:
        """The most of a small drag a grab covers, s/(1 + s): s the spring over the tree's
        stiffness at the point (the tree model), or the spring pull's loop gain (the paper's)."""
        s = (GRAB_STIFFNESS if self.sim.model == "tree" else GAIN) * self.grab_strength
        return s / (1.0 + s)

    def pin(self) -> bool:
        """Pin the drag in progress (tree model): the branch stays held where the drag's target
        is when the mouse lets go. Returns whether one was pinned (else a line in the status
        line says why)."""
        if not isinstance(self.grab, TreeDrag):
            self.say("pin: drag a branch first (the tree model)" if self.grab is None
                     else "pin: pins need the tree model")
            return False
        self.pins.append(self.grab)
        self.grab = None  # the mouse lets go of it, the simulation keeps it
        self._end_drag()
        self.say(f"pinned #{self.pins[-1].object} ({self.sim.tree.kind[self.pins[-1].object]})")
        return True

    def unpin(self, index: int | None = None) -> int:
        """Let go of pin ``index`` (in :attr:`pins`; None: of all, Shift+P): the branch swings
        back. Returns how many were let go."""
        gone = self.pins if index is None else self.pins[index:index + 1]
        for p in gone:
            p.release(self.sim)
        self.pins = [] if index is None else self.pins[:index] + self.pins[index + 1:]
        return len(gone)

    def _take_pin(self, obj: int) -> None:
        """A new grab of ``obj`` takes over its pin (the simulation holds one drag an object)."""
        self.pins = [p for p in self.pins if p.object != obj]

    def pinned_points(self) -> np.ndarray:
        """(K, 3) where the pinned points are held (world): each pin's target."""
        return np.array([p.target for p in self.pins]).reshape(-1, 3)
