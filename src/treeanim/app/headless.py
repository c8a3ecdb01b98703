"""A window without a display: :class:`HeadlessWindow`, an EGL context (Mesa llvmpipe where there
is no GPU) drawing into an offscreen framebuffer, for the viewer with no X server.

It implements :class:`~treeanim.app.protocol.AppWindow` as the GLFW window does, so
``Viewer(HeadlessWindow(1280, 720), tree)`` is the whole app, imgui panel included: the viewer's
input handlers (``on_cursor_pos``, ``on_mouse_button``, ``on_key`` …) are called directly, a
frame is :meth:`Viewer.frame <treeanim.app.viewer.Viewer.frame>`, and :meth:`read_pixels` reads
what it drew. What a window system would do is a method here: :meth:`resize` (0 × 0: minimised)
queues the size events that :meth:`poll` delivers to the connected viewer, as GLFW's callbacks
do; :meth:`request_close` ends :func:`~treeanim.app.viewer.run`.
"""

from __future__ import annotations

import time

import moderngl
import numpy as np

from ..render.offscreen import create_egl_context
from .protocol import gl_max_pixels

__all__ = ["HeadlessWindow"]


class HeadlessWindow:
    """An offscreen "window" of ``width`` × ``height`` screen units on an EGL context.

    Parameters
    ----------
    width, height : int
        Size in screen units (0 × 0: minimised).
    samples : int
        MSAA samples (down to a power of two and what the context supports; 0: none, as the
        viewer on a software rasteriser).
    content_scale : float
        Pixels per screen unit (2 stands for a 'retina' display): the framebuffer is the size ×
        this, and the panel's UI scale.

    Attributes
    ----------
    ctx : moderngl.Context
        The EGL context, current from construction to :meth:`close`.
    samples : int
    swaps : int
        Frames shown (:meth:`swap` calls).
    handle : None
        No window-system handle.

    Raises
    ------
    RuntimeError
        No EGL OpenGL 3.3 context here (:func:`~treeanim.render.offscreen.create_egl_context`).
    """

    handle = None

    def __init__(self, width: int = 1280, height: int = 720, *, samples: int = 0, content_scale: float = 1.0) -> None:
        scale = float(content_scale)
        if not np.isfinite(scale) or scale <= 0:
            raise ValueError(f"content_scale must be a positive number, got {content_scale!r}")
        self.ctx = create_egl_context()
        self.ctx.__enter__()  # current while the window is open, as a GLFW window's context is
        most = min(int(samples), int(self.ctx.max_samples))
        self.samples = 0 if most <= 1 else 1 << (most.bit_length() - 1)
        self._scale = scale
        # Bound while our framebuffers are released: moderngl rebinds the framebuffer bound last
        # after it makes one, and rebinding a deleted one is GL_INVALID_OPERATION.
        self._default_fbo = self.ctx.detect_framebuffer(0)
        self._size = (0, 0)
        self._fb_size = (0, 0)
        self._fbos: list = []  # what _set_size made: the framebuffer drawn into first
        self._resolve = None  # the single-sampled framebuffer read back (the drawn one without MSAA)
        self._events: list[tuple[str, tuple]] = []
        self._viewer = None
        self._close = False
        self._closed = False
        self._clipboard = ""
        self.swaps = 0
        try:
            self._set_size(width, height)
        except BaseException:
            self.ctx.__exit__(None, None, None)
            self.ctx.release()
            raise
        self._events.clear()

    # ------------------------------------------------------------------ framebuffers
    def _release_fbos(self) -> None:
        if self._fbos:
            self._default_fbo.use()
        for o in self._fbos:
            o.release()
        self._fbos = []
        self._resolve = None

    def _set_size(self, width: int, height: int) -> None:
        w, h = max(int(width), 0), max(int(height), 0)
        fb = (int(round(w * self._scale)), int(round(h * self._scale)))
        most = self.max_pixels
        fb = (min(fb[0], most), min(fb[1], most))
        self._size = (w, h)
        if fb != self._fb_size or not self._fbos:
            self.make_current()
            self._release_fbos()
            self._fb_size = fb
            if fb[0] > 0 and fb[1] > 0:
                ctx = self.ctx
                color, depth = ctx.renderbuffer(fb, 4), ctx.depth_renderbuffer(fb)
                self._resolve = ctx.framebuffer(color, depth)
                self._fbos = [self._resolve, color, depth]
                if self.samples:
                    mcolor = ctx.renderbuffer(fb, 4, samples=self.samples)
                    mdepth = ctx.depth_renderbuffer(fb, samples=self.samples)
                    self._fbos[:0] = [ctx.framebuffer(mcolor, mdepth), mcolor, mdepth]
                self._fbos[0].use()
                self._fbos[0].clear(0.0, 0.0, 0.0, 1.0)
        self._events.append(("on_window_size", self._size))
        self._events.append(("on_resize", self._fb_size))

    def resize(self, width: int, height: int) -> None:
        """Make the window ``width`` × ``height`` screen units (0 × 0: minimised), as a user or a
        window manager would: the framebuffer follows at once (the size × the content scale, at
        most :attr:`max_pixels` a side), and the viewer hears of it at the next :meth:`poll`."""
        self._set_size(width, height)

    # ------------------------------------------------------------------ queries
    @property
    def size(self) -> tuple[int, int]:
        """Size in screen units (what cursor positions are measured in)."""
        return self._size

    @property
    def framebuffer_size(self) -> tuple[int, int]:
        """Framebuffer size in pixels (0 × 0 when minimised)."""
        return self._fb_size

    @property
    def framebuffer(self) -> moderngl.Framebuffer | None:
        """The framebuffer a frame is drawn into (None while minimised)."""
        return self._fbos[0] if self._fbos else None

    @property
    def content_scale(self) -> float:
        """Pixels per screen unit, the panel's UI scale."""
        return self._scale

    @property
    def max_pixels(self) -> int:
        """The largest side, in pixels, the GL can draw and read back."""
        return gl_max_pixels(self.ctx)

    def shrink_to(self, most: int) -> None:
        """Make the window at most ``most`` pixels a side."""
        side = max(int(most / self._scale), 0)
        self.resize(min(self._size[0], side), min(self._size[1], side))

    @property
    def should_close(self) -> bool:
        """Whether :meth:`request_close` was called."""
        return self._close

    def request_close(self) -> None:
        """Ask the main loop to stop."""
        self._close = True

    def cancel_close(self) -> None:
        """Take back :meth:`request_close` (the main loop runs again)."""
        self._close = False

    @property
    def fullscreen(self) -> bool:
        """Always False: no monitor to cover."""
        return False

    def toggle_fullscreen(self) -> None:
        """Nothing: there is no monitor."""

    def make_current(self) -> None:
        """Make the EGL context current on this thread (a ``with`` block on another context left
        none current)."""
        self.ctx.__enter__()

    # ------------------------------------------------------------------ loop
    def connect(self, viewer) -> None:
        """Deliver this window's events (its size changes) to ``viewer``'s handlers."""
        self._viewer = viewer

    def poll(self) -> None:
        """Deliver the queued size events to the connected viewer (none connected: dropped)."""
        events, self._events = self._events, []
        if self._viewer is not None:
            for name, args in events:
                getattr(self._viewer, name)(*args)

    def wait(self, timeout: float) -> None:
        """As :meth:`poll`: nothing else can happen to a headless window, so it never waits. A
        minimised one with nothing queued can never come back (only code resizes it): waiting
        on it asks to close, so the main loop ends instead of spinning."""
        if not self._events and 0 in self.framebuffer_size:
            self.request_close()
        self.poll()

    def swap(self) -> None:
        """Count a shown frame; the framebuffer keeps what was drawn."""
        self.swaps += 1

    @staticmethod
    def now() -> float:
        """Seconds (``time.perf_counter``)."""
        return time.perf_counter()

    # ------------------------------------------------------------------ pixels
    def read_pixels(self, width: int, height: int) -> np.ndarray:
        """The framebuffer's ``width`` × ``height`` pixels (from its lower left corner, at most
        its size) as drawn so far, (height, width, 3) uint8, row 0 at the top (a multisampled
        one resolved first)."""
        w, h = min(max(int(width), 0), self._fb_size[0]), min(max(int(height), 0), self._fb_size[1])
        if w == 0 or h == 0 or not self._fbos:
            return np.zeros((h, w, 3), np.uint8)
        self.make_current()
        bound = self.ctx.fbo
        if self._fbos[0] is not self._resolve:
            self.ctx.copy_framebuffer(self._resolve, self._fbos[0])
        data = self._resolve.read(viewport=(0, 0, w, h), components=3, alignment=1)
        if bound is not None:
            bound.use()
        img = np.frombuffer(data, np.uint8).reshape(h, w, 3)
        return np.ascontiguousarray(img[::-1])

    def release_readback(self) -> None:
        """Nothing to free: the read-back framebuffer lives as long as the window's size."""

    # ------------------------------------------------------------------ clipboard
    def get_clipboard(self) -> str:
        """The text last put on this window's own clipboard."""
        return self._clipboard

    def set_clipboard(self, text: str) -> None:
        """Keep ``text`` on this window's own clipboard."""
        self._clipboard = str(text)

    # ------------------------------------------------------------------ end
    def close(self) -> None:
        """Free the framebuffers and the context, leaving no context current (idempotent)."""
        if self._closed:
            return
        self._closed = True
        self._viewer = None
        try:
            self.make_current()
            self._release_fbos()
        finally:
            self.ctx.__exit__(None, None, None)  # none current: a GLX window may open next
            self.ctx.release()

    def __enter__(self) -> "HeadlessWindow":
        return self

    def __exit__(self, *exc) -> None:
        self.close()
