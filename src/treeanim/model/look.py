"""A species' look that the simulation does not use: its bark (the preset's ``[bark]`` table)."""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["Bark"]


@dataclass(frozen=True)
class Bark:
    """Bark of a species, drawn procedurally by ``shaders/tree.frag``.

    Attributes
    ----------
    color : (3,) float
        sRGB in [0, 1].
    furrows : float
        Furrows round a branch (> 0).
    depth : float
        How much darker a furrow is than a ridge, in [0, 1].
    interlace : float
        How far the ridges wander and merge, in [0, 1] (0: straight; about 1: a tulip poplar's
        interlaced diamonds).
    lenticels : float
        Strength of horizontal lenticels, in [0, 1] (a cherry's; 0: none).
    """

    color: tuple[float, float, float] = (0.40, 0.30, 0.23)
    furrows: float = 10.0
    depth: float = 0.35
    interlace: float = 0.3
    lenticels: float = 0.0
