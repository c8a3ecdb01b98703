"""Recording a simulation's tips over time (``treeanim trace``, the Lissajous figures)."""

from __future__ import annotations

import numpy as np

from ..validate import finite_float
from .simulation import Simulation

__all__ = ["trace_tips", "MAX_TRACE_VALUES"]

#: Largest number of floats :func:`trace_tips` records ((steps + 1) × (3·objects + 1)),
#: about 1 GB of float64.
MAX_TRACE_VALUES = 125_000_000


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
    out[0] = sim.tip_positions(objs)
    times[0] = sim.time
    for k in range(n):
        sim.step(dt)
        out[k + 1] = sim.tip_positions(objs)
        times[k + 1] = sim.time
    return times, out
