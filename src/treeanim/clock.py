"""One fixed-step clock for every way a simulation is driven: the viewer's frames and the
offline commands' (docs/design.md §10).

The simulation always steps by the same ``step`` (1/60 s by default), whatever the frame rate,
so a render, an export and the viewer take the same steps and the exact integrator's
coefficients stay cached. Elapsed time accumulates; a step is taken once more than half of it
is due, so frames land within half a step of their times.
"""

from __future__ import annotations

import math

__all__ = ["StepClock", "STEP"]

#: The simulation's step (s).
STEP = 1.0 / 60.0


class StepClock:
    """Whole steps of ``step`` seconds for a stream of elapsed times.

    Parameters
    ----------
    step : float
        The step (s), > 0; settable (the viewer's slow motion shortens it).
    """

    def __init__(self, step: float = STEP):
        self.step = step
        self.reset()

    def reset(self) -> None:
        """Nothing due."""
        self._due = 0.0

    def advance(self, elapsed: float, most: int | None = None) -> int:
        """Add ``elapsed`` seconds (>= 0); return how many steps are now due (at most ``most``).

        What is left over (within half a step either way) carries over."""
        h = self.step
        self._due += max(float(elapsed), 0.0)
        n = int(math.floor(self._due / h + 0.5))
        if most is not None:
            n = min(n, most)
        self._due = min(max(self._due - n * h, -0.5 * h), h)
        return n
