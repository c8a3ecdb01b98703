"""numba for the compiled passes, with its on-disk cache kept best effort.

Every compiled function here is ``@njit(cache=True)``: the first run compiles (seconds) and
saves the machine code beside the module, later runs load it. numba lets an error in that
save escape from the call being compiled, so a full disk or a file-size limit would end a
``render`` or an ``export`` with "File too large" before it wrote a byte of its own. Saving
is an optimisation: here a cache that cannot be written costs a compile at the next start,
never the command.
"""

from __future__ import annotations

import numpy as np
from llvmlite import ir
from numba import njit, types
from numba.core.caching import Cache
from numba.extending import intrinsic

__all__ = ["njit", "inv_cbrt"]

_save_overload = Cache.save_overload


def _save_if_possible(self, sig, data):
    try:
        _save_overload(self, sig, data)
    except OSError:
        pass


Cache.save_overload = _save_if_possible


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
    """x^(−1/3) for normal x > 0, to a few ulps, three times faster than 1/``np.cbrt`` and
    inline (no call): a guess from the exponent's bits (within 11 %), then twice
    y ← y·(1 + e/3 + 2e²/9 + 14e³/81 + 35e⁴/243), e = 1 − x·y³ (the series of (1 − e)^(−1/3):
    fifth order, 10⁻⁶ after the first)."""
    y = _float(np.int64(0x553EF0FF289DD796) - _bits(x) // 3)
    for _ in range(2):
        e = 1.0 - x * y * y * y
        y = y + y * e * (1.0 / 3.0 + e * (2.0 / 9.0 + e * (14.0 / 81.0 + e * (35.0 / 243.0))))
    return y
