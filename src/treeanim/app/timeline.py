"""The timeline (issue 31): pause, scrub back through the last seconds, resume from there.

:class:`Timeline` keeps copies of the simulation's state (``sim.state``, a deep copy) over the
last :data:`SECONDS` seconds, one after every step while they fit in :data:`BUDGET` bytes;
a bigger tree's states are kept further apart so the ring still spans the seconds in the
budget (the small cherry's state is about 0.2 MB: every step, 1,200 states, about 240 MB at
most; see :meth:`Timeline.interval`). The viewer (:class:`ViewerTimeline`, mixed into
:class:`treeanim.app.viewer.Viewer`) records after every step, and :meth:`~ViewerTimeline.scrub`
pauses and puts a kept state back into the simulation; resuming (Space, the panel) continues
from it and forgets the states after it (the future is discarded). ← and → step back and
forward one kept state (→ at the newest takes a step). A new tree, a reset or a change of model
forgets the timeline.
"""

from __future__ import annotations

from collections import deque

import numpy as np

__all__ = ["Timeline", "ViewerTimeline", "SECONDS", "BUDGET", "state_bytes"]

#: The seconds of simulated time the timeline spans.
SECONDS = 20.0
#: The most bytes of states the timeline keeps.
BUDGET = 256 * 2**20


def state_bytes(state, depth: int = 4) -> int:
    """The bytes of the arrays in ``state`` (a simulation's state: dataclasses and objects of
    arrays, ``depth`` levels down)."""
    if isinstance(state, np.ndarray):
        return state.nbytes
    if depth <= 0:
        return 0
    if isinstance(state, (list, tuple)):
        return sum(state_bytes(v, depth - 1) for v in state)
    if isinstance(state, dict):
        return sum(state_bytes(v, depth - 1) for v in state.values())
    if hasattr(state, "__dict__"):
        return sum(state_bytes(v, depth - 1) for v in vars(state).values())
    return 0


class Timeline:
    """A ring of a simulation's states over its last ``seconds``, within ``budget`` bytes.

    Parameters
    ----------
    seconds : float
        Simulated seconds spanned.
    budget : int
        Most bytes of states kept.

    Attributes
    ----------
    cursor : int or None
        The kept state the simulation was scrubbed to (an index, oldest 0); None: live.
    """

    def __init__(self, seconds: float = SECONDS, budget: int = BUDGET) -> None:
        self.seconds = float(seconds)
        self.budget = int(budget)
        self._kept: deque = deque()  # (time, state), oldest first
        self._bytes = 0  # one state's
        self.cursor: int | None = None

    def __len__(self) -> int:
        return len(self._kept)

    @property
    def times(self) -> np.ndarray:
        """(K,) the kept states' times (s), oldest first."""
        return np.array([t for t, _ in self._kept])

    @property
    def interval(self) -> float:
        """Simulated seconds between kept states: the span over the states that fit in the
        budget (0 before the first; a step as long or longer: every step kept)."""
        if not self._bytes:
            return 0.0
        return self.seconds / max(self.budget // self._bytes, 1)

    @property
    def memory(self) -> int:
        """Bytes of states kept now."""
        return len(self._kept) * self._bytes

    def clear(self) -> None:
        """Forget every state."""
        self._kept.clear()
        self.cursor = None

    def record(self, sim) -> None:
        """Keep ``sim``'s state after a step (if :attr:`interval` has passed since the last
        kept one); forget states older than :attr:`seconds`."""
        t = sim.time
        if self._kept and t - self._kept[-1][0] < self.interval - 1e-9:
            return
        state = sim.state
        self._bytes = self._bytes or state_bytes(state)
        self._kept.append((t, state))
        while t - self._kept[0][0] > self.seconds + 1e-9 or len(self._kept) * self._bytes > self.budget:
            self._kept.popleft()

    def restore(self, sim, index: int) -> float:
        """Put kept state ``index`` back into ``sim`` (the cursor there); returns its time."""
        t, state = self._kept[index]
        sim.state = state
        self.cursor = index % len(self._kept)
        return t

    def resume(self) -> None:
        """Continue from the cursor: forget the states after it."""
        if self.cursor is not None:
            while len(self._kept) > self.cursor + 1:
                self._kept.pop()
        self.cursor = None


class ViewerTimeline:
    """The timeline's actions of a :class:`~treeanim.app.viewer.Viewer` (its ``timeline``,
    ``sim``, ``paused``)."""

    def scrub(self, index: int) -> bool:
        """Pause and show kept state ``index`` (0 the oldest, −1 the newest). Returns whether
        there was one."""
        n = len(self.timeline)
        if not -n <= index < n:
            return False
        self.paused = True
        self.timeline.restore(self.sim, index)
        self.trace.clear()  # the trace follows the point from here
        self._uploaded = None
        return True

    def step_back(self) -> bool:
        """Pause and go back one kept state (←)."""
        tl = self.timeline
        if tl.cursor is not None:
            index = tl.cursor - 1
        else:  # live: the newest kept state, unless it is the state shown
            index = len(tl) - 1 - bool(len(tl) and tl.times[-1] >= self.sim.time)
        return index >= 0 and self.scrub(index)

    def step_forward(self) -> bool:
        """Pause and go forward one kept state; at the newest, take one step (→)."""
        cursor = self.timeline.cursor
        if cursor is not None and cursor + 1 < len(self.timeline):
            return self.scrub(cursor + 1)
        self.paused = True
        self.timeline.resume()
        self._steps(1)
        return True

    def set_paused(self, paused: bool) -> None:
        """Pause (True) or resume the simulation: from a scrubbed state, the states after it
        are forgotten."""
        self.paused = bool(paused)
        if not self.paused:
            self.timeline.resume()
            self.signals.forget_after(self.sim.time)

    def toggle_pause(self) -> None:
        """Pause or resume the simulation (Space)."""
        self.set_paused(not self.paused)
