"""Boundary checks of numbers given to the package: finite, positive, within a range, a
finite 3-vector. Each raises ValueError naming the argument (the command line reports it as
one line, exit status 2). No dependency but numpy: every layer may use them."""

from __future__ import annotations

import math
import numbers

import numpy as np

__all__ = ["finite_float", "finite_vector3", "positive_float", "float_within"]


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


def positive_float(name: str, value) -> float:
    """``value`` as a finite float greater than 0, or ValueError naming the argument.

    Parameters
    ----------
    name : str
        The argument's name, for the message.
    value : object
        Anything ``float()`` accepts.

    Returns
    -------
    float
    """
    x = finite_float(name, value)
    if not x > 0:
        raise ValueError(f"{name} must be a positive number, got {value!r}")
    return x


def float_within(name: str, value, lo: float, hi: float, unit: str = "") -> float:
    """``value`` as a finite float in [``lo``, ``hi``], or ValueError naming the argument.

    Parameters
    ----------
    name : str
        The argument's name, for the message.
    value : object
        Anything ``float()`` accepts.
    lo, hi : float
        The closed range.
    unit : str
        Appended to the range in the message (e.g. ``" m/s"``).

    Returns
    -------
    float
    """
    x = finite_float(name, value)
    if not lo <= x <= hi:
        raise ValueError(f"{name} must be from {lo:g} to {hi:g}{unit}, got {value!r}")
    return x


def object_index(i, n: int) -> int:
    """``i`` as an object index of a tree of ``n`` objects (an integer in [0, n)).

    Raises
    ------
    ValueError
        Not an integer (booleans included) or out of range.
    """
    if isinstance(i, bool) or not isinstance(i, numbers.Integral):
        raise ValueError(f"object index i must be an integer, got {i!r}")
    if not 0 <= int(i) < n:
        raise ValueError(f"object index i={i} is out of range: the tree has {n} objects")
    return int(i)
