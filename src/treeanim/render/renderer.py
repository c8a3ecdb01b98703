"""The tree renderer: static skinned mesh on the GPU, per-frame node transforms as a texture.

Per frame the CPU packs node positions and rotations into one RGBA32F texture (12 floats a
node) and writes it; the vertex shader skins every vertex from it (``shaders/skin.glsl``).
Nothing per vertex or per triangle is touched on the CPU after construction.

Texture layout (both textures are ``TEXTURE_WIDTH`` texels wide, rows as many as needed,
texel i at (i mod width, i div width), read with texelFetch):

- nodes, RGBA32F, 3 texels a node j: ``3j = (p.x, p.y, p.z, r00)``,
  ``3j+1 = (r01, r02, r10, r11)``, ``3j+2 = (r12, r20, r21, r22)``; p the world position,
  r the rotation relative to rest, row-major.
- objects, RGBA32F, 1 texel an object: ``(visible, highlight, 0, 0)``; rewritten only when
  the visibility or highlight changes.

The frame is drawn by passes (:mod:`treeanim.render.passes`, :mod:`treeanim.render.shadow`),
each with its own programs, buffers and uniform block; the renderer owns the pose's textures
and the blocks every pass reads (``Light``: the scene's light, ``View``: the camera; see
:mod:`treeanim.render.uniforms`). Each frame draws the sun's shadow map first, then the leaves
(opaque), the ground over the shadow's footprint and the background (sky and the rest of the
ground; while the camera is still, a copy of a cache) where the leaves left pixels uncovered,
then the bark and the grass blades over them (blended: twigs and blades thinner than a pixel
are soft lines of their true weight), then the overlays. Each part of the mesh
(``mesh.PARTS``) has its own program, and the ground looks the shadow map up only over the
shadow's footprint: a software rasteriser such as llvmpipe runs both sides of every branch,
so code a pixel does not need costs it unless it is left out of that pixel's program.
"""

from __future__ import annotations

import math

import moderngl
import numpy as np

from ..model.tree import Tree
from .camera import OrbitCamera
from .culling import frustum_planes
from .lod import THIN_CASTER_TEXELS, caster_classes
from .mesh import TreeMesh, build_mesh
from .passes import BackgroundCache, GroundPass, OverlayPass, SkyPass, TreePass, release_all
from .scene import Scene
from .shaders import DEPTH_FOOTPRINT, DEPTH_GROUND
from .shadow import ShadowMap, shadow_indices
from .shadow_view import MIN_REACH, VIEW_REACH, view_slice
from .turf import TurfPass
from .uniforms import SAMPLERS, UniformBlock

#: Width in texels of the node and object textures (GL 3.3 guarantees 1024).
TEXTURE_WIDTH = 1024
#: The ground's square reaches this many times the eye's height from the eye: out to where a
#: view ray falls 1e-5 per unit of its length, i.e. to the horizon (ground.frag's limit).
HORIZON_REACH = 1e5


def _lin(rgb) -> tuple[float, float, float]:
    return tuple(float(c) ** 2.2 for c in rgb)


def _bound_framebuffer(ctx: moderngl.Context) -> moderngl.Framebuffer:
    """The framebuffer bound now (moderngl's record of it, else the one GL reports)."""
    return ctx.fbo if ctx.fbo is not None else ctx.detect_framebuffer()


class Renderer:
    """Draws one tree or a scene of many (plus sky, ground and overlays) on any moderngl context
    of GL >= 3.3; a scene tree by tree, those in view (docs/design.md §17, Drawing).

    Parameters
    ----------
    ctx : moderngl.Context
        A window's or a standalone context, current on this thread.
    tree : Tree
    mesh : TreeMesh or None
        A prebuilt mesh of ``tree`` (None builds one).
    scene : Scene or None

    Attributes
    ----------
    tree_pass : TreePass
    shadow : ShadowMap
    ground_pass : GroundPass
    sky_pass : SkyPass
    background : BackgroundCache
    overlay_pass : OverlayPass
        The passes of a frame (:mod:`treeanim.render.passes`).
    """

    def __init__(self, ctx: moderngl.Context, tree: Tree, mesh: TreeMesh | None = None,
                 scene: Scene | None = None) -> None:
        if ctx.version_code < 330:
            raise RuntimeError(f"the renderer needs OpenGL 3.3, the context has {ctx.version_code // 100}."
                               f"{ctx.version_code % 100 // 10}")
        self.ctx = ctx
        self.tree = tree
        self.mesh = mesh if mesh is not None else build_mesh(tree)
        self.scene = scene if scene is not None else Scene()
        self._applied_scene: tuple | None = None
        self._released = False
        lo, hi = self.bounds()
        self.size = float(np.max(hi - lo))
        # Everything GL starts as None, so that release() can free whatever was made before a
        # failure part-way through (a shader that does not compile, an out-of-memory buffer).
        self.light = self.view = self.node_texture = self.object_texture = None
        self.tree_pass = self.shadow = self.sky_pass = self.background = self.overlay_pass = self.ground_pass = None
        self.turf_pass = None
        try:
            self.light = UniformBlock(ctx, "Light")
            self.view = UniformBlock(ctx, "View")
            self.tree_pass = TreePass(ctx, self.mesh, tree, self.pad)
            bound = _bound_framebuffer(ctx)
            casters = shadow_indices(self.mesh, tree, coarse_bark=self.tree_pass.many)
            classes = caster_classes(self.mesh, tree, casters) if self.tree_pass.many else [(math.inf, casters)]
            self._casters, tris, first = [], [], 0  # (thickest diameter, ranges) of each class
            for thickest, t in classes:
                t, ranges = self.tree_pass.order.group(t, first)
                self._casters.append((thickest, ranges))
                tris.append(t)
                first += ranges.total
            self.shadow = ShadowMap(ctx, self.tree_pass.vbo, np.concatenate(tris), self.scene.shadow_size)
            bound.use()  # making the map's framebuffer bound it

            # --- per-frame textures
            N, M = tree.n_nodes, tree.n_objects
            rows = max(1, math.ceil(3 * N / TEXTURE_WIDTH))
            self._node_staging = np.zeros((rows * TEXTURE_WIDTH, 4), np.float32)
            self._node_rows = self._node_staging.reshape(-1)[: 12 * N].reshape(N, 12)
            self.node_texture = ctx.texture((TEXTURE_WIDTH, rows), 4, dtype="f4")
            orows = max(1, math.ceil(M / TEXTURE_WIDTH))
            self._object_staging = np.zeros((orows * TEXTURE_WIDTH, 4), np.float32)
            self.object_texture = ctx.texture((TEXTURE_WIDTH, orows), 4, dtype="f4")
            for tex in (self.node_texture, self.object_texture):
                tex.filter = (moderngl.NEAREST, moderngl.NEAREST)
                tex.repeat_x = tex.repeat_y = False

            self.sky_pass = SkyPass(ctx)
            self.background = BackgroundCache(ctx)
            self.overlay_pass = OverlayPass(ctx)
            self.ground_pass = GroundPass(ctx, tree, (lo, hi))
            self.turf_pass = TurfPass(ctx, (lo, hi), self.ground_pass.maps)

            self._present: np.ndarray | None = None  # None: derived from the season at draw time
            self._present_season: float | None = None
            self._highlight = np.zeros(M, bool)
            self._objects_dirty = True
            self._shadow_runs = None  # the shadow map's draws (None: all)
            self.update(tree.rest_positions, np.broadcast_to(np.eye(3), (N, 3, 3)))
        except BaseException:
            self.release()
            raise

    # ------------------------------------------------------------------ helpers
    @property
    def pad(self) -> float:
        """How far the tree's surface reaches beyond its nodes (metres): a lamina's length plus
        half the thickest diameter."""
        return float(np.max(self.tree.lamina_length, initial=0.0)) + 0.5 * float(np.max(self.tree.node_diameter))

    def bounds(self, positions: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Axis-aligned box of the tree (nodes, plus the leaves' laminas), world."""
        P = self.tree.rest_positions if positions is None else np.asarray(positions)
        return P.min(axis=0) - self.pad, P.max(axis=0) + self.pad

    def _apply_scene(self) -> None:
        """Hand the scene to the blocks and passes, when it changed."""
        s = self.scene
        key = tuple(vars(s).values())
        if key == self._applied_scene:
            return
        sun = np.asarray(s.sun_direction, float)
        sun = sun / np.linalg.norm(sun)
        self.light.set(
            sun_dir=sun,
            sun_color=tuple(c * s.sun_intensity for c in _lin(s.sun_color)),
            sky_zenith=_lin(s.sky_zenith),
            sky_horizon=_lin(s.sky_horizon),
            ground_bounce=_lin(s.ground_bounce),
            ambient=s.ambient,
            haze_distance=s.haze_distance or max(40.0 * self.size, 60.0),
            exposure=s.exposure,
        )
        for p in (self.tree_pass, self.ground_pass, self.sky_pass):
            p.apply(s)
        if s.shadow:
            self.shadow.fit(sun, *self.bounds(), self.tree.rest_positions, self.pad)
        self.shadow.enable(s.shadow)
        self._applied_scene = key

    # ------------------------------------------------------------------ per frame
    def update(self, positions: np.ndarray, rotations: np.ndarray, present: np.ndarray | None = None,
               highlight=None, wind=None, time: float = 0.0) -> None:
        """Upload the pose for the next draws.

        Parameters
        ----------
        positions : (N, 3) float
            Node positions, world (``Simulation.positions``).
        rotations : (N, 3, 3) float
            Node rotations relative to rest (``Simulation.rotations``).
        present : (M,) bool or None
            Objects shown (``Simulation.present``); None shows the leaves present at the
            ``season`` passed to :meth:`draw` (``Tree.leaves_present``).
        highlight : None, int, sequence of int, or bool (scalar or (M,))
            Objects drawn highlighted (e.g. the grabbed one).
        wind : WindField or None
            The wind on the turf at ``time`` (s), which leans the ground's grass
            (:class:`~.turf.TurfPass`; ``Simulation.wind`` and ``Simulation.time``); None: still.
        """
        self.turf_pass.blow(wind, time)
        rows = self._node_rows
        rows[:, 0:3] = positions
        rows[:, 3:12] = np.reshape(rotations, (-1, 9))
        self.node_texture.write(self._node_staging)

        M = self.tree.n_objects
        if present is None:
            if self._present is not None:
                self._present, self._present_season = None, None
        else:
            present = np.asarray(present, bool)
            if self._present is None or not np.array_equal(present, self._present):
                self._present = present.copy()
                self._objects_dirty = True
        hl = np.zeros(M, bool)
        if highlight is not None:
            h = np.asarray(highlight)
            if h.dtype == bool:
                hl = np.broadcast_to(h, (M,))
            elif h.size:
                hl[h.astype(int).reshape(-1)] = True
        if not np.array_equal(hl, self._highlight):
            self._highlight = hl
            self._objects_dirty = True

    def _upload_objects(self, season: float) -> None:
        if self._present is None and self._present_season != season:
            self._present_season = season
            self._objects_dirty = True
        if not self._objects_dirty:
            return
        M = self.tree.n_objects
        present = self._present if self._present is not None else self.tree.leaves_present(season)
        self._object_staging[:M, 0] = present
        self._object_staging[:M, 1] = self._highlight
        self.object_texture.write(self._object_staging)
        self._objects_dirty = False

    def draw(self, camera: OrbitCamera, width: int, height: int, season: float = 0.0,
             overlays=(), framebuffer: moderngl.Framebuffer | None = None) -> None:
        """Draw sky, ground, tree and ``overlays`` into ``framebuffer`` (None: the one bound),
        over its ``width`` × ``height`` pixels. A zero-sized viewport draws nothing.

        Parameters
        ----------
        season : float
            0 summer .. 1 winter: the leaves' colour (and, when :meth:`update` got no
            ``present``, which leaves are shown).
        overlays : iterable of Overlay
        """
        if self._released:
            raise RuntimeError("draw() on a released Renderer")
        width, height = int(width), int(height)
        if width <= 0 or height <= 0:
            return
        ctx = self.ctx
        target = framebuffer if framebuffer is not None else _bound_framebuffer(ctx)
        self._apply_scene()
        season = float(np.clip(season, 0.0, 1.0))
        self._upload_objects(season)
        self.node_texture.use(SAMPLERS["nodes"].unit)
        self.object_texture.use(SAMPLERS["objects"].unit)
        vp = camera.view_projection(width, height)
        pixels_per_metre = 0.5 * height / math.tan(math.radians(camera.fov_y) / 2)
        self._cull(camera, vp, pixels_per_metre)
        if self.scene.shadow:
            ctx.disable(moderngl.CULL_FACE | moderngl.BLEND)
            self.shadow.draw(self._shadow_runs)
        self.view.set(view_proj=vp, inv_view_proj=np.linalg.inv(vp.astype(np.float64)), camera_pos=camera.eye,
                      viewport=(width, height), pixels_per_metre=pixels_per_metre)
        for block in (self.light, self.view, self.shadow.block):
            block.use()
        key = (width, height, vp.tobytes(), tuple(camera.eye), self._applied_scene)
        cached = self.background.holds(key, (width, height), lambda: self._draw_background(camera, vp))
        target.use()
        ctx.viewport = (0, 0, width, height)

        s = self.scene
        hz = _lin(s.sky_horizon)
        ctx.clear(hz[0] ** (1 / 2.2), hz[1] ** (1 / 2.2), hz[2] ** (1 / 2.2), 1.0, depth=1.0)
        ctx.disable(moderngl.CULL_FACE | moderngl.BLEND)
        ctx.enable(moderngl.DEPTH_TEST)
        ctx.depth_func = "<"
        self.shadow.texture.use(SAMPLERS["shadow_map"].unit)
        # The leaves first: solid, so the ground and sky under them are never shaded. Then the
        # ground over the shadow's footprint, with its shadow, and where neither was drawn the
        # background: sky and the rest of the ground (a copy of the cache, or drawn here).
        self.tree_pass.draw("LEAVES", season=season)
        if s.shadow and self._ground_shown(camera):
            self.ground_pass.draw(self.shadow.footprint, vp, DEPTH_FOOTPRINT, shadowed=True)
        if cached:
            self.background.draw()
        else:
            self._draw_background(camera, vp)
        if self._ground_shown(camera):
            self.turf_pass.draw(vp)
        # Blended: twigs and blades thinner than a pixel are drawn faint over what lies behind.
        ctx.enable(moderngl.BLEND)
        ctx.blend_func = moderngl.SRC_ALPHA, moderngl.ONE_MINUS_SRC_ALPHA
        self.tree_pass.draw("BARK", "BLADES", season=season)
        ctx.disable(moderngl.BLEND)
        self.overlay_pass.draw([o for o in overlays if o is not None], self.tree)

    def _cull(self, camera: OrbitCamera, vp: np.ndarray, pixels_per_metre: float) -> None:
        """A scene's draws for this view: the trees in it, far leaves coarse, and the shadow map
        fitted to the view and drawn with the trees in the sun's view of it, less twigs far
        thinner than its texel (none where the view sees nothing the map shades). A lone tree is
        drawn whole (its grass: the squares in view, far clumps one blade), its shadow map
        fitted to it, and drawn where the view sees anything it shades."""
        self._shadow_runs = None
        self.tree_pass.view(vp, camera.eye, pixels_per_metre)
        if not self.tree_pass.many:
            if self.scene.shadow and not self.shadow.sees(frustum_planes(vp)):
                self._shadow_runs = []
            return
        if self.scene.shadow:
            reach = max(VIEW_REACH * camera.distance, MIN_REACH)
            self.shadow.follow(view_slice(vp, camera.eye, camera.forward, reach))
            visible = self.tree_pass.order.visible(self.shadow.matrix) & self.shadow.seen
            thinnest = THIN_CASTER_TEXELS * self.shadow.texel
            self._shadow_runs = [run for thickest, ranges in self._casters if thickest > thinnest for run in ranges.runs(visible)]

    @property
    def drawn(self) -> dict:
        """The last frame's draws of the tree: ``trees`` in view, ``triangles`` and ``draws``
        (calls) of the colour passes, ``shadow_triangles`` of the shadow map's."""
        runs = [(0, sum(r.total for _, r in self._casters))] if self._shadow_runs is None else self._shadow_runs
        return dict(self.tree_pass.drawn, shadow_triangles=sum(c for _, c in runs) // 3 if self.scene.shadow else 0)

    def _ground_shown(self, camera: OrbitCamera) -> bool:
        return bool(self.scene.show_ground and camera.eye[1] > 0.0)

    def _draw_background(self, camera: OrbitCamera, vp: np.ndarray) -> None:
        """The background, where nothing was drawn yet (depth test on): the ground without
        shadows, a square out to the horizon round the eye, behind the footprint's, then the
        sky at the far plane."""
        if self._ground_shown(camera):
            eye = np.asarray(camera.eye, float)
            square = eye[[0, 2]] + HORIZON_REACH * eye[1] * np.array([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]])
            self.ground_pass.draw(square, vp, DEPTH_GROUND, shadowed=False)
        self.sky_pass.draw()

    # ------------------------------------------------------------------ teardown
    def release(self) -> None:
        """Free every GPU resource (idempotent)."""
        if self._released:
            return
        self._released = True
        release_all(self.overlay_pass, self.background, self.turf_pass, self.ground_pass, self.sky_pass, self.shadow, self.tree_pass,
                    self.node_texture, self.object_texture, self.light, self.view)
