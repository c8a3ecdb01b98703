"""The viewer's GLFW window: OpenGL 3.3 core (forward-compatible), MSAA where available, vsync,
and a moderngl context made from it; one of the two :class:`~treeanim.app.protocol.AppWindow`
implementations (the other: :class:`~treeanim.app.headless.HeadlessWindow`).

Anything that keeps the window from opening (no display, no GLFW, no OpenGL 3.3) is raised as
:class:`ViewerUnavailable` carrying one line that says what is missing and points to the
headless commands.
"""

from __future__ import annotations

import ctypes
import re

import glfw

# imgui_bundle ships its own libglfw; importing it first makes pyGLFW load that same library, so
# the process holds one GLFW state (the order matters only when both are imported).
import imgui_bundle  # noqa: F401  (side effect: PYGLFW_LIBRARY)
import moderngl
import numpy as np

from ..errors import ViewerUnavailable
from .display import HEADLESS_HINT, check_display
from .protocol import gl_max_pixels

__all__ = ["Window", "ViewerUnavailable", "HEADLESS_HINT", "SOFTWARE_RENDERER"]

#: Windows open now: GLFW is stopped when the last one closes.
_open_windows: set = set()


#: GL_RENDERER strings of software rasterisers.
SOFTWARE_RENDERER = re.compile(r"llvmpipe|softpipe|swrast|software|swiftshader", re.IGNORECASE)


def _samples() -> int:
    """GL_SAMPLES of the current context's default framebuffer."""
    try:
        from OpenGL import GL  # PyOpenGL

        return int(GL.glGetIntegerv(GL.GL_SAMPLES))
    except Exception:  # pragma: no cover - PyOpenGL missing or unusable
        return 0


def _one_line(text) -> str:
    if isinstance(text, bytes):
        text = text.decode("utf-8", "replace")
    return " ".join(str(text).split())


class Window:
    """A GLFW window with a current OpenGL >= 3.3 core context and its moderngl context.

    Use :meth:`open`; the constructor is internal.

    Attributes
    ----------
    handle : GLFW window pointer
    ctx : moderngl.Context
    samples : int
        MSAA samples of the window's framebuffer (0: none).
    """

    def __init__(self, handle, ctx: moderngl.Context, samples: int, errors: list[str], previous_error_cb) -> None:
        self.handle = handle
        self.ctx = ctx
        self.samples = samples
        self.errors = errors
        self._previous_error_cb = previous_error_cb
        self._windowed: tuple[int, int, int, int] | None = None
        self._callbacks: list = []  # keep the Python callables alive
        self._closed = False
        self._readback = None  # ((w, h), framebuffer, renderbuffer) for read_pixels
        scale = self.content_scale
        most = int(self.max_pixels / scale)  # the window manager keeps the window within the GL's limits
        glfw.set_window_size_limits(handle, glfw.DONT_CARE, glfw.DONT_CARE, most, most)

    # ------------------------------------------------------------------ creation
    @classmethod
    def open(cls, width: int = 1280, height: int = 720, title: str = "treeanim", *, visible: bool = True,
             samples: int | None = None, vsync: bool = True) -> "Window":
        """Open a window of ``width`` × ``height`` screen units.

        Parameters
        ----------
        samples : int or None
            MSAA samples (falls back to none where the display has no multisampled
            configuration). None: 4, except on a software rasteriser (Mesa llvmpipe, softpipe,
            SwiftShader), where 4× MSAA makes every frame some 2.5 times slower: none there.
        vsync : bool
            Swap on the display's refresh (swap interval 1).

        Raises
        ------
        ViewerUnavailable
            No display, GLFW cannot start, or no OpenGL 3.3 core context.
        """
        check_display()
        errors: list[str] = []

        def on_error(code, description):
            errors.append(_one_line(description))
            del errors[:-20]

        previous = glfw.set_error_callback(on_error)
        try:
            if not glfw.init():
                why = errors[-1] if errors else "unknown reason"
                raise ViewerUnavailable(f"cannot start GLFW ({why}); {HEADLESS_HINT}")
            auto = samples is None
            handle, ctx = cls._create(width, height, title, 4 if auto else max(int(samples), 0), visible and not auto,
                                      errors)
            if auto:
                if SOFTWARE_RENDERER.search(ctx.info.get("GL_RENDERER", "")) and _samples() > 0:
                    ctx.release()
                    glfw.destroy_window(handle)
                    handle, ctx = cls._create(width, height, title, 0, False, errors)
                glfw.make_context_current(handle)
                if visible:
                    glfw.show_window(handle)
            glfw.swap_interval(1 if vsync else 0)
            win = cls(handle, ctx, _samples(), errors, previous)
            _open_windows.add(id(win))
            return win
        except BaseException:
            if not _open_windows:
                glfw.set_error_callback(previous)
                glfw.terminate()
            raise

    @staticmethod
    def _create(width: int, height: int, title: str, samples: int, visible: bool, errors: list[str]):
        handle = None
        for s in ([samples, 0] if samples > 0 else [0]):
            glfw.default_window_hints()
            glfw.window_hint(glfw.CONTEXT_VERSION_MAJOR, 3)
            glfw.window_hint(glfw.CONTEXT_VERSION_MINOR, 3)
            glfw.window_hint(glfw.OPENGL_PROFILE, glfw.OPENGL_CORE_PROFILE)
            glfw.window_hint(glfw.OPENGL_FORWARD_COMPAT, True)
            glfw.window_hint(glfw.SAMPLES, s)
            glfw.window_hint(glfw.VISIBLE, bool(visible))
            glfw.window_hint(glfw.SCALE_TO_MONITOR, True)
            handle = glfw.create_window(max(int(width), 1), max(int(height), 1), title, None, None)
            if handle:
                break
        if not handle:
            why = errors[-1] if errors else "no reason given"
            raise ViewerUnavailable(f"no OpenGL 3.3 core context for a window ({why}); {HEADLESS_HINT}")
        glfw.make_context_current(handle)
        try:
            ctx = moderngl.create_context(require=330)
        except Exception as exc:  # moderngl raises plain Exceptions
            glfw.destroy_window(handle)
            raise ViewerUnavailable(f"no OpenGL 3.3 context ({_one_line(exc)}); {HEADLESS_HINT}") from None
        return handle, ctx

    def make_current(self) -> None:
        """Make this window's GL context current on this thread (if another one is)."""
        cur = glfw.get_current_context()
        if not cur or ctypes.addressof(cur.contents) != ctypes.addressof(self.handle.contents):
            glfw.make_context_current(self.handle)

    # ------------------------------------------------------------------ queries
    @property
    def size(self) -> tuple[int, int]:
        """Window size in screen units (what cursor positions are measured in)."""
        return tuple(glfw.get_window_size(self.handle))

    @property
    def framebuffer_size(self) -> tuple[int, int]:
        """Framebuffer size in pixels (0 × 0 when minimised)."""
        return tuple(glfw.get_framebuffer_size(self.handle))

    @property
    def framebuffer(self) -> moderngl.Framebuffer:
        """The window's default framebuffer (its back buffer), which a frame is drawn into."""
        return self.ctx.screen

    @property
    def max_pixels(self) -> int:
        """The largest side, in pixels, the GL can draw and read back (viewport, renderbuffer and
        texture limits): a larger window is drawn only up to it."""
        return gl_max_pixels(self.ctx)

    def shrink_to(self, most: int) -> None:
        """Make the window at most ``most`` pixels a side (where no window manager did)."""
        w, h = glfw.get_window_size(self.handle)
        fw, fh = glfw.get_framebuffer_size(self.handle)
        scale = max(fw / max(w, 1), fh / max(h, 1), 1e-6)
        glfw.set_window_size(self.handle, min(w, int(most / scale)), min(h, int(most / scale)))

    @property
    def content_scale(self) -> float:
        """The monitor's content scale (1 on a plain display, 2 on a 'retina' one)."""
        try:
            return float(max(glfw.get_window_content_scale(self.handle)))
        except Exception:  # pragma: no cover
            return 1.0

    @property
    def should_close(self) -> bool:
        """Whether the user (or :meth:`request_close`) asked the window to close."""
        return bool(glfw.window_should_close(self.handle))

    def request_close(self) -> None:
        """Ask the main loop to stop."""
        glfw.set_window_should_close(self.handle, True)

    @property
    def fullscreen(self) -> bool:
        """Whether the window covers a monitor (see :meth:`toggle_fullscreen`)."""
        return glfw.get_window_monitor(self.handle) is not None and bool(glfw.get_window_monitor(self.handle))

    def toggle_fullscreen(self) -> None:
        """Switch between a window and full screen on the primary monitor."""
        if self.fullscreen:
            x, y, w, h = self._windowed or (100, 100, 1280, 720)
            glfw.set_window_monitor(self.handle, None, x, y, w, h, 0)
            return
        monitor = glfw.get_primary_monitor()
        if not monitor:
            return
        mode = glfw.get_video_mode(monitor)
        x, y = glfw.get_window_pos(self.handle)
        w, h = glfw.get_window_size(self.handle)
        self._windowed = (x, y, w, h)
        glfw.set_window_monitor(self.handle, monitor, 0, 0, mode.size.width, mode.size.height, mode.refresh_rate)

    # ------------------------------------------------------------------ loop
    def connect(self, viewer) -> None:
        """Route the window's GLFW callbacks to ``viewer``'s input handlers."""
        h = self.handle
        cbs = [
            (glfw.set_cursor_pos_callback, lambda w, x, y: viewer.on_cursor_pos(x, y)),
            (glfw.set_mouse_button_callback, lambda w, b, a, m: viewer.on_mouse_button(b, a, m)),
            (glfw.set_scroll_callback, lambda w, dx, dy: viewer.on_scroll(dx, dy)),
            (glfw.set_key_callback, lambda w, k, s, a, m: viewer.on_key(k, s, a, m)),
            (glfw.set_char_callback, lambda w, c: viewer.on_char(c)),
            (glfw.set_framebuffer_size_callback, lambda w, x, y: viewer.on_resize(x, y)),
            (glfw.set_window_size_callback, lambda w, x, y: viewer.on_window_size(x, y)),
            (glfw.set_window_focus_callback, lambda w, f: viewer.on_focus(bool(f))),
            (glfw.set_cursor_enter_callback, lambda w, e: viewer.on_cursor_enter(bool(e))),
            (glfw.set_window_refresh_callback, lambda w: viewer.on_refresh()),
        ]
        self._callbacks = [fn for _, fn in cbs]
        for setter, fn in cbs:
            setter(h, fn)

    def swap(self) -> None:
        """Show the frame drawn into the back buffer (waits for the display's refresh when the
        window was opened with ``vsync``)."""
        glfw.swap_buffers(self.handle)

    @staticmethod
    def poll() -> None:
        """Process the input and window events waiting now, without blocking.

        Notes
        -----
        GLFW calls the callbacks set by :meth:`connect` from within this call, on this thread.
        """
        glfw.poll_events()

    @staticmethod
    def wait(timeout: float) -> None:
        """Sleep until an event arrives or ``timeout`` passes, then process the events.

        Parameters
        ----------
        timeout : float
            Longest wait, seconds (> 0).
        """
        glfw.wait_events_timeout(timeout)

    @staticmethod
    def now() -> float:
        """GLFW's clock, seconds."""
        return glfw.get_time()

    def read_pixels(self, width: int, height: int) -> np.ndarray:
        """The back buffer's ``width`` × ``height`` pixels as drawn so far, (height, width, 3)
        uint8, row 0 at the top (a multisampled buffer is resolved first)."""
        if width <= 0 or height <= 0:
            return np.zeros((max(height, 0), max(width, 0), 3), np.uint8)
        from OpenGL import GL

        self.make_current()
        ctx = self.ctx
        if self._readback is None or self._readback[0] != (width, height):
            self.release_readback()
            rb = ctx.renderbuffer((width, height), 4)
            self._readback = ((width, height), ctx.framebuffer([rb]), rb)
        fbo = self._readback[1]
        GL.glBindFramebuffer(GL.GL_READ_FRAMEBUFFER, 0)
        GL.glReadBuffer(GL.GL_BACK)
        GL.glBindFramebuffer(GL.GL_DRAW_FRAMEBUFFER, fbo.glo)
        GL.glBlitFramebuffer(0, 0, width, height, 0, 0, width, height, GL.GL_COLOR_BUFFER_BIT, GL.GL_NEAREST)
        data = fbo.read(components=3, alignment=1)
        ctx.screen.use()
        img = np.frombuffer(data, np.uint8).reshape(height, width, 3)
        return np.ascontiguousarray(img[::-1])

    def release_readback(self) -> None:
        """Free :meth:`read_pixels`' buffers (made again when next needed)."""
        if self._readback is not None:
            self.make_current()
            self.ctx.screen.use()
            for o in self._readback[1:]:
                o.release()
            self._readback = None

    def get_clipboard(self) -> str:
        """The system clipboard's text ('' when it holds none)."""
        text = glfw.get_clipboard_string(self.handle)
        return text.decode("utf-8", "replace") if text else ""

    def set_clipboard(self, text: str) -> None:
        """Put ``text`` on the system clipboard."""
        glfw.set_clipboard_string(self.handle, text)

    def close(self) -> None:
        """Destroy the window and stop GLFW (idempotent)."""
        if self._closed:
            return
        self._closed = True
        try:
            self.release_readback()
            self.ctx.release()
        except Exception:  # pragma: no cover
            pass
        glfw.destroy_window(self.handle)
        _open_windows.discard(id(self))
        if not _open_windows:  # the last window: stop GLFW, restore the error callback
            glfw.terminate()
            glfw.set_error_callback(self._previous_error_cb)

    def __enter__(self) -> "Window":
        return self

    def __exit__(self, *exc) -> None:
        self.close()
