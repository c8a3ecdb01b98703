"""Scripted runs for the offline commands: scheduled pulls and fixed-rate frames.

``--pull OBJECT:FX,FY,FZ@T0-T1`` pulls object OBJECT's tip with a world force (newtons) from
time T0 and lets go at T1; several pulls may be given.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from typing import Iterator

import numpy as np

from .clock import STEP, StepClock

_PULL = re.compile(r"^\s*(\d+)\s*:\s*([^@]+?)\s*@\s*([^-]+?)\s*-\s*(.+?)\s*$")


@dataclass(frozen=True)
class Pull:
    """A pull on ``obj``'s tip with world ``force`` (N) from ``start`` to ``end`` seconds."""

    obj: int
    force: tuple[float, float, float]
    start: float
    end: float


def parse_vector(text: str, what: str) -> tuple[float, float, float]:
    """``'FX,FY,FZ'`` as three finite floats; ValueError naming ``what`` otherwise."""
    parts = text.split(",")
    try:
        values = tuple(float(p) for p in parts)
    except ValueError:
        values = ()
    if len(values) != 3 or not all(math.isfinite(v) for v in values):
        raise ValueError(f"{what}: expected three finite numbers X,Y,Z, got {text!r}")
    return values  # type: ignore[return-value]


def parse_force(text: str, what: str) -> tuple[float, float, float]:
    """``'FX,FY,FZ'`` newtons: three finite floats of magnitude at most the simulation's
    ``MAX_PULL``; ValueError naming ``what`` otherwise."""
    from .physics.simulation import MAX_PULL

    force = parse_vector(text, what)
    if not math.hypot(*force) <= MAX_PULL:
        raise ValueError(f"{what}: a force of at most {MAX_PULL:g} N, got {text!r}")
    return force


def parse_pull(text: str) -> Pull:
    """Parse ``OBJECT:FX,FY,FZ@T0-T1``.

    Raises
    ------
    ValueError
        With a message that repeats the expected form.
    """
    form = "expected OBJECT:FX,FY,FZ@T0-T1, e.g. 0:300,0,0@0.5-2"
    m = _PULL.match(text)
    if not m:
        raise ValueError(f"--pull {text!r}: {form}")
    force = parse_force(m.group(2), f"--pull {text!r}")
    try:
        t0, t1 = float(m.group(3)), float(m.group(4))
    except ValueError:
        raise ValueError(f"--pull {text!r}: {form}") from None
    if not (math.isfinite(t0) and math.isfinite(t1) and 0 <= t0 < t1):
        raise ValueError(f"--pull {text!r}: expected times 0 <= T0 < T1")
    return Pull(int(m.group(1)), force, t0, t1)


def check_pulls(pulls: list[Pull], n_objects: int) -> None:
    """Refuse a pull on an object the tree does not have."""
    for p in pulls:
        if not 0 <= p.obj < n_objects:
            raise ValueError(f"--pull on object {p.obj}: the tree has objects 0 to {n_objects - 1}")


def frames(sim, seconds: float, fps: float, pulls: list[Pull] = (), step: float = STEP) -> Iterator[int]:
    """Advance ``sim`` to each frame time k / fps for k = 0 .. round(seconds * fps) - 1.

    Yields the frame index once the simulation is within half a ``step`` of that frame's time:
    it steps by ``step`` on the viewer's clock (:class:`~treeanim.clock.StepClock`).
    Before every step, exactly the pulls whose interval [T0, T1) holds the step's start time
    are held (pulls on different objects may overlap); the others are let go.
    """
    n = int(round(seconds * fps))
    clock = StepClock(step)
    held: dict[int, tuple[float, float, float]] = {}
    t = 0.0
    for k in range(n):
        for _ in range(clock.advance(1.0 / fps if k else 0.0)):
            want = {p.obj: p.force for p in pulls if p.start <= t < p.end}
            for obj in held.keys() - want.keys():
                sim.release(obj)
            for obj, force in want.items():
                if held.get(obj) != force:
                    sim.pull(obj, np.asarray(force, float))
            held = want
            sim.step(step)
            t += step
        yield k
    for obj in held:
        sim.release(obj)
