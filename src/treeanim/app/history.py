"""The viewer's undo history of setting changes: :class:`History`, a bounded list of steps, each
one or more :class:`Change` (name, old value, new value) that
:meth:`ViewerTuning.change_setting <treeanim.app.tuning.ViewerTuning.change_setting>` records
and :meth:`~treeanim.app.tuning.ViewerTuning.undo` /
:meth:`~treeanim.app.tuning.ViewerTuning.redo` apply again through the same actions.
"""

from __future__ import annotations

from contextlib import contextmanager
from dataclasses import dataclass
from typing import Any

__all__ = ["Change", "History", "HISTORY_STEPS"]

#: The most steps kept (the oldest are forgotten first).
HISTORY_STEPS = 200


@dataclass
class Change:
    """One setting changed.

    Attributes
    ----------
    name : str
        The setting (a key of :data:`~treeanim.app.settings.SETTINGS`).
    old, new : object
        Its value before and after.
    season : str or None
        The season table of a seasonal setting (an f or ζ range), else None.
    """

    name: str
    old: Any
    new: Any
    season: str | None = None


class History:
    """Steps of setting changes to undo and to redo.

    Parameters
    ----------
    limit : int
        The most steps kept to undo.

    Attributes
    ----------
    done : list of list of Change
        Steps to undo, the newest last.
    undone : list of list of Change
        Steps undone, to redo, the newest last (cleared by a new change).
    """

    def __init__(self, limit: int = HISTORY_STEPS) -> None:
        self.limit = int(limit)
        self.done: list[list[Change]] = []
        self.undone: list[list[Change]] = []
        self._group: list[Change] | None = None

    @property
    def can_undo(self) -> bool:
        return bool(self.done)

    @property
    def can_redo(self) -> bool:
        return bool(self.undone)

    def record(self, change: Change, merge: bool = False) -> None:
        """Record ``change`` as a new step (inside :meth:`group`: as part of the group's step).

        Parameters
        ----------
        merge : bool
            The change continues the last step (a slider still held): where that step is one
            change of the same setting, its new value becomes ``change.new`` (a drag is one
            step, from the value before it to the value let go).
        """
        if self._group is not None:
            self._group.append(change)
            return
        last = self.done[-1] if self.done else None
        if merge and last is not None and len(last) == 1 and (last[0].name, last[0].season) == (change.name, change.season):
            last[0].new = change.new
        else:
            self.done.append([change])
            del self.done[:-self.limit]
        self.undone.clear()

    @contextmanager
    def group(self):
        """Record the changes made inside as one step (Reset all)."""
        if self._group is not None:  # nested: the outer group takes them
            yield
            return
        self._group = []
        try:
            yield
        finally:
            changes, self._group = self._group, None
            if changes:
                self.done.append(changes)
                del self.done[:-self.limit]
                self.undone.clear()

    def clear(self) -> None:
        """Forget every step."""
        self.done.clear()
        self.undone.clear()
