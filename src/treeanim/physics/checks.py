"""Argument checks shared by the physics modules."""

from __future__ import annotations

import math

import numpy as np

__all__ = ["finite_float", "finite_vector3"]


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


def finite_vector3(name: str, value) -> np.ndarray:
    """``value`` as a float64 array of shape (3,), all finite, or ValueError naming the argument.

    Parameters
    ----------
    name : str
        The argument's name, for the message.
    value : array_like
        Three numbers (x, y, z).

    Returns
    -------
    numpy.ndarray, (3,) float64
    """
    try:
        v = np.array(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be three finite numbers, got {value!r}") from None
    if v.shape != (3,):
        raise ValueError(f"{name} must be three numbers (x, y, z), got shape {v.shape}")
    if not np.all(np.isfinite(v)):
        raise ValueError(f"{name} must be finite, got {value!r}")
    return v
