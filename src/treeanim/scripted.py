"""Scripted runs for the offline commands: scheduled pulls and drags, and fixed-rate frames.

``--pull OBJECT:FX,FY,FZ@T0-T1`` pulls object OBJECT's tip with a world force (newtons) from
time T0 and lets go at T1; several pulls may be given (either model).

``--drag OBJECT[@S]:X,Y,Z@T0-T1`` drags the point at fraction S of object OBJECT's length (its
tip, S = 1, by default) toward the world point X,Y,Z (metres) from T0 and lets go at T1, through
:meth:`Simulation.drag <treeanim.physics.simulation.Simulation.drag>` (the tree model only);
several drags may be given, one at a time.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from typing import Iterator

import numpy as np

from .driver import STEP, FrameDriver

_PULL = re.compile(r"^\s*(\d+)\s*:\s*([^@]+?)\s*@\s*([^-]+?)\s*-\s*(.+?)\s*$")
_DRAG = re.compile(r"^\s*(\d+)\s*(?:@\s*([^:]+?)\s*)?:\s*([^@]+?)\s*@\s*([^-]+?)\s*-\s*(.+?)\s*$")


@dataclass(frozen=True)
class Pull:
    """A pull on ``obj``'s tip with world ``force`` (N) from ``start`` to ``end`` seconds."""

    obj: int
    force: tuple[float, float, float]
    start: float
    end: float


@dataclass(frozen=True)
class Drag:
    """A drag of the point at fraction ``s`` of ``obj``'s length toward world ``target`` (m)
    from ``start`` to ``end`` seconds (the tree model's :meth:`Simulation.drag`)."""

    obj: int
    target: tuple[float, float, float]
    start: float
    end: float
    s: float = 1.0


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
    t0, t1 = _interval(m.group(3), m.group(4), f"--pull {text!r}", form)
    return Pull(int(m.group(1)), force, t0, t1)


def parse_drag(text: str) -> Drag:
    """Parse ``OBJECT[@S]:X,Y,Z@T0-T1`` (S, the fraction of the object's length held, in
    [0, 1]; default 1, the tip).

    Raises
    ------
    ValueError
        With a message that repeats the expected form.
    """
    form = "expected OBJECT[@S]:X,Y,Z@T0-T1, e.g. 0:0.3,1.2,0@0.5-2 or 0@0.5:0.3,1.2,0@0.5-2"
    m = _DRAG.match(text)
    if not m:
        raise ValueError(f"--drag {text!r}: {form}")
    target = parse_vector(m.group(3), f"--drag {text!r}")
    try:
        s = 1.0 if m.group(2) is None else float(m.group(2))
    except ValueError:
        raise ValueError(f"--drag {text!r}: {form}") from None
    if not 0.0 <= s <= 1.0:
        raise ValueError(f"--drag {text!r}: expected S in [0, 1] (the fraction of the object's length)")
    t0, t1 = _interval(m.group(4), m.group(5), f"--drag {text!r}", form)
    return Drag(int(m.group(1)), target, t0, t1, s)


def _interval(start: str, end: str, what: str, form: str) -> tuple[float, float]:
    """``T0``, ``T1`` of a scheduled pull or drag: finite, 0 <= T0 < T1; ValueError naming
    ``what`` otherwise."""
    try:
        t0, t1 = float(start), float(end)
    except ValueError:
        raise ValueError(f"{what}: {form}") from None
    if not (math.isfinite(t0) and math.isfinite(t1) and 0 <= t0 < t1):
        raise ValueError(f"{what}: expected times 0 <= T0 < T1")
    return t0, t1


def check_pulls(pulls: list, n_objects: int, model: str = "tree") -> None:
    """Refuse a pull or drag on an object the tree does not have, a drag on a model other than
    the tree model, and drags whose intervals overlap (the tree holds one drag at a time)."""
    drags = sorted((p for p in pulls if isinstance(p, Drag)), key=lambda d: d.start)
    for p in pulls:
        option = "--drag" if isinstance(p, Drag) else "--pull"
        if not 0 <= p.obj < n_objects:
            raise ValueError(f"{option} on object {p.obj}: the tree has objects 0 to {n_objects - 1}")
    if drags and model != "tree":
        raise ValueError("--drag needs the tree model, not --paper (the paper's objects are independent: "
                         "use --pull)")
    for a, b in zip(drags, drags[1:]):
        if b.start < a.end:
            raise ValueError(f"--drag: the drags at {a.start:g}-{a.end:g} s and {b.start:g}-{b.end:g} s overlap; "
                             f"the tree holds one drag at a time")


class Schedule:
    """Scheduled pulls and drags, a hand of :class:`~treeanim.driver.FrameDriver`.

    ``pulls`` holds :class:`Pull` and :class:`Drag` items, their times counted from the
    schedule's first step. Before every step, exactly the pulls and the drag whose interval
    [T0, T1) holds the step's start time are held (pulls on different objects may overlap;
    drags may not, see :func:`check_pulls`); the others are let go.
    """

    def __init__(self, pulls=()) -> None:
        self.forces = [p for p in pulls if not isinstance(p, Drag)]
        self.drags = [p for p in pulls if isinstance(p, Drag)]
        self.held: dict[int, tuple[float, float, float]] = {}
        self.dragged: Drag | None = None
        self.time = 0.0

    def step(self, sim, h: float, exact: bool = True) -> None:
        """Before a step of ``h`` seconds: hold what is due now, let go of the rest."""
        t = self.time
        want = {p.obj: p.force for p in self.forces if p.start <= t < p.end}
        drag = next((d for d in self.drags if d.start <= t < d.end), None)
        gone = self.held.keys() - want.keys()  # release() lets go of an object's pull and drag
        if self.dragged is not None and (drag is None or drag.obj != self.dragged.obj):
            gone |= {self.dragged.obj}
        for obj in sorted(gone):
            sim.release(obj)
        for obj, force in want.items():
            if obj in gone or self.held.get(obj) != force:
                sim.pull(obj, np.asarray(force, float))
        if drag is not None and (drag != self.dragged or drag.obj in gone):
            sim.drag(drag.obj, np.asarray(drag.target, float), drag.s)
        self.held, self.dragged = want, drag
        self.time = t + h

    def release(self, sim) -> None:
        """Let go of everything held."""
        held = self.held.keys() | ({self.dragged.obj} if self.dragged is not None else set())
        for obj in sorted(held):
            sim.release(obj)
        self.held, self.dragged = {}, None


def frames(sim, count: int, fps: float, pulls: list = (), step: float = STEP) -> Iterator[int]:
    """Advance ``sim`` to each frame time k / fps for k = 0 … ``count`` − 1 with the scheduled
    ``pulls`` (:class:`Schedule`), yielding k there; everything is let go at the end.

    The steps are the frame driver's for frames at ``fps``, of at most ``step`` seconds
    (:meth:`FrameDriver.at_rate <treeanim.driver.FrameDriver.at_rate>`).
    """
    schedule = Schedule(pulls)
    yield from FrameDriver.at_rate(fps, step).frames(sim, count, schedule)
    schedule.release(sim)
