"""Argument checks shared by the physics modules."""

from __future__ import annotations

import math

__all__ = ["finite_float"]


def finite_float(name: str, value) -> float:
    """``value`` as a finite float, or ValueError naming the argument.

    Parameters
    ----------
    name : str
        The argument's name, for the message.
    value : object
        Anything ``float()`` accepts.

    Returns
    -------
    float

    Raises
    ------
    ValueError
        If ``value`` is not a real number or is NaN or infinite.
    """
    try:
        x = float(value)
    except (TypeError, ValueError, OverflowError):
        raise ValueError(f"{name} must be a finite number, got {value!r}") from None
    if not math.isfinite(x):
        raise ValueError(f"{name} must be finite, got {value!r}")
    return x
