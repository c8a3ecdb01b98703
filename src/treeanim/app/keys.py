"""The viewer's controls in one table: :data:`BINDINGS` (key → action, description) drives
both :meth:`Viewer.on_key <treeanim.app.viewer.Viewer.on_key>` and the panel's Controls help
(:func:`help_lines`); :data:`MOUSE` describes the mouse."""

from __future__ import annotations

from dataclasses import dataclass

import glfw

__all__ = ["Binding", "BINDINGS", "MOUSE", "binding_for", "help_lines"]


@dataclass(frozen=True)
class Binding:
    """One shortcut.

    Attributes
    ----------
    keys : tuple of int
        GLFW key codes that trigger it.
    label : str
        The keys as the help shows them.
    action : str
        The :class:`~treeanim.app.viewer.Viewer` method it calls (no arguments).
    does : str
        What it does, for the help.
    ctrl : bool
        Only with Ctrl held (and never without it).
    shift : bool or None
        Only with Shift held (True), never with it (False), either way (None).
    numbered : bool
        The action takes the key's number: 1 for the first of :attr:`keys`, 2 for the next …
    """

    keys: tuple[int, ...]
    label: str
    action: str
    does: str
    ctrl: bool = False
    shift: bool | None = None
    numbered: bool = False

    def args(self, key: int) -> tuple:
        """The arguments the action takes for a press of ``key``."""
        return (self.keys.index(key) + 1,) if self.numbered else ()


_DIGITS = (glfw.KEY_1, glfw.KEY_2, glfw.KEY_3, glfw.KEY_4)


#: Every shortcut, in the order the help lists them.
BINDINGS = (
    Binding((glfw.KEY_F,), "F", "frame_camera", "frame the tree"),
    Binding((glfw.KEY_SPACE,), "Space", "toggle_pause", "pause (resume: from the timeline's state)"),
    Binding((glfw.KEY_LEFT,), "Left", "step_back", "pause, step back"),
    Binding((glfw.KEY_RIGHT,), "Right", "step_forward", "step forward"),
    Binding((glfw.KEY_P,), "P", "pin", "pin the branch dragged (or let go with Shift)", shift=False),
    Binding((glfw.KEY_P,), "Shift+P", "unpin", "unpin all", shift=True),
    Binding((glfw.KEY_R,), "R", "reset", "reset"),
    Binding((glfw.KEY_H,), "H", "toggle_panel", "hide the panel"),
    Binding((glfw.KEY_S, glfw.KEY_F12), "S/F12", "request_screenshot", "screenshot"),
    Binding((glfw.KEY_F11,), "F11", "toggle_fullscreen", "full screen"),
    Binding((glfw.KEY_S,), "Ctrl+S", "save_preset", "save the preset", ctrl=True),
    Binding((glfw.KEY_O,), "Ctrl+O", "open_file", "load it", ctrl=True),
    Binding((glfw.KEY_Z,), "Ctrl+Z", "undo", "undo a setting", ctrl=True, shift=False),
    Binding((glfw.KEY_Y,), "Ctrl+Y", "redo", "redo", ctrl=True),
    Binding((glfw.KEY_Z,), "Ctrl+Shift+Z", "redo", "redo", ctrl=True, shift=True),
    Binding(_DIGITS, "Ctrl+1–4", "store_bookmark", "store the camera", ctrl=True, numbered=True),
    Binding(_DIGITS, "1–4", "recall_bookmark", "recall it", numbered=True),
    Binding((glfw.KEY_D,), "D", "toggle_draft", "draft mode (fast)"),
    Binding((glfw.KEY_ESCAPE, glfw.KEY_Q), "Esc/Q", "quit", "quit"),
)
#: The mouse: (what, does).
MOUSE = (
    ("left-drag a branch or leaf", "drag it, let go: swing"),
    ("left-drag the sky", "orbit"),
    ("right/middle-drag", "pan"),
    ("wheel", "zoom"),
    ("right-click a panel setting", "back to its default"),
)


def binding_for(key: int, mods: int) -> Binding | None:
    """The binding a press of ``key`` with modifier bits ``mods`` triggers, or None."""
    ctrl, shift = bool(mods & glfw.MOD_CONTROL), bool(mods & glfw.MOD_SHIFT)
    return next((b for b in BINDINGS if b.ctrl == ctrl and key in b.keys and b.shift in (None, shift)), None)


def help_lines() -> list[str]:
    """The controls as short lines: the mouse's, then two shortcuts a line."""
    lines = [f"{what}: {does}" for what, does in MOUSE]
    keys = [f"{b.label} {b.does}" for b in BINDINGS]
    return lines + ["   ".join(keys[i:i + 2]) for i in range(0, len(keys), 2)]
