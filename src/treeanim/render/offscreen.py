"""Headless rendering: the same :class:`Renderer` on an EGL standalone context (Mesa llvmpipe
where there is no GPU), drawn into a multisampled framebuffer and resolved into a readable one.
"""

from __future__ import annotations

import moderngl
import numpy as np

from ..model.tree import Tree
from .camera import OrbitCamera
from .renderer import Renderer
from .scene import Scene


def create_egl_context() -> moderngl.Context:
    """A standalone OpenGL >= 3.3 core context through EGL, or RuntimeError saying what is missing.

    The context is returned *not* current: use it inside ``with ctx:``. (A thread must not keep
    an EGL context current while it makes a GLX context current, e.g. when GLFW opens a window:
    libglvnd refuses with BadAccess.)"""
    try:
        ctx = moderngl.create_standalone_context(backend="egl", require=330)
    except Exception as exc:  # moderngl/glcontext raise plain Exceptions
        why = " ".join(str(exc).split()) or type(exc).__name__
        raise RuntimeError(
            f"no EGL OpenGL 3.3 context (install Mesa's EGL and libGL, e.g. libegl1 libgl1-mesa-dri): {why}"
        ) from None
    if ctx.version_code < 330:
        version = ctx.info.get("GL_VERSION", ctx.version_code)
        ctx.release()
        raise RuntimeError(f"EGL context offers OpenGL {version}, OpenGL 3.3 is required")
    ctx.__exit__(None, None, None)  # creation left it current
    return ctx


class OffscreenRenderer:
    """Renders a tree to images without a window.

    Every method makes the context current for its own duration only (``with self.ctx:``), so
    offscreen renders mix safely with windows and other contexts in one thread. To call the
    :class:`Renderer` directly, do it inside ``with off.ctx:``.

    Parameters
    ----------
    width, height : int
        Image size in pixels (0 gives empty images).
    samples : int
        MSAA samples (down to a power of two and to what the context supports; 0 or 1: none).
    ctx : moderngl.Context or None
        An existing context to render with (None creates an EGL one, owned and released here).

    Example
    -------
    >>> off = OffscreenRenderer(640, 360)
    >>> off.load(tree)                                        # a Renderer on off.ctx
    >>> off.update(sim.positions, sim.rotations, sim.present)
    >>> img = off.render(camera, season=0.3)    # (360, 640, 3) uint8, row 0 at the top
    """

    def __init__(self, width: int, height: int, samples: int = 4, ctx: moderngl.Context | None = None) -> None:
        self._own_ctx = ctx is None
        self.ctx = create_egl_context() if ctx is None else ctx
        most = min(int(samples), int(self.ctx.max_samples))
        self.samples = 0 if most <= 1 else 1 << (most.bit_length() - 1)
        self.renderer: Renderer | None = None
        self._fbos: list = []
        self.fbo = self.resolve_fbo = None
        self.width = self.height = 0
        with self.ctx:
            # Bound while our framebuffers are released: moderngl rebinds the last framebuffer
            # used after creating one, and a deleted one would raise GL_INVALID_OPERATION.
            self._default_fbo = self.ctx.screen or self.ctx.detect_framebuffer(0)
        self.resize(width, height)

    # ------------------------------------------------------------------ framebuffers
    def _release_fbos(self) -> None:
        if self._fbos:
            self._default_fbo.use()
        for o in self._fbos:
            o.release()
        self._fbos = []
        self.fbo = self.resolve_fbo = None

    def resize(self, width: int, height: int) -> None:
        """Change the image size (any size; 0 × 0 allowed)."""
        width, height = max(int(width), 0), max(int(height), 0)
        if (width, height) == (self.width, self.height) and (self._fbos or not width * height):
            return
        with self.ctx:
            self._release_fbos()
            self.width, self.height = width, height
            if width == 0 or height == 0:
                return
            ctx = self.ctx
            size = (width, height)
            color = ctx.renderbuffer(size, 4, dtype="f1")
            depth = ctx.depth_renderbuffer(size)
            self.resolve_fbo = ctx.framebuffer(color, depth)
            self._fbos = [self.resolve_fbo, color, depth]
            self.fbo = self.resolve_fbo
            if self.samples:
                mcolor = ctx.renderbuffer(size, 4, samples=self.samples, dtype="f1")
                mdepth = ctx.depth_renderbuffer(size, samples=self.samples)
                self.fbo = ctx.framebuffer(mcolor, mdepth)
                self._fbos += [self.fbo, mcolor, mdepth]

    # ------------------------------------------------------------------ rendering
    def load(self, tree: Tree, scene: Scene | None = None, **kw) -> Renderer:
        """Make (and keep) a :class:`Renderer` for ``tree`` on this context, releasing the
        previous one. Extra keywords go to :class:`Renderer`."""
        with self.ctx:
            if self.renderer is not None:
                self.renderer.release()
                self.renderer = None
            self.renderer = Renderer(self.ctx, tree, scene=scene, **kw)
        return self.renderer

    def update(self, positions, rotations, present=None, highlight=None, wind=None, time: float = 0.0) -> None:
        """:meth:`Renderer.update` of the loaded renderer, with the context current."""
        with self.ctx:
            self._loaded().update(positions, rotations, present=present, highlight=highlight, wind=wind, time=time)

    def _loaded(self, renderer: Renderer | None = None) -> Renderer:
        r = renderer or self.renderer
        if r is None:
            raise RuntimeError("OffscreenRenderer: no tree loaded (call load(tree) first)")
        return r

    def render(self, camera: OrbitCamera, season: float = 0.0, overlays=(), renderer: Renderer | None = None) -> np.ndarray:
        """Draw and read back one frame.

        Parameters
        ----------
        camera : OrbitCamera
        season : float
        overlays : iterable of Overlay
        renderer : Renderer or None
            Which renderer draws (None: the one :meth:`load` made); it must live on ``ctx``.

        Returns
        -------
        (height, width, 3) uint8, row 0 at the top.
        """
        r = self._loaded(renderer)
        if self.width == 0 or self.height == 0:
            return np.zeros((self.height, self.width, 3), np.uint8)
        with self.ctx:
            r.draw(camera, self.width, self.height, season=season, overlays=overlays, framebuffer=self.fbo)
            if self.fbo is not self.resolve_fbo:
                self.ctx.copy_framebuffer(self.resolve_fbo, self.fbo)
            data = self.resolve_fbo.read(components=3, alignment=1)
        img = np.frombuffer(data, np.uint8).reshape(self.height, self.width, 3)
        return np.ascontiguousarray(img[::-1])

    def release(self) -> None:
        """Free the renderer, framebuffers and (if owned) the context (idempotent)."""
        if self.ctx is None:
            return
        with self.ctx:
            if self.renderer is not None:
                self.renderer.release()
                self.renderer = None
            self._release_fbos()
        if self._own_ctx:
            self.ctx.release()
        self.ctx = None

    def __enter__(self) -> "OffscreenRenderer":
        return self

    def __exit__(self, *exc) -> None:
        self.release()
