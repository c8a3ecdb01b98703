"""Dear ImGui (imgui-bundle) on the viewer's window: the platform part is ours (input fed from
the viewer's handlers, the display size and frame time given to :meth:`Gui.new_frame`, the
clipboard the window's), drawing goes through imgui-bundle's C++ OpenGL 3 backend. So the same
panel runs in a GLFW window and headless on EGL (:mod:`treeanim.app.headless`).

Why not imgui-bundle's C++ GLFW backend (``imgui.backends.glfw_init_for_opengl``)? It needs the
``GLFWwindow*`` of the very libglfw it links; pyGLFW loads that library only when imgui_bundle
is imported first (it sets ``PYGLFW_LIBRARY``), and otherwise a second copy with a state of its
own, whose windows the C++ backend must not touch. Feeding ImGui's IO from the viewer's input
handlers works with either library, and lets tests drive the panel through the same handlers
as a user, with or without a window system. Key and button codes are GLFW's numbers (plain
constants: no GLFW call is made here). The renderer (``imgui.backends.opengl3_*``) only needs
the current GL context, a GLFW window's or an EGL one.
"""

from __future__ import annotations

import os

import glfw
from imgui_bundle import imgui, implot

#: GLFW key → ImGui key, for the keys a panel uses (text fields, navigation, shortcuts).
_KEYS: dict[int, "imgui.Key"] = {
    glfw.KEY_TAB: imgui.Key.tab, glfw.KEY_LEFT: imgui.Key.left_arrow, glfw.KEY_RIGHT: imgui.Key.right_arrow,
    glfw.KEY_UP: imgui.Key.up_arrow, glfw.KEY_DOWN: imgui.Key.down_arrow, glfw.KEY_PAGE_UP: imgui.Key.page_up,
    glfw.KEY_PAGE_DOWN: imgui.Key.page_down, glfw.KEY_HOME: imgui.Key.home, glfw.KEY_END: imgui.Key.end,
    glfw.KEY_INSERT: imgui.Key.insert, glfw.KEY_DELETE: imgui.Key.delete, glfw.KEY_BACKSPACE: imgui.Key.backspace,
    glfw.KEY_SPACE: imgui.Key.space, glfw.KEY_ENTER: imgui.Key.enter, glfw.KEY_ESCAPE: imgui.Key.escape,
    glfw.KEY_KP_ENTER: imgui.Key.keypad_enter, glfw.KEY_LEFT_CONTROL: imgui.Key.left_ctrl,
    glfw.KEY_RIGHT_CONTROL: imgui.Key.right_ctrl, glfw.KEY_LEFT_SHIFT: imgui.Key.left_shift,
    glfw.KEY_RIGHT_SHIFT: imgui.Key.right_shift, glfw.KEY_LEFT_ALT: imgui.Key.left_alt,
    glfw.KEY_RIGHT_ALT: imgui.Key.right_alt, glfw.KEY_LEFT_SUPER: imgui.Key.left_super,
    glfw.KEY_RIGHT_SUPER: imgui.Key.right_super, glfw.KEY_MINUS: imgui.Key.minus,
    glfw.KEY_PERIOD: imgui.Key.period, glfw.KEY_SLASH: imgui.Key.slash, glfw.KEY_COMMA: imgui.Key.comma,
}
_KEYS.update({glfw.KEY_A + i: getattr(imgui.Key, chr(ord("a") + i)) for i in range(26)})
_KEYS.update({glfw.KEY_0 + i: getattr(imgui.Key, f"_{i}") for i in range(10)})
_KEYS.update({glfw.KEY_F1 + i: getattr(imgui.Key, f"f{i + 1}") for i in range(12)})

#: GLFW mouse button → ImGui mouse button (left, right, middle).
_BUTTONS = {glfw.MOUSE_BUTTON_LEFT: 0, glfw.MOUSE_BUTTON_RIGHT: 1, glfw.MOUSE_BUTTON_MIDDLE: 2}


def _font_path() -> str | None:
    import imgui_bundle

    path = os.path.join(os.path.dirname(imgui_bundle.__file__), "assets", "fonts", "Roboto", "Roboto-Regular.ttf")
    return path if os.path.isfile(path) else None


class Gui:
    """One ImGui context drawn into the current OpenGL 3.3 context.

    Parameters
    ----------
    clipboard : object or None
        Where the text fields copy to and paste from: anything with ``get_clipboard()`` and
        ``set_clipboard(text)`` (the window: :class:`~treeanim.app.protocol.AppWindow`); None:
        no clipboard.
    scale : float
        UI scale (the monitor's content scale): font size and spacing.
    font_size : float
        Font size in pixels at scale 1.

    Notes
    -----
    Per frame: :meth:`new_frame`, build widgets with ``imgui.*``, :meth:`render`. Input goes in
    through :meth:`mouse_pos`, :meth:`mouse_button`, :meth:`scroll`, :meth:`key`, :meth:`char`
    and :meth:`focus` at any time between frames.
    """

    def __init__(self, clipboard=None, scale: float = 1.0, font_size: float = 15.0) -> None:
        self.scale = float(scale)
        self.ctx = imgui.create_context()
        imgui.set_current_context(self.ctx)
        self.plot_ctx = implot.create_context()  # the panel's live plots (ImPlot)
        self.io = io = imgui.get_io()
        io.set_ini_filename(None)  # no imgui.ini in the user's folder
        io.config_flags &= ~imgui.ConfigFlags_.nav_enable_keyboard
        imgui.style_colors_dark()
        style = imgui.get_style()
        style.window_rounding = 6.0
        style.frame_rounding = 3.0
        style.grab_rounding = 3.0
        style.window_border_size = 0.0
        style.frame_padding = imgui.ImVec2(6.0, 2.0)
        style.item_spacing = imgui.ImVec2(6.0, 3.0)
        c = style.color_(imgui.Col_.window_bg)
        style.set_color_(imgui.Col_.window_bg, imgui.ImVec4(c.x, c.y, c.z, 0.86))
        # a slider's knob narrow and see-through: its value, drawn over it, stays readable
        style.grab_min_size = 5.0
        for col, alpha in ((imgui.Col_.slider_grab, 0.45), (imgui.Col_.slider_grab_active, 0.7)):
            c = style.color_(col)
            style.set_color_(col, imgui.ImVec4(c.x, c.y, c.z, alpha))
        if scale != 1.0:
            style.scale_all_sizes(scale)
        path = _font_path()
        if path is not None:
            io.fonts.add_font_from_file_ttf(path, font_size * scale)
        if clipboard is not None:
            pio = imgui.get_platform_io()
            pio.platform_get_clipboard_text_fn = lambda _ctx: clipboard.get_clipboard()
            pio.platform_set_clipboard_text_fn = lambda _ctx, text: clipboard.set_clipboard(text)
        if not imgui.backends.opengl3_init("#version 330 core"):
            raise RuntimeError("imgui's OpenGL 3 renderer could not start")
        self._released = False
        self.in_frame = False

    # ------------------------------------------------------------------ input
    def mouse_pos(self, x: float, y: float) -> None:
        """The cursor moved.

        Parameters
        ----------
        x, y : float
            Position in screen units (window coordinates, origin at the top left).
        """
        self.io.add_mouse_pos_event(float(x), float(y))

    def mouse_left(self) -> None:
        """The cursor left the window (ImGui hovers nothing until the next :meth:`mouse_pos`)."""
        self.io.add_mouse_pos_event(-3.4e38, -3.4e38)

    def mouse_button(self, button: int, down: bool) -> None:
        """A mouse button went down or up.

        Parameters
        ----------
        button : int
            GLFW button (``glfw.MOUSE_BUTTON_LEFT``, ``_RIGHT``, ``_MIDDLE``; others are ignored).
        down : bool
            True when pressed, False when released.
        """
        b = _BUTTONS.get(button)
        if b is not None:
            self.io.add_mouse_button_event(b, bool(down))

    def scroll(self, dx: float, dy: float) -> None:
        """The wheel (or a touchpad) scrolled.

        Parameters
        ----------
        dx, dy : float
            Notches, as GLFW reports them (``dy > 0``: away from the user, scrolls up).
        """
        self.io.add_mouse_wheel_event(float(dx), float(dy))

    def key(self, key: int, action: int, mods: int) -> None:
        """A key went down, repeated or up.

        Parameters
        ----------
        key : int
            GLFW key code (keys ImGui has no use for only update the modifiers).
        action : int
            ``glfw.PRESS``, ``glfw.REPEAT`` or ``glfw.RELEASE``.
        mods : int
            GLFW modifier bits (``glfw.MOD_CONTROL`` ...) held at the time.
        """
        io = self.io
        io.add_key_event(imgui.Key.mod_ctrl, bool(mods & glfw.MOD_CONTROL))
        io.add_key_event(imgui.Key.mod_shift, bool(mods & glfw.MOD_SHIFT))
        io.add_key_event(imgui.Key.mod_alt, bool(mods & glfw.MOD_ALT))
        io.add_key_event(imgui.Key.mod_super, bool(mods & glfw.MOD_SUPER))
        k = _KEYS.get(key)
        if k is not None:
            io.add_key_event(k, action != glfw.RELEASE)

    def char(self, codepoint: int) -> None:
        """A character was typed (text fields take their text from here, not from :meth:`key`).

        Parameters
        ----------
        codepoint : int
            Unicode code point.
        """
        self.io.add_input_character(int(codepoint))

    def focus(self, focused: bool) -> None:
        """The window gained (True) or lost (False) the keyboard focus (on losing it ImGui
        forgets the keys it thought held)."""
        self.io.add_focus_event(bool(focused))

    @property
    def wants_mouse(self) -> bool:
        """ImGui uses the mouse (hovering or dragging a widget, a popup open)."""
        return bool(self.io.want_capture_mouse)

    @property
    def wants_keyboard(self) -> bool:
        """ImGui uses the keyboard (typing in a field, a widget active)."""
        return bool(self.io.want_capture_keyboard)

    # ------------------------------------------------------------------ frames
    def new_frame(self, width: int, height: int, fb_width: int, fb_height: int, dt: float) -> None:
        """Begin a frame over a window of ``width`` × ``height`` screen units."""
        imgui.set_current_context(self.ctx)
        implot.set_current_context(self.plot_ctx)
        io = self.io
        io.display_size = imgui.ImVec2(float(width), float(height))
        if width > 0 and height > 0:
            io.display_framebuffer_scale = imgui.ImVec2(fb_width / width, fb_height / height)
        io.delta_time = float(min(max(dt, 1e-4), 0.25))
        imgui.backends.opengl3_new_frame()
        imgui.new_frame()
        self.in_frame = True

    def render(self) -> None:
        """End the frame and draw it over whatever is in the bound framebuffer."""
        imgui.render()
        self.in_frame = False
        imgui.backends.opengl3_render_draw_data(imgui.get_draw_data())

    def end_frame_without_drawing(self) -> None:
        """End a frame begun with :meth:`new_frame` and draw nothing."""
        if self.in_frame:
            imgui.end_frame()
            self.in_frame = False

    def release(self) -> None:
        """Free the GL objects and the context (idempotent; the GL context must be current)."""
        if self._released:
            return
        self._released = True
        imgui.set_current_context(self.ctx)
        if self.in_frame:
            imgui.end_frame()
        imgui.backends.opengl3_shutdown()
        implot.destroy_context(self.plot_ctx)
        imgui.destroy_context(self.ctx)
