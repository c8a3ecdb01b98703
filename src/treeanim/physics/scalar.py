"""Scalar functions for the compiled passes, inline and without calls into libm: sines and
cosines by fixed chains of multiply-adds (no loop or table whose branches a processor
mispredicts leaf after leaf), and x^(−1/3). Each agrees with numpy's to a few ulps."""

from __future__ import annotations

import numpy as np
from llvmlite import ir
from numba import types
from numba.extending import intrinsic

from .compiled import njit

__all__ = ["sinc_cos", "sinc_cos_series", "sincos", "sin_turn", "inv_cbrt", "SERIES_MAX"]

#: The largest x² :func:`sinc_cos_series` holds for (x ≤ 1.6).
SERIES_MAX = 2.56


@njit(cache=True, fastmath=True, error_model="numpy", inline="always")
def _sinc_long(x2):
    """sin x / x for x² ≤ :data:`SERIES_MAX`: its Taylor series to x²² (error below 10⁻²⁰)."""
    return 1.0 + x2 * (-1.0 / 6.0 + x2 * (1.0 / 120.0 + x2 * (-1.0 / 5040.0 + x2 * (1.0 / 362880.0 + x2 * (
        -1.0 / 39916800.0 + x2 * (1.0 / 6227020800.0 + x2 * (-1.0 / 1307674368000.0 + x2 * (
            1.0 / 355687428096000.0 + x2 * (-1.0 / 121645100408832000.0 + x2 * (
                1.0 / 51090942171709440000.0 + x2 * (-1.0 / 25852016738884976640000.0)))))))))))


@njit(cache=True, fastmath=True, error_model="numpy", inline="always")
def sinc_cos(x2):
    """(sin x / x, cos x) from x² alone (no square root, no division): Taylor series to x¹⁴
    and x¹⁶ for x² ≤ ¼ (errors below 10⁻¹⁹), :func:`sinc_cos_series` to x² ≤
    :data:`SERIES_MAX`; libm's beyond."""
    if x2 <= 0.25:
        s = 1.0 + x2 * (-1.0 / 6.0 + x2 * (1.0 / 120.0 + x2 * (-1.0 / 5040.0 + x2 * (
            1.0 / 362880.0 + x2 * (-1.0 / 39916800.0 + x2 * (1.0 / 6227020800.0 + x2 * (
                -1.0 / 1307674368000.0)))))))
        c = 1.0 + x2 * (-0.5 + x2 * (1.0 / 24.0 + x2 * (-1.0 / 720.0 + x2 * (1.0 / 40320.0 + x2 * (
            -1.0 / 3628800.0 + x2 * (1.0 / 479001600.0 + x2 * (-1.0 / 87178291200.0 + x2 * (
                1.0 / 20922789888000.0))))))))
        return s, c
    if x2 > SERIES_MAX:
        x = np.sqrt(x2)
        return np.sin(x) / x, np.cos(x)
    return sinc_cos_series(x2)


@njit(cache=True, fastmath=True, error_model="numpy", inline="always")
def sinc_cos_series(x2):
    """(sin x / x, cos x) for x² ≤ :data:`SERIES_MAX`: Taylor series to x²² and x²⁴ (errors
    below 10⁻²⁰), without a branch, so a loop over many x runs as vectors."""
    c = 1.0 + x2 * (-0.5 + x2 * (1.0 / 24.0 + x2 * (-1.0 / 720.0 + x2 * (1.0 / 40320.0 + x2 * (
        -1.0 / 3628800.0 + x2 * (1.0 / 479001600.0 + x2 * (-1.0 / 87178291200.0 + x2 * (
            1.0 / 20922789888000.0 + x2 * (-1.0 / 6402373705728000.0 + x2 * (
                1.0 / 2432902008176640000.0 + x2 * (-1.0 / 1124000727777607680000.0 + x2 * (
                    1.0 / 620448401733239439360000.0))))))))))))
    return _sinc_long(x2), c


@njit(cache=True, fastmath=True, error_model="numpy", inline="always")
def sincos(x):
    """(sin x, cos x), three times faster than libm's pair for |x| ≤ 1.6 (:func:`sinc_cos`)."""
    s, c = sinc_cos(x * x)
    return x * s, c


@njit(cache=True, fastmath=True, error_model="numpy", inline="always")
def sin_turn(x):
    """sin x for x in [0, 2π), folded onto [−π/2, π/2] without branches (sin(π − x) = sin x)."""
    x = x - 2.0 * np.pi if x > np.pi else x
    x = np.pi - x if x > 0.5 * np.pi else x
    x = -np.pi - x if x < -0.5 * np.pi else x
    return x * _sinc_long(x * x)


@intrinsic
def _bits(typingctx, x):
    """The float64's bits as an int64."""
    return types.int64(types.float64), lambda context, builder, sig, args: builder.bitcast(args[0], ir.IntType(64))


@intrinsic
def _float(typingctx, i):
    """The int64's bits as a float64."""
    return types.float64(types.int64), lambda context, builder, sig, args: builder.bitcast(args[0], ir.DoubleType())


@njit(cache=True, fastmath=True, error_model="numpy", inline="always")
def inv_cbrt(x):
    """x^(−1/3) for normal x > 0, three times faster than 1/``np.cbrt``: a guess from the
    exponent's bits (within 11 %), then twice y ← y·(1 + e/3 + 2e²/9 + 14e³/81 + 35e⁴/243),
    e = 1 − x·y³ (the series of (1 − e)^(−1/3): fifth order, 10⁻⁶ after the first)."""
    y = _float(np.int64(0x553EF0FF289DD796) - _bits(x) // 3)
    for _ in range(2):
        e = 1.0 - x * y * y * y
        y = y + y * e * (1.0 / 3.0 + e * (2.0 / 9.0 + e * (14.0 / 81.0 + e * (35.0 / 243.0))))
    return y
