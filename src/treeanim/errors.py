"""Every exception treeanim raises of its own: bad input, and no way to draw here.

Bad input is a :class:`ValueError` (:class:`InputError`, and :class:`PresetError` for a preset
file), so callers that catch ValueError keep working; the command line prints it as one line
and exits with status 2. A missing capability is a :class:`RuntimeError` whose message says
what to install or use instead. This module imports nothing, so every layer may use it.
"""

from __future__ import annotations

__all__ = ["InputError", "UsageError", "PresetError", "QSMError", "SceneError", "GLUnavailable", "ViewerUnavailable"]


class InputError(ValueError):
    """Bad user input (an option, a path, a number out of range); ``str(exc)`` is one line
    naming what was given and what is expected."""


class UsageError(InputError):
    """Bad command-line input found by the command line itself."""


class PresetError(InputError):
    """A preset file that cannot be used: the message names the file, the key and what was
    expected, on one line."""


class QSMError(PresetError):
    """A TreeQSM cylinder model that cannot be used: one line naming the file, the row (the
    cylinder's number, 1-based as TreeQSM counts) and what was wrong."""


class SceneError(PresetError):
    """A scene file that cannot be used: one line naming the file, the key (``trees[3].scale``,
    ``scatter[0].count``) and what was expected."""


class GLUnavailable(RuntimeError):
    """No OpenGL context to render offscreen with (the message says what to install)."""


class ViewerUnavailable(RuntimeError):
    """The viewer cannot open its window here; ``str(exc)`` is one line saying why."""
