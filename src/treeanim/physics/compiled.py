"""numba for the compiled passes, with its on-disk cache kept best effort.

Every compiled function here is ``@njit(cache=True)``: the first run compiles (seconds) and
saves the machine code beside the module, later runs load it. numba lets an error in that
save escape from the call being compiled, so a full disk or a file-size limit would end a
``render`` or an ``export`` with "File too large" before it wrote a byte of its own. Saving
is an optimisation: here a cache that cannot be written costs a compile at the next start,
never the command.
"""

from __future__ import annotations

from numba import njit
from numba.core.caching import Cache

__all__ = ["njit"]

_save_overload = Cache.save_overload


def _save_if_possible(self, sig, data):
    try:
        _save_overload(self, sig, data)
    except OSError:
        pass


Cache.save_overload = _save_if_possible
