"""One frame driver for every way a simulation is driven: the viewer's frames and the offline
commands' (``render``, ``export``, ``trace``, ``bench``; docs/design.md §10).

:class:`FrameDriver` owns the clock and the step policy:

* **Fixed steps.** Real time (the viewer) steps by :data:`STEP` × the time scale (at most
  :data:`STEP`) whatever the frame rate, so its motion is the same at 2 frames a second as at
  120 and the exact integrator's coefficients stay cached. Frames at a fixed rate (the offline
  commands) step by the longest step of at most :data:`STEP` that divides the frame interval
  (:func:`step_for`: 1/60 s at 30 and 60 frames a second, 1/72 s at 24, 1/120 s at 120), so
  every frame lands exactly on its time; the tree model's motion differs between such steps
  by what its implicit step resolves (the same frequencies within 5 % from 1/120 to 1/10 s).
* **Elapsed time accumulates**; a step is taken once more than half of it is due, so frames
  land within half a step of their times. A frame longer than ``max_frame`` (a stalled or
  dragged window) is cut to it: the simulation never jumps.
* **A hand acts before every step**: the viewer's grab, or the offline commands' scheduled
  pulls and drags (:class:`treeanim.scripted.Schedule`). A hand is any object with
  ``step(sim, h, exact)``; ``exact`` is true at the first step of a frame (the one that may
  look at the whole pose).
"""

from __future__ import annotations

import math
from typing import Callable, Iterator, Protocol

__all__ = ["FrameDriver", "Hand", "STEP", "MAX_FRAME_DT", "step_for"]

#: The simulation's step (s).
STEP = 1.0 / 60.0

#: Longest real time one viewer frame advances the simulation by (s): slow frames (a software
#: renderer at a few frames a second) still keep real time, in steps; a stall (a dragged or
#: hidden window) never makes a jump.
MAX_FRAME_DT = 0.5


class Hand(Protocol):
    """What acts on the simulation before each step (a grab, a schedule of pulls)."""

    def step(self, sim, h: float, exact: bool = True) -> None:
        """Act on ``sim`` before a step of ``h`` seconds (``exact``: the frame's first step)."""


def step_for(rate: float, most: float = STEP) -> float:
    """The step for frames at ``rate`` a second: the longest of at most ``most`` seconds that
    divides the frame interval 1 / ``rate`` into whole steps.

    Raises
    ------
    ValueError
        ``rate`` or ``most`` not finite and positive.
    """
    if not (0 < rate < math.inf and 0 < most < math.inf):
        raise ValueError(f"frames need a finite positive rate and step, got {rate!r} a second and {most!r} s")
    interval = 1.0 / rate
    return interval / max(1, math.ceil(interval / most - 1e-9))


class FrameDriver:
    """Advances a simulation by frames of elapsed time in fixed steps.

    Parameters
    ----------
    step : float
        The step at time scale 1 (s), > 0.
    max_frame : float or None
        Longest real time one :meth:`advance` takes in (s); None: no limit.

    Attributes
    ----------
    rate : float or None
        Frames a second of :meth:`frames` (a driver made by :meth:`at_rate`); None: real time.
    """

    def __init__(self, step: float = STEP, max_frame: float | None = MAX_FRAME_DT) -> None:
        if not 0 < step < math.inf:
            raise ValueError(f"step must be finite and > 0, got {step!r}")
        self.base_step = float(step)
        self.max_frame = max_frame
        self.rate: float | None = None
        self._scale = 1.0
        self.reset()

    @classmethod
    def at_rate(cls, rate: float, most: float = STEP) -> "FrameDriver":
        """A driver for frames at ``rate`` a second (the offline commands): steps of
        :func:`step_for` ``(rate, most)``, no cut on a frame's length."""
        driver = cls(step_for(rate, most), max_frame=None)
        driver.rate = float(rate)
        return driver

    @property
    def time_scale(self) -> float:
        """Simulated seconds per real second (finite, > 0). Below 1 the step shortens with it,
        so at any slow-motion scale a frame of one step takes one step."""
        return self._scale

    @time_scale.setter
    def time_scale(self, value: float) -> None:
        value = float(value)
        if not 0 < value < math.inf:
            raise ValueError(f"time scale must be finite and > 0, got {value!r}")
        self._scale = value

    @property
    def step(self) -> float:
        """The step now (s): the base step × the time scale, at most the base step."""
        return self.base_step * min(1.0, self._scale)

    def reset(self) -> None:
        """Nothing due (after a reset of the simulation or a new one)."""
        self._due = 0.0

    def advance(self, sim, elapsed: float, hand: Hand | None = None,
                after: Callable[[], None] | None = None) -> int:
        """Step ``sim`` (anything with ``step(h)``): take in ``elapsed`` seconds of real time (× the time scale; cut to ``max_frame``)
        and take the steps now due, ``hand`` acting before each and ``after`` called after
        each. Returns the number of steps taken; what is left over (within half a step either
        way) carries over to the next frame."""
        h = self.step
        elapsed = max(float(elapsed), 0.0)
        if self.max_frame is not None:
            elapsed = min(elapsed, self.max_frame)
        self._due += elapsed * self._scale
        n = int(math.floor(self._due / h + 0.5))
        self._due = min(max(self._due - n * h, -0.5 * h), h)
        for j in range(n):
            if hand is not None:
                hand.step(sim, h, exact=j == 0)
            sim.step(h)
            if after is not None:
                after()
        return n

    def frames(self, sim, count: int, hand: Hand | None = None) -> Iterator[int]:
        """Advance ``sim`` to each frame time k / :attr:`rate` for k = 0 … ``count`` − 1 (a
        driver made by :meth:`at_rate`), yielding k once the simulation is there (frame 0 is the
        current state)."""
        if self.rate is None:
            raise ValueError("frames() needs a driver made by FrameDriver.at_rate")
        for k in range(count):
            self.advance(sim, 1.0 / self.rate if k else 0.0, hand)
            yield k
