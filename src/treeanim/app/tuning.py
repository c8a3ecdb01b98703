"""What a tuning tool is expected to have: every setting's change recorded to undo and redo, a
setting (or all) back to its default, camera bookmarks, and a draft mode for slow renderers.

Mixed into :class:`treeanim.app.viewer.Viewer` beside :class:`~treeanim.app.actions.ViewerActions`
(a module of its own: it reads the settings table, which imports the actions' ranges). Every
change of a setting, the panel's included (:meth:`Panel.apply
<treeanim.app.panel.Panel.apply>`), goes through :meth:`ViewerTuning.change_setting`, which
applies it by the setting's action, shows a refusal in the status line and records the change
in :attr:`history` (:class:`~treeanim.app.history.History`); undo and redo apply the recorded
values through the same actions, so a value refused now is refused there as well.
"""

from __future__ import annotations

from ..model.tree import KINDS
from .history import Change, History
from .settings import SETTINGS

__all__ = ["ViewerTuning", "UNTRACKED", "BOOKMARKS", "DRAFT_SCALE"]

#: Settings neither recorded nor reset: the tree itself, a named wind (its speed, turbulence
#: and gusts are sliders of their own), pausing, draft mode.
UNTRACKED = frozenset({"preset", "wind_preset", "paused", "draft"})
#: Camera bookmarks, numbered from 1 (Ctrl+1 … stores, 1 … recalls).
BOOKMARKS = 4
#: Draft mode draws the scene at this fraction of the window's pixels a side.
DRAFT_SCALE = 0.5


def _one_line(e: BaseException) -> str:
    return " ".join(str(e).split())


class ViewerTuning:
    """Undo, defaults, camera bookmarks and draft mode of a :class:`~treeanim.app.viewer.Viewer`.

    Attributes
    ----------
    history : History
        The setting changes to undo and redo.
    defaults : dict
        (name, season or None) → the value the setting had when the tree was loaded (a
        paper-only setting's: when the paper's model was first switched on for this tree).
    bookmarks : dict
        Number → (azimuth, elevation, distance, target, shift) of the camera stored there
        (kept while the tree changes).
    draft : bool
        Draft mode: the scene drawn at :data:`DRAFT_SCALE` of the pixels, without MSAA and
        without shadows (the shadows setting is kept, and returns with full quality).
    """

    history: History
    defaults: dict
    bookmarks: dict
    draft: bool = False

    def _init_tuning(self) -> None:
        self.history = History()
        self.defaults = {}
        self.bookmarks = {}
        self.draft = False

    # ------------------------------------------------------------------ values and defaults
    def setting_value(self, name: str, season: str = "summer"):
        """The current value of setting ``name`` (an f or ζ range: of the ``season`` table;
        AttributeError for a paper-only setting on the tree model)."""
        st = SETTINGS[name]
        if st.seasonal:
            return self.mode_range(*st.args, season=season)
        return st.value(self)

    def _keys(self):
        """(name, season or None) of every setting that has a default."""
        for name, st in SETTINGS.items():
            if name in UNTRACKED:
                continue
            if st.seasonal:
                if st.args[0] in KINDS:
                    yield from ((name, s) for s in ("summer", "winter"))
            elif st.get is not None:
                yield name, None

    def note_defaults(self, fresh: bool = False) -> None:
        """Take the current values as the defaults (``fresh``: all of them, a new tree; else
        only those not known yet, e.g. the paper model's settings when it is switched on)."""
        if fresh:
            self.defaults = {}
        for name, season in self._keys():
            if (name, season) in self.defaults:
                continue
            try:
                value = self.setting_value(name, season or "summer")
            except AttributeError:  # the paper model's settings on the tree model
                continue
            if value is not None:
                self.defaults[(name, season)] = value

    def default_of(self, name: str, season: str = "summer"):
        """Setting ``name``'s default (None: none known)."""
        return self.defaults.get((name, season if SETTINGS[name].seasonal else None))

    def is_default(self, name: str, season: str = "summer") -> bool:
        """Whether setting ``name`` has its default value (True where it has none)."""
        default = self.default_of(name, season)
        try:
            return default is None or self.setting_value(name, season) == default
        except AttributeError:
            return True

    # ------------------------------------------------------------------ changes
    def change_setting(self, name: str, value, *, season: str = "summer", merge: bool = False,
                       record: bool = True) -> bool:
        """Apply setting ``name`` (a key of :data:`~treeanim.app.settings.SETTINGS`) through its
        action and record the change in :attr:`history`.

        Parameters
        ----------
        season : {'summer', 'winter'}
            The table an f or ζ range is set in.
        merge : bool
            Part of the last step (a slider still held: a drag is one step).
        record : bool
            Record the change (undo and redo do not).

        Returns
        -------
        bool
            Whether it was accepted; a refusal (ValueError, OSError) is shown in the status
            line instead of raised.
        """
        try:
            st = SETTINGS.get(name)
            if st is None:
                raise ValueError(f"unknown setting {name!r}")
            tracked = record and name not in UNTRACKED
            extra = {"season": season} if st.seasonal else {}
            old = self._value_or_none(name, season) if tracked else None
            st.apply(self, value, **extra)
        except (ValueError, OSError) as e:
            self.say(f"error: {_one_line(e)}")
            return False
        if tracked and old is not None:
            new = self._value_or_none(name, season)
            if new is not None and new != old:
                self.history.record(Change(name, old, new, season if st.seasonal else None), merge=merge)
        return True

    def _value_or_none(self, name: str, season: str):
        try:
            return self.setting_value(name, season)
        except AttributeError:
            return None

    def _replay(self, steps: list, into: list, attr: str, verb: str) -> bool:
        if not steps:
            self.say(f"nothing to {verb}")
            return False
        step = steps[-1]
        order = reversed(step) if verb == "undo" else step
        ok = all([self.change_setting(c.name, getattr(c, attr), season=c.season or "summer", record=False)
                  for c in order])
        if not ok:  # refused (said in the status line): the step stays
            return False
        into.append(steps.pop())
        names = ", ".join(SETTINGS[c.name].label for c in step)
        self.say(f"{verb}: {names}" if len(names) < 60 else f"{verb}: {len(step)} settings")
        return True

    def undo(self) -> bool:
        """Undo the last step of setting changes (its old values through the same actions).
        Returns whether it was undone: a value refused now (a paper-only setting on the tree
        model) is shown in the status line and the step stays."""
        return self._replay(self.history.done, self.history.undone, "old", "undo")

    def redo(self) -> bool:
        """Redo the last step undone (until a new change). Returns whether it was redone."""
        return self._replay(self.history.undone, self.history.done, "new", "redo")

    def reset_setting(self, name: str, season: str = "summer") -> bool:
        """Set ``name`` back to its default (:attr:`defaults`: its value when the tree was
        loaded), a step to undo. Returns whether it has its default now (an unknown setting or
        one without a default is said in the status line)."""
        st = SETTINGS.get(name)
        if st is None or name in UNTRACKED:
            self.say(f"error: no default for {name!r}")
            return False
        default = self.default_of(name, season)
        if default is None:
            self.say(f"error: {st.label}: no default known")
            return False
        if self.is_default(name, season):
            return True
        return self.change_setting(name, default, season=season)

    def reset_all(self) -> int:
        """Every setting back to its default, one step to undo. Returns how many changed."""
        changed = 0
        with self.history.group():
            for name, season in list(self.defaults):
                if name == "paper_model" or self.is_default(name, season or "summer"):
                    continue
                changed += self.reset_setting(name, season or "summer")
            if not self.is_default("paper_model"):  # last: the paper's own settings first
                changed += self.reset_setting("paper_model")
        self.say(f"reset {changed} setting{'s' * (changed != 1)}" if changed else "all settings at their defaults")
        return changed

    # ------------------------------------------------------------------ camera bookmarks
    def _bookmark_number(self, n) -> int:
        n = int(n)
        if not 1 <= n <= BOOKMARKS:
            raise ValueError(f"camera bookmark must be 1 … {BOOKMARKS}, got {n}")
        return n

    def store_bookmark(self, n: int) -> None:
        """Store the camera (orbit, distance, pivot) as bookmark ``n`` (1 … :data:`BOOKMARKS`;
        ValueError otherwise); bookmarks are kept while the tree changes."""
        n = self._bookmark_number(n)
        c = self.camera
        self.bookmarks[n] = (c.azimuth, c.elevation, c.distance, c.target.copy(), c.shift.copy())
        self.say(f"camera bookmark {n} stored")

    def recall_bookmark(self, n: int) -> bool:
        """Move the camera to bookmark ``n``. Returns False (said in the status line) where none
        is stored."""
        n = self._bookmark_number(n)
        if n not in self.bookmarks:
            self.say(f"no camera bookmark {n} (Ctrl+{n} stores one)")
            return False
        c = self.camera
        c.azimuth, c.elevation, c.distance, target, shift = self.bookmarks[n]
        c.target, c.shift = target.copy(), shift.copy()
        self.say(f"camera bookmark {n}")
        return True

    # ------------------------------------------------------------------ draft mode
    def set_draft(self, on: bool) -> None:
        """Draft mode on or off: the scene drawn at :data:`DRAFT_SCALE` of the pixels a side,
        without MSAA and without shadows, for software renderers (llvmpipe); the panel's
        status line says so."""
        self.draft = bool(on)
        self.say("draft mode: half resolution, no MSAA, no shadows" if self.draft else "draft mode off")

    def toggle_draft(self) -> None:
        """Draft mode on or off (:meth:`set_draft`)."""
        self.set_draft(not self.draft)
