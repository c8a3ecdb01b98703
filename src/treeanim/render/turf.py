"""The turf in the wind: the ground's grass leaned by the simulated wind, so a gust crossing a
meadow reads as a bright or dark patch travelling downwind (honami).

The ground (``ground.frag``) is upright turf, drawn once while the view holds still
(:class:`~.passes.BackgroundCache`). Each frame :meth:`TurfPass.blow` samples the wind field
that drives the trees (``WindField.sample``, the same field and time) on a square grid at the
turf's height over the scene and its surroundings, and :meth:`TurfPass.draw` lays a pass
(``turf.frag``) over the ground there that scales each pixel by how blades leaned by that wind
catch the sun: the blades lean downwind as the meadow's simulated ones do (:data:`LEAN_45`),
and a blade is a fibre (Kajiya-Kay): its diffuse light depends on its direction and the
sun's, against an upright blade's. A gust leans the turf over and changes its brightness where
it passes, and the patch moves with the gust at the wind's speed.
"""

from __future__ import annotations

import moderngl
import numpy as np

from .passes import release_all
from .scene import clip_ground
from .shaders import DEPTH_TURF, load_program
from .uniforms import SAMPLERS, UniformBlock

#: Samples of the wind a side of the grid.
GRID = 64
#: The grid's side over the scene's (its box across x and z), and its least side (m): its
#: outer 30 % fades out (turf.frag), so round a lone tree the gusts show 30 m and more away.
REACH, MIN_SIDE = 1.6, 80.0
#: Height (m) at which the turf feels the wind: a meadow's blades, 0.2 to 0.45 m tall.
TURF_HEIGHT = 0.3
#: How the turf's blades lean in a wind U at its height: tan(lean) = (U / U45)^n, U45 in m/s;
#: measured from the meadow's own simulated blades (``scenes/plants/meadow.toml``, a steady
#: wind, their tips' mean lean over 2 s): 19, 35, 44 and 53 degrees at 2.0, 3.5, 4.8 and
#: 6.5 m/s. Slower than drag's U² (n = 2): the blades bend out of the wind and shed drag.
LEAN_45, LEAN_EXPONENT = 5.0, 1.14


class TurfPass:
    """The turf in the wind over a square round the scene.

    Parameters
    ----------
    ctx : moderngl.Context
    bounds : ((3,) float, (3,) float)
        The scene's box at rest: the grid covers :data:`REACH` times its width, centred on it.
    maps : moderngl.Texture
        The ground's maps (:func:`~.ground_maps.ground_texture`, the ground pass's): where the
        ground is bare soil, which has no blades.
    """

    def __init__(self, ctx: moderngl.Context, bounds, maps: moderngl.Texture) -> None:
        self.ctx = ctx
        self.maps = maps
        self.texture = self.prog = self.vbo = self.vao = self.block = None
        lo, hi = (np.asarray(b, float) for b in bounds)
        side = max(REACH * float(np.max((hi - lo)[[0, 2]])), MIN_SIDE)
        self.corner = 0.5 * (lo + hi)[[0, 2]] - 0.5 * side
        self.side = side
        axis = np.linspace(0.0, side, GRID)
        x, z = np.meshgrid(self.corner[0] + axis, self.corner[1] + axis)
        self.points = np.column_stack([x.ravel(), np.full(x.size, TURF_HEIGHT), z.ravel()])
        self._blown = None  # (wind, time) not yet sampled into the texture
        self.blowing = False
        try:
            self.block = UniformBlock(ctx, "Turf")
            self.block.set(turf_grid=(*self.corner, side, GRID), turf_lean=(LEAN_45, LEAN_EXPONENT))
            self.texture = ctx.texture((GRID, GRID), 2, dtype="f4")
            self.texture.repeat_x = self.texture.repeat_y = False
            self.prog = load_program(ctx, "ground.vert", "turf.frag")
            self.vbo = ctx.buffer(reserve=1024, dynamic=True)
            self.vao = ctx.vertex_array(self.prog, [(self.vbo, "4f", "in_clip")])
        except BaseException:
            self.release()
            raise

    def blow(self, wind, time: float) -> None:
        """Sample ``wind`` (anything with ``sample(points, t)``, as ``Simulation`` takes; None or a
        calm ``WindField``: no pass) at ``time`` (s) over the grid, when the next :meth:`draw`
        sees the grid (a view with no turf in it samples nothing)."""
        self.blowing = wind is not None and not getattr(wind, "calm", False)
        self._blown = (wind, time) if self.blowing else None

    def draw(self, view_proj: np.ndarray) -> None:
        """Scale the ground in the bound framebuffer over the grid (depth test on: where the
        ground was drawn, behind everything else), when the wind blows.

        Parameters
        ----------
        view_proj : (4, 4) float
            World → clip (:meth:`OrbitCamera.view_projection`).
        """
        if not self.blowing:
            return
        x0, z0 = self.corner
        square = np.array([[x0, z0], [x0 + self.side, z0], [x0 + self.side, z0 + self.side], [x0, z0 + self.side]])
        tris = clip_ground(square, view_proj, DEPTH_TURF)
        if not len(tris):
            return
        if self._blown is not None:
            wind, time = self._blown
            v = np.asarray(wind.sample(self.points, time), np.float32)
            self.texture.write(np.ascontiguousarray(v[:, [0, 2]]).tobytes())
            self._blown = None
        ctx = self.ctx
        self.vbo.write(tris.tobytes())
        self.block.use()
        self.texture.use(SAMPLERS["turf_wind"].unit)
        self.maps.use(SAMPLERS["ground_maps"].unit)
        ctx.enable(moderngl.BLEND)
        ctx.blend_func = moderngl.DST_COLOR, moderngl.SRC_ALPHA
        ctx.depth_func = "<="
        ctx.depth_mask = False
        self.vao.render(moderngl.TRIANGLES, vertices=len(tris))
        ctx.depth_mask = True
        ctx.depth_func = "<"
        ctx.disable(moderngl.BLEND)

    def release(self) -> None:
        """Free the GL objects (idempotent)."""
        release_all(self.vao, self.vbo, self.prog, self.texture, self.block)
        self.vao = self.vbo = self.prog = self.texture = self.block = None
