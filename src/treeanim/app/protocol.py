"""What the viewer needs of a window: :class:`AppWindow`, the protocol that the GLFW window
(:class:`treeanim.app.window.Window`) and the headless one
(:class:`treeanim.app.headless.HeadlessWindow`: an EGL context and an offscreen framebuffer)
both implement.

The viewer draws into :attr:`AppWindow.framebuffer` on :attr:`AppWindow.ctx`, reads sizes in
screen units (:attr:`~AppWindow.size`, what cursor positions are measured in) and pixels
(:attr:`~AppWindow.framebuffer_size`), and gets its input through its own handler methods, which
a window calls from :meth:`~AppWindow.poll` once :meth:`~AppWindow.connect` routed its events
to them (a headless window has no user: its caller calls the handlers itself).
"""

from __future__ import annotations

from typing import Protocol, runtime_checkable

import moderngl
import numpy as np

__all__ = ["AppWindow", "gl_max_pixels"]


def gl_max_pixels(ctx: moderngl.Context) -> int:
    """The largest side, in pixels, ``ctx`` can draw and read back (its viewport, renderbuffer
    and texture limits)."""
    info = ctx.info
    dims = info.get("GL_MAX_VIEWPORT_DIMS", (16384, 16384))
    return int(min(min(dims), info.get("GL_MAX_RENDERBUFFER_SIZE", 16384), info.get("GL_MAX_TEXTURE_SIZE", 16384)))


@runtime_checkable
class AppWindow(Protocol):
    """A drawable window with an OpenGL >= 3.3 core context (current on this thread while the
    window is open).

    Attributes
    ----------
    ctx : moderngl.Context
    samples : int
        MSAA samples of the framebuffer drawn into (0: none).
    """

    ctx: moderngl.Context
    samples: int

    @property
    def size(self) -> tuple[int, int]:
        """Size in screen units (cursor positions are measured in them)."""

    @property
    def framebuffer_size(self) -> tuple[int, int]:
        """Size of the framebuffer in pixels (0 × 0 when minimised)."""

    @property
    def framebuffer(self) -> moderngl.Framebuffer | None:
        """The framebuffer a frame is drawn into (None while there is none: minimised)."""

    @property
    def content_scale(self) -> float:
        """The UI scale: 1 on a plain display, 2 on a 'retina' one."""

    @property
    def max_pixels(self) -> int:
        """The largest side in pixels the GL can draw and read back."""

    @property
    def should_close(self) -> bool:
        """Whether the main loop should stop."""

    @property
    def fullscreen(self) -> bool:
        """Whether the window covers a monitor."""

    def make_current(self) -> None:
        """Make the window's context current on this thread."""

    def request_close(self) -> None:
        """Ask the main loop to stop."""

    def toggle_fullscreen(self) -> None:
        """Full screen, or back (a headless window has no monitor: nothing happens)."""

    def shrink_to(self, most: int) -> None:
        """Make the window at most ``most`` pixels a side."""

    def connect(self, viewer) -> None:
        """Route the window's events to ``viewer``'s handlers (``on_resize``, ``on_key`` …)."""

    def poll(self) -> None:
        """Deliver the events waiting now to the connected viewer, without blocking."""

    def wait(self, timeout: float) -> None:
        """Wait for an event for at most ``timeout`` seconds, then deliver what came."""

    def swap(self) -> None:
        """Show the frame drawn."""

    def now(self) -> float:
        """The window system's clock, seconds."""

    def read_pixels(self, width: int, height: int) -> np.ndarray:
        """The frame as drawn so far, (height, width, 3) uint8, row 0 at the top."""

    def release_readback(self) -> None:
        """Free what :meth:`read_pixels` keeps between calls."""

    def get_clipboard(self) -> str:
        """The clipboard's text (the panel's text fields paste it)."""

    def set_clipboard(self, text: str) -> None:
        """Put ``text`` on the clipboard."""

    def close(self) -> None:
        """Close the window and free its context (idempotent)."""
