"""Draft mode's drawing: the scene into a smaller single-sample framebuffer, then scaled up
onto the window's (:class:`DraftTarget`). A software rasteriser's cost goes with the pixels
(and their samples) it shades: at half the size a side it shades a quarter of them."""

from __future__ import annotations

import moderngl

from ..render.shaders import load_program
from ..render.uniforms import SAMPLERS

__all__ = ["DraftTarget"]


class DraftTarget:
    """A smaller framebuffer (no MSAA) the scene is drawn into, and the pass that scales it up.

    Parameters
    ----------
    ctx : moderngl.Context
    """

    def __init__(self, ctx: moderngl.Context) -> None:
        self.ctx = ctx
        self.program = load_program(ctx, "draft.vert", "draft.frag")
        self.vao = ctx.vertex_array(self.program, [])
        self.size: tuple[int, int] | None = None
        self._fbo = self._color = self._depth = None

    def _fit(self, size: tuple[int, int]) -> None:
        if size == self.size:
            return
        self._free()
        self._color = self.ctx.texture(size, 4)
        self._color.filter = (moderngl.LINEAR, moderngl.LINEAR)
        self._depth = self.ctx.depth_renderbuffer(size)
        self._fbo = self.ctx.framebuffer([self._color], self._depth)
        self.size = size

    def draw(self, renderer, camera, width: int, height: int, scale: float, target, **kw) -> None:
        """Draw the scene with ``renderer`` (``kw``: its ``draw``'s season and overlays) at
        ``scale`` × (``width`` × ``height``) pixels, then fill ``target`` (the window's
        framebuffer, ``width`` × ``height``) with it, scaled up."""
        size = (max(int(round(width * scale)), 1), max(int(round(height * scale)), 1))
        self._fit(size)
        self._fbo.use()
        renderer.draw(camera, *size, framebuffer=self._fbo, **kw)
        target.use()
        self.ctx.viewport = (0, 0, int(width), int(height))
        self.ctx.disable(moderngl.DEPTH_TEST | moderngl.BLEND | moderngl.CULL_FACE)
        self._color.use(SAMPLERS["draft"].unit)
        self.vao.render(moderngl.TRIANGLES, vertices=3)
        self.ctx.enable(moderngl.DEPTH_TEST)

    def _free(self) -> None:
        for obj in (self._fbo, self._color, self._depth):
            if obj is not None:
                obj.release()
        self._fbo = self._color = self._depth = None
        self.size = None

    def release(self) -> None:
        """Free the GL objects."""
        self._free()
        self.vao.release()
        self.program.release()
