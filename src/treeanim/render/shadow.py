"""The sun's shadow map: the skinned tree's depth seen from the sun, drawn each frame before the
scene, and sampled with percentage-closer filtering by the tree and the ground
(``sun_visibility`` in ``shaders/sun.glsl``), so the crown shades the ground and itself.

The sun's orthographic view is fitted once per sun direction to a box round the tree that
leaves room for it to sway, and to that box's shadow on the ground: the map's texels stay
fixed in the world while the tree moves (no swimming edges). The ground looks the map up only
inside :attr:`ShadowMap.footprint`, the polygon that holds every shadow the box can cast.
"""

from __future__ import annotations

import moderngl
import numpy as np
from scipy.spatial import ConvexHull, QhullError

from ..model.tree import Tree
from .culling import SWAY_MARGIN
from .lod import clump_copies, coarse_laminas, coarse_tubes
from .mesh import (
    MATERIAL_BARK,
    MATERIAL_LAMINA,
    MATERIAL_PETIOLE,
    VERTEX_ATTRIBUTES,
    VERTEX_DTYPE,
    VERTEX_FORMAT,
    TreeMesh,
)
from .shaders import load_program
from .shadow_view import EDGE_FADE, clip_convex, seen_corners, view_window, window_on_ground
from .uniforms import UniformBlock

#: Attributes the shadow pass reads; the rest of each vertex is skipped.
SHADOW_ATTRIBUTES = ("in_ids", "in_offset", "in_extra", "in_curve", "in_tangent0", "in_tangent1")
#: The lowest sun elevation the map is fitted for (sin of it): lower suns cast the shadow of
#: a sun at this height, not an endless one.
MIN_SUN_HEIGHT = 0.15
#: Corners of a lamina's outline kept for its shadow (its teeth are far below a texel).
SHADOW_LAMINA_CORNERS = 12
#: The footprint reaches this many shadow-map texels beyond the box's shadow: the reach of a
#: ground point's lookup (its offset off the ground and the filter's taps, ``shaders/sun.glsl``).
FOOTPRINT_TEXELS = 4.0


def _skipping_format() -> str:
    """:data:`VERTEX_FORMAT` with the attributes the shadow pass does not read as padding."""
    parts = []
    for fmt, name in zip(VERTEX_FORMAT.split(), VERTEX_ATTRIBUTES):
        if name in SHADOW_ATTRIBUTES:
            parts.append(fmt)
        else:
            parts.append(f"{VERTEX_DTYPE[name[3:]].itemsize}x")
    return " ".join(parts)


def shadow_indices(mesh: TreeMesh, tree: Tree, coarse_bark: bool = False) -> np.ndarray:
    """The triangles the shadow pass draws: the mesh's, without petioles (a few millimetres
    across, far below a texel), with each lamina outlined by :data:`SHADOW_LAMINA_CORNERS`
    of its corners (a lamina's vertices are its outline's, in order, per leaf), and each blade
    clump casting its simulated blade's shadow (an object's first triangles: mesh notes);
    with ``coarse_bark`` (a scene's), the bark's tubes with half their sides
    (:func:`~.lod.coarse_tubes`).

    Returns
    -------
    (T', 3) uint32
        Indices into ``mesh.vertices``.
    """
    first = mesh.material[mesh.indices[:, 0]]
    bark = coarse_bark & (first == MATERIAL_BARK)
    keep = [mesh.indices[(first != MATERIAL_PETIOLE) & (first != MATERIAL_LAMINA) & ~clump_copies(mesh) & ~bark],
            coarse_laminas(mesh, tree, SHADOW_LAMINA_CORNERS), coarse_tubes(mesh) if coarse_bark else np.zeros((0, 3), np.uint32)]
    return np.ascontiguousarray(np.concatenate(keep), dtype=np.uint32)


def cast_direction(sun) -> np.ndarray:
    """The sun the map is made for: ``sun``, or where it is lower than :data:`MIN_SUN_HEIGHT`,
    a sun at that height in the same azimuth (its shadows stay on a finite ground).

    Parameters
    ----------
    sun : (3,) float
        Towards the sun (any length).

    Returns
    -------
    (3,) float
        Unit vector towards the sun the shadows are cast from.
    """
    sun = np.asarray(sun, float)
    sun = sun / np.linalg.norm(sun)
    if sun[1] < MIN_SUN_HEIGHT:
        h = np.hypot(sun[0], sun[2])
        flat = sun[[0, 2]] / h if h > 0 else np.array([1.0, 0.0])
        c = np.sqrt(1.0 - MIN_SUN_HEIGHT**2)
        sun = np.array([c * flat[0], MIN_SUN_HEIGHT, c * flat[1]])
    return sun


def _box_and_shadow(sun: np.ndarray, lo, hi) -> tuple[np.ndarray, np.ndarray]:
    """The 8 corners of the box ``lo`` .. ``hi`` and their shadows on the ground y = 0 (corners
    below the ground stand for the ground under them)."""
    corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
    return corners, _shadow(sun, corners)


def _receivers(sun: np.ndarray, lo, hi) -> tuple[np.ndarray, np.ndarray]:
    """The box that holds the box ``lo`` .. ``hi`` and its shadow on the ground: all that a
    caster inside it can shade."""
    pts = np.vstack(_box_and_shadow(sun, lo, hi))
    return pts.min(axis=0), pts.max(axis=0)


def _shadow(sun: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Shadows on the ground y = 0 of ``points`` (points below the ground: the ground under them)."""
    return points - np.outer(np.maximum(points[:, 1], 0.0) / sun[1], sun)


def ground_footprint(sun, points, reach: float) -> np.ndarray:
    """Where on the ground y = 0 anything within ``reach`` of ``points`` can cast its shadow.

    Parameters
    ----------
    sun : (3,) float
        Towards the sun (made :func:`cast_direction`).
    points : (P, 3) float
        The casters (a tree's nodes at rest).
    reach : float
        How far from a point its surface may be, or sway to (metres; each axis).

    Returns
    -------
    (K, 2) float
        The convex polygon (x, z), in order round it: the hull of the shadows of the segments
        from ``reach`` below each point to ``reach`` above it, widened by ``reach`` along x and z
        (a shadow is a linear map of its caster, so the shadow of the box round each point falls
        inside).
    """
    sun = cast_direction(sun)
    points = np.asarray(points, float)
    ends = np.concatenate([points - [0.0, reach, 0.0], points + [0.0, reach, 0.0]])
    xz = _shadow(sun, ends)[:, [0, 2]]
    try:
        xz = xz[ConvexHull(xz).vertices]
    except QhullError:  # all in a line (one straight beam): the widening below makes it 2-D
        pass
    xz = (xz[:, None, :] + reach * np.array([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]])).reshape(-1, 2)
    return xz[ConvexHull(xz).vertices]


def sun_basis(sun) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(right, up, forward): the sun's view axes, unit; it looks along forward, towards the
    ground, from the sun :func:`cast_direction` makes of ``sun``."""
    forward = -cast_direction(sun)
    up = np.array([0.0, 1.0, 0.0]) if abs(forward[1]) < 0.99 else np.array([0.0, 0.0, 1.0])
    right = np.cross(forward, up)
    right /= np.linalg.norm(right)
    return right, np.cross(right, forward), forward


def light_view_projection(sun: np.ndarray, lo: np.ndarray, hi: np.ndarray, window=None) -> tuple[np.ndarray, float]:
    """The sun's orthographic view-projection for a tree in the box ``lo`` .. ``hi``.

    Parameters
    ----------
    sun : (3,) float
        Unit vector towards the sun.
    lo, hi : (3,) float
        Corners of the box that holds every caster (world, y up, ground at y = 0).
    window : (x0, x1, y0, y1) or None
        The map's extent across the sun's rays (along :func:`sun_basis`' right and up, metres);
        None: the box's and its shadow's, and a margin.

    Returns
    -------
    matrix : (4, 4) float32
        World → clip, column-major bytes order as GLSL reads it (``matrix.tobytes()``).
    extent : float
        The larger side of the map's footprint (metres), for the texel size.
    """
    right, up, forward = sun_basis(sun)
    corners, ground = _box_and_shadow(cast_direction(sun), lo, hi)
    pts = np.vstack([corners, ground])
    x, y, d = pts @ right, pts @ up, pts @ forward  # d: distance along the sun's rays
    x0, x1, y0, y1 = x.min(), x.max(), y.min(), y.max()
    pad = 0.02 * max(x1 - x0, y1 - y0)
    x0, x1, y0, y1 = (x0 - pad, x1 + pad, y0 - pad, y1 + pad) if window is None else window
    near, far = d.min() - pad, d.max() + pad
    view = np.eye(4)
    view[0, :3], view[1, :3], view[2, :3] = right, up, -forward  # a right-handed eye space
    ortho = np.diag([2.0 / (x1 - x0), 2.0 / (y1 - y0), -2.0 / (far - near), 1.0])
    ortho[:3, 3] = [-(x1 + x0) / (x1 - x0), -(y1 + y0) / (y1 - y0), -(far + near) / (far - near)]
    # eye z = -d, so d = near maps to -1 and d = far to +1
    m = ortho @ view
    return np.ascontiguousarray(m.T, dtype=np.float32), float(max(x1 - x0, y1 - y0))


class ShadowMap:
    """A depth texture of the tree seen from the sun, the pass that draws it, and the ``Shadow``
    uniform block that the map's lookups read (``sun.glsl``): bound by the renderer for every
    pass, by :meth:`draw` for its own.

    Parameters
    ----------
    ctx : moderngl.Context
    vbo : moderngl.Buffer or None
        The tree's static vertices (:class:`~treeanim.render.mesh.TreeMesh` layout).
    indices : (T, 3) uint32
        The triangles to cast shadows (:func:`shadow_indices`).
    size : int
        Texels a side (clamped to the context's largest texture).
    """

    def __init__(self, ctx: moderngl.Context, vbo, indices: np.ndarray, size: int) -> None:
        self.ctx = ctx
        self.size = int(min(max(size, 16), ctx.info["GL_MAX_TEXTURE_SIZE"]))
        self.count = 3 * len(indices)
        self.prog = self.texture = self.fbo = self.vao = self.ibo = self.block = None
        try:
            self.block = UniformBlock(ctx, "Shadow")
            self.prog = load_program(ctx, "shadow.vert", "shadow.frag")
            self.texture = ctx.depth_texture((self.size, self.size))
            self.texture.compare_func = "<="  # sampler2DShadow: 1 where the point is nearest
            self.texture.filter = (moderngl.LINEAR, moderngl.LINEAR)  # 2 x 2 PCF per tap
            self.texture.repeat_x = self.texture.repeat_y = False
            self.fbo = ctx.framebuffer(depth_attachment=self.texture)
            if vbo is not None and self.count:
                self.ibo = ctx.buffer(np.ascontiguousarray(indices, np.uint32).tobytes())
                self.vao = ctx.vertex_array(self.prog, [(vbo, _skipping_format(), *SHADOW_ATTRIBUTES)],
                                            index_buffer=self.ibo, index_element_size=4)
        except BaseException:
            self.release()
            raise
        self.matrix = np.eye(4, dtype=np.float32)
        self.texel = 1.0
        self.footprint = np.zeros((0, 2))
        self.window: tuple | None = None  # :meth:`follow`'s window; None: the whole tree's map
        self.seen = True  # whether the view sees anything the map can shade (:meth:`follow`)
        self._fitted: tuple | None = None
        self.block.set(light_view_proj=self.matrix, shadow_texel=self.texel, shadow_on=1, shadow_edge=0.0)
        self.clear()

    def fit(self, sun, lo, hi, points, pad: float) -> None:
        """Fit the sun's view to the box ``lo`` .. ``hi`` grown by :data:`~.culling.SWAY_MARGIN`
        of its size each way for sway, but by no more than its height (nothing sways further than
        it stands tall: a meadow's box grows by a blade's length, not by 15 % of its width) (cached),
        and the ground's :attr:`footprint` to the tree's ``points`` (its nodes at rest) grown by
        the same and by ``pad`` (how far its surface reaches beyond them)."""
        key = (tuple(np.round(sun, 9)), tuple(lo), tuple(hi))
        if key == self._fitted:
            return
        self._fitted = key
        lo, hi = np.asarray(lo, float), np.asarray(hi, float)
        grow = min(SWAY_MARGIN * (hi - lo).max(), hi[1] - lo[1])
        self._sun, self._box = cast_direction(sun), (lo - grow, hi + grow)
        matrix, self._extent = light_view_projection(sun, *self._box)
        texel = self._extent / self.size
        reach = grow + pad + FOOTPRINT_TEXELS * texel / self._sun[1]  # texels long on the ground
        self._whole = matrix, texel, ground_footprint(sun, points, reach)
        self._receivers = _receivers(self._sun, *self._box)
        self.window, self.seen = None, True
        self._show(*self._whole, edge=0.0)

    def _show(self, matrix: np.ndarray, texel: float, footprint: np.ndarray, edge: float) -> None:
        self.matrix, self.texel, self.footprint = matrix, texel, footprint
        self.block.set(light_view_proj=matrix, shadow_texel=texel, shadow_edge=edge)

    def follow(self, slice_planes: np.ndarray) -> None:
        """Fit the map to what a view sees (after :meth:`fit`): the receivers inside
        ``slice_planes`` (:func:`~.shadow_view.view_slice`), snapped to the texel grid
        (:func:`~.shadow_view.view_window`), shadows fading out at its border; or the whole
        tree's map where that is no larger. Where the view sees none of the receivers,
        :attr:`seen` is False: no caster need be drawn."""
        basis = sun_basis(self._sun)
        corners = seen_corners(self._receivers, slice_planes)
        self.seen = bool(len(corners))
        window = view_window(basis, corners, self.size, self._extent) if self.seen else self.window
        if window == self.window:
            return
        self.window = window
        if window is None:
            self._show(*self._whole, edge=0.0)
            return
        matrix, side = light_view_projection(self._sun, *self._box, window=window)
        footprint = clip_convex(self._whole[2], window_on_ground(basis, window))
        self._show(matrix, side / self.size, footprint, edge=EDGE_FADE)

    def sees(self, planes: np.ndarray) -> bool:
        """Whether the volume ``planes`` (6, 4) keep (a view's :func:`~.culling.frustum_planes`)
        holds any of what the map shades (after :meth:`fit`)."""
        return bool(len(seen_corners(self._receivers, planes)))

    def enable(self, on: bool) -> None:
        """Shadows on (the map drawn each frame by :meth:`draw`) or off (the map cleared, its
        lookups everything lit)."""
        self.block.set(shadow_on=on)
        if not on:
            self.clear()

    def clear(self) -> None:
        """Nothing in the map: everything lit."""
        self.fbo.clear(depth=1.0)

    def draw(self, runs=None) -> None:
        """Draw the tree into the map (the node and object textures bound to units 0 and 1, as
        for the scene): the (first, count) ``runs`` of its indices, or all (None). Leaves the
        map's framebuffer bound."""
        ctx = self.ctx
        self.fbo.use()
        ctx.viewport = (0, 0, self.size, self.size)
        self.fbo.clear(depth=1.0)
        if self.vao is None:
            return
        self.block.use()
        ctx.enable(moderngl.DEPTH_TEST)
        ctx.depth_func = "<"
        ctx.polygon_offset = 1.5, 2.0  # slope-scaled bias against acne on grazing faces
        for first, count in [(0, self.count)] if runs is None else runs:
            self.vao.render(moderngl.TRIANGLES, vertices=count, first=first)
        ctx.polygon_offset = 0.0, 0.0

    def release(self) -> None:
        """Free the GL objects (idempotent)."""
        for o in (self.vao, self.ibo, self.fbo, self.texture, self.prog, self.block):
            if o is not None:
                o.release()
        self.vao = self.ibo = self.fbo = self.texture = self.prog = self.block = None
