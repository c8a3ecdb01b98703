"""The viewer's input handlers: what a GLFW window's callbacks call, and what tests and scripts
call directly on a headless app. Buttons, actions and keys are GLFW's codes (plain constants).

A left-drag on an object drags it (the tree model; the paper's pulls it with a spring; let go
with Shift held, the drag stays pinned), elsewhere it orbits; a right or middle drag pans, the wheel
zooms; keys act through the table in :mod:`treeanim.app.keys`; the panel gets the mouse and
the keyboard while it wants them. Mixed into :class:`treeanim.app.viewer.Viewer`, whose
camera, panel, gui, window and grabs they drive.
"""

from __future__ import annotations

import glfw

from .keys import binding_for

#: Orbit speed, degrees per screen unit of drag.
ORBIT_DEG_PER_UNIT = 0.35
#: Zoom factor per wheel notch.
ZOOM_PER_NOTCH = 0.88


class ViewerInput:
    """Input handlers of a :class:`~treeanim.app.viewer.Viewer` (screen units, origin at the
    window's top left, y down)."""

    _mode: str | None = None  # 'orbit', 'pan', 'pull' (a grab: drag or pull) while a button is held
    _mode_button: int | None = None
    _cursor = (0.0, 0.0)

    def _end_drag(self) -> None:
        """Let go of whatever a held button was doing (a grab is released)."""
        self.end_pull()
        self._mode = None
        self._mode_button = None

    def _over_panel(self, x: float, y: float) -> bool:
        return self.show_panel and self.panel.owns_mouse(x, y)

    def on_cursor_pos(self, x: float, y: float) -> None:
        """Cursor moved to (x, y) screen units, origin top-left."""
        px, py = self._cursor
        self._cursor = (float(x), float(y))
        if self.show_panel:
            self.gui.mouse_pos(x, y)
        dx, dy = x - px, y - py
        if self._mode == "orbit":
            self.camera.orbit(-ORBIT_DEG_PER_UNIT * dx, ORBIT_DEG_PER_UNIT * dy)
        elif self._mode == "pan":
            self.camera.pan(dx, dy, max(self._win[1], 1))
        elif self._mode == "pull" and self.grab is not None:
            self.grab.aim(*self._ray(x, y))

    def on_mouse_button(self, button: int, action: int, mods: int = 0) -> None:
        """A mouse button went down (``glfw.PRESS``) or up (``glfw.RELEASE``)."""
        x, y = self._cursor
        if action == glfw.PRESS:
            over = self._over_panel(x, y)
            if self.show_panel:
                self.gui.mouse_button(button, True)
            if over or self._mode is not None:
                return
            if button == glfw.MOUSE_BUTTON_LEFT:
                self._mode = "pull" if self.start_pull(x, y) else "orbit"
            elif button in (glfw.MOUSE_BUTTON_RIGHT, glfw.MOUSE_BUTTON_MIDDLE):
                self._mode = "pan"
            else:
                return
            self._mode_button = button
        elif action == glfw.RELEASE:
            self.gui.mouse_button(button, False)
            if button == self._mode_button:
                # let go with Shift held: the drag stays, pinned (hold.py)
                if not (mods & glfw.MOD_SHIFT and self._mode == "pull" and self.pin()):
                    self._end_drag()

    def on_scroll(self, dx: float, dy: float) -> None:
        """Wheel turned (dy > 0: away from the user, zooms in)."""
        if self._over_panel(*self._cursor):
            self.gui.scroll(dx, dy)
            return
        self.camera.zoom(ZOOM_PER_NOTCH ** float(dy))

    def on_char(self, codepoint: int) -> None:
        """A character was typed (for the panel's text fields)."""
        if self.show_panel:
            self.gui.char(codepoint)

    def on_key(self, key: int, scancode: int, action: int, mods: int) -> None:
        """A key went down, repeated or up. Shortcuts act on presses while the panel does not
        want the keyboard."""
        if self.show_panel or action == glfw.RELEASE:
            self.gui.key(key, action, mods)
        if action != glfw.PRESS or (self.show_panel and self.gui.wants_keyboard):
            return
        binding = binding_for(key, mods)
        if binding is not None:
            getattr(self, binding.action)(*binding.args(key))

    def on_resize(self, width: int, height: int) -> None:
        """The framebuffer is now ``width`` × ``height`` pixels (0 × 0: minimised). Beyond the
        GL's largest size (no window manager kept it within) the window is shrunk back, and
        drawn only up to that size meanwhile."""
        most = self.window.max_pixels
        if width > most or height > most:
            self.window.shrink_to(most)
        self._fb = (min(max(int(width), 0), most), min(max(int(height), 0), most))
        try:
            self._win = tuple(self.window.size)
        except Exception:  # pragma: no cover
            self._win = self._fb

    def on_window_size(self, width: int, height: int) -> None:
        """The window is now ``width`` × ``height`` screen units."""
        self._win = (max(int(width), 0), max(int(height), 0))

    def on_focus(self, focused: bool) -> None:
        """Focus gained or lost; losing it ends any mouse drag and lets go of a grab."""
        self.gui.focus(focused)
        if not focused:
            self._end_drag()

    def on_cursor_enter(self, entered: bool) -> None:
        if not entered:
            self.gui.mouse_left()

    def on_refresh(self) -> None:
        """The window needs redrawing (nothing to do: the loop draws continuously)."""
