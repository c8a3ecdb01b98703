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

Each frame draws the sun's shadow map first (:mod:`treeanim.render.shadow`), then the leaves
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
import weakref
from dataclasses import dataclass

import moderngl
import numpy as np

from ..model.tree import Tree
from .camera import OrbitCamera
from .mesh import PARTS, VERTEX_ATTRIBUTES, VERTEX_FORMAT, TreeMesh, build_mesh
from .overlays import LINE_ATTRIBUTES, LINE_FORMAT, Overlay
from .scene import Scene, clip_ground
from .shaders import DEPTH_FOOTPRINT, DEPTH_GROUND, load_program
from .shadow import ShadowMap, shadow_indices

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


@dataclass
class _Part:
    """One part of the mesh (``mesh.PARTS``): its program, and its triangles' range in the
    renderer's index buffer."""

    prog: moderngl.Program
    vao: moderngl.VertexArray | None
    first: int
    count: int

    def render(self) -> None:
        if self.count:
            self.vao.render(moderngl.TRIANGLES, vertices=self.count, first=self.first)


class _Lines:
    """GPU buffers of one overlay."""

    def __init__(self, overlay: Overlay) -> None:
        self.ref = weakref.ref(overlay)
        self.vbo: moderngl.Buffer | None = None
        self.vao: moderngl.VertexArray | None = None
        self.count = 0
        self.uploaded = False

    def release(self) -> None:
        for o in (self.vao, self.vbo):
            if o is not None:
                o.release()
        self.vao = self.vbo = None


class Renderer:
    """Draws one tree (plus sky, ground and overlays) on any moderngl context of GL >= 3.3.

    Parameters
    ----------
    ctx : moderngl.Context
        A window's or a standalone context, current on this thread.
    tree : Tree
    mesh : TreeMesh or None
        A prebuilt mesh of ``tree`` (None builds one).
    scene : Scene or None
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
        # Every GL object starts as None, so that release() can free whatever was made before a
        # failure part-way through (a shader that does not compile, an out-of-memory buffer).
        self.line_prog = self.sky_prog = None
        self.ground_progs: list[moderngl.Program] = []
        self.parts: dict[str, _Part] = {}
        self.vbo = self.ibo = self.sky_vao = self.ground_vbo = None
        self.background_prog = self.background_vao = self.background_texture = self.background_fbo = None
        self.background_depth = None
        self._background_key: tuple | None = None  # the view the cache holds
        self._last_view: tuple | None = None        # the last frame's
        self.ground_vaos: list[moderngl.VertexArray] = []
        self.node_texture = self.object_texture = None
        self.shadow: ShadowMap | None = None
        self._lines: dict[int, _Lines] = {}
        try:
            self.sky_prog = load_program(ctx, "sky.vert", "sky.frag")
            for shadowed in (0, 1):  # off and over the shadow's footprint
                self.ground_progs.append(load_program(ctx, "ground.vert", "ground.frag", defines={"SUN_SHADOW": shadowed}))
            self.background_prog = load_program(ctx, "sky.vert", "background.frag")
            self.line_prog = load_program(ctx, "line.vert", "line.frag", "line_geom.glsl")

            # --- static mesh: one index buffer, part after part
            tris = [self.mesh.part_indices(name) for name in PARTS]
            if self.mesh.triangle_count:
                self.vbo = ctx.buffer(self.mesh.vertices.tobytes())
                self.ibo = ctx.buffer(np.concatenate(tris).tobytes())
            first = 0
            for k, (name, t) in enumerate(zip(PARTS, tris)):
                part = self.parts[name] = _Part(load_program(ctx, "tree.vert", "tree.frag", defines={"PART": k}),
                                                None, first, 3 * len(t))
                if part.count:
                    part.vao = ctx.vertex_array(part.prog, [(self.vbo, VERTEX_FORMAT, *VERTEX_ATTRIBUTES)],
                                                index_buffer=self.ibo, index_element_size=4)
                first += part.count
            bound = _bound_framebuffer(ctx)
            self.shadow = ShadowMap(ctx, self.vbo, shadow_indices(self.mesh, tree), self.scene.shadow_size)
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
            for prog in (*self.tree_progs, self.line_prog, self.shadow.prog):
                self._uniform(prog, "u_nodes", 0)
                self._uniform(prog, "u_objects", 1)
            for prog in (*self.tree_progs, *self.ground_progs):
                self._uniform(prog, "u_shadow_map", 2)

            # --- sky and background: a full-screen triangle; ground: polygons in clip space
            self.sky_vao = ctx.vertex_array(self.sky_prog, [])
            self.background_vao = ctx.vertex_array(self.background_prog, [])
            self._uniform(self.background_prog, "u_background", 3)
            self.ground_vbo = ctx.buffer(reserve=4096, dynamic=True)
            for prog in self.ground_progs:
                self.ground_vaos.append(ctx.vertex_array(prog, [(self.ground_vbo, "4f", "in_clip")]))
            self._place_ground()

            self._present: np.ndarray | None = None  # None: derived from the season at draw time
            self._present_season: float | None = None
            self._highlight = np.zeros(M, bool)
            self._objects_dirty = True
            self.update(tree.rest_positions, np.broadcast_to(np.eye(3), (N, 3, 3)))
        except BaseException:
            self.release()
            raise

    # ------------------------------------------------------------------ helpers
    @property
    def tree_progs(self) -> list[moderngl.Program]:
        """The programs of the mesh's parts."""
        return [p.prog for p in self.parts.values()]

    @property
    def lit_progs(self) -> list[moderngl.Program]:
        """Every program that lights a surface (``common.glsl``'s uniforms)."""
        return [*self.tree_progs, *self.ground_progs, self.sky_prog]

    @staticmethod
    def _uniform(prog: moderngl.Program, name: str, value) -> None:
        u = prog.get(name, None)
        if u is not None:
            u.value = value

    def _write(self, progs, name: str, data: bytes) -> None:
        for prog in progs:
            u = prog.get(name, None)
            if u is not None:
                u.write(data)

    @property
    def pad(self) -> float:
        """How far the tree's surface reaches beyond its nodes (metres): a lamina's length plus
        half the thickest diameter."""
        return float(np.max(self.tree.lamina_length, initial=0.0)) + 0.5 * float(np.max(self.tree.node_diameter))

    def bounds(self, positions: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Axis-aligned box of the tree (nodes, plus the leaves' laminas), world."""
        P = self.tree.rest_positions if positions is None else np.asarray(positions)
        return P.min(axis=0) - self.pad, P.max(axis=0) + self.pad

    def _place_ground(self) -> None:
        tree = self.tree
        P = tree.rest_positions
        lo, hi = self.bounds()
        size = float(np.max(hi - lo))
        self.size = size
        roots = tree.object_start[tree.parent < 0]
        branch = tree.kind == "branch"
        trunk_foot = P[roots[0]] if len(roots) and branch.any() else 0.5 * (lo + hi)
        self.ground_centre = np.array([trunk_foot[0], 0.0, trunk_foot[2]])
        trunks = tree.object_start[(tree.parent < 0) & branch]
        self.earth_radius = float(5.0 * tree.node_diameter[trunks].max()) if len(trunks) else 0.0
        leafy = tree.kind != "branch"
        pts = P[np.isin(tree.node_object, np.flatnonzero(leafy))] if leafy.any() else P
        self.crown_centre = pts.mean(axis=0)
        spread = np.percentile(np.linalg.norm(pts[:, [0, 2]] - self.crown_centre[[0, 2]], axis=1), 85)
        self.occlusion_radius = float(max(1.1 * spread, 0.1 * size))
        self.trunk_radius = float(0.5 * tree.node_diameter[trunks].max()) if len(trunks) else 0.0

    def _apply_scene(self) -> None:
        s = self.scene
        key = tuple(vars(s).values())
        if key == self._applied_scene:
            return
        self._applied_scene = key
        sun = np.asarray(s.sun_direction, float)
        sun = tuple(sun / np.linalg.norm(sun))
        lit = {
            "u_sun_dir": sun,
            "u_sun_color": tuple(c * s.sun_intensity for c in _lin(s.sun_color)),
            "u_sky_zenith": _lin(s.sky_zenith),
            "u_sky_horizon": _lin(s.sky_horizon),
            "u_ground_bounce": _lin(s.ground_bounce),
            "u_ambient": float(s.ambient),
            "u_haze_distance": float(s.haze_distance or max(40.0 * self.size, 60.0)),
            "u_exposure": float(s.exposure),
        }
        for prog in self.lit_progs:
            for k, v in lit.items():
                self._uniform(prog, k, v)
        self._uniform(self.sky_prog, "u_show_sky", int(s.show_sky))
        c = self.crown_centre  # the crown hides the sky straight above the ground under it
        for g in self.ground_progs:
            self._uniform(g, "u_ground_centre", tuple(self.ground_centre))
            self._uniform(g, "u_earth_radius", float(self.earth_radius))
            self._uniform(g, "u_occlusion_centre", (float(c[0]), 0.0, float(c[2])))
            self._uniform(g, "u_occlusion_radius", float(self.occlusion_radius if s.shadow else 0.0))
            self._uniform(g, "u_trunk_radius", float(self.trunk_radius if s.shadow else 0.0))
            self._uniform(g, "u_grid", float(s.ground_grid))
        bark = self.tree.bark
        for prog in self.tree_progs:
            self._uniform(prog, "u_translucency", float(s.translucency))
            self._uniform(prog, "u_bark_color", tuple(float(c) for c in bark.color))
            self._uniform(prog, "u_bark", (float(bark.furrows), float(bark.depth), float(bark.interlace),
                                           float(bark.lenticels)))
        if s.shadow:
            self.shadow.fit(sun, *self.bounds(), self.tree.rest_positions, self.pad)
        else:
            self.shadow.clear()
        for prog in self.lit_progs:
            self._uniform(prog, "u_shadow_on", int(s.shadow))
            self._uniform(prog, "u_shadow_texel", float(self.shadow.texel))
            self._write((prog,), "u_light_view_proj", self.shadow.matrix.tobytes())

    # ------------------------------------------------------------------ per frame
    def update(self, positions: np.ndarray, rotations: np.ndarray, present: np.ndarray | None = None,
               highlight=None) -> None:
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
        """
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
        self.node_texture.use(0)
        self.object_texture.use(1)
        if self.scene.shadow:
            ctx.disable(moderngl.CULL_FACE | moderngl.BLEND)
            self.shadow.draw()
        vp = camera.view_projection(width, height)
        vp_bytes = vp.tobytes()
        eye = tuple(float(x) for x in camera.eye)
        inv_bytes = np.linalg.inv(vp.astype(np.float64)).astype(np.float32).tobytes()
        self._write((*self.tree_progs, self.line_prog), "u_view_proj", vp_bytes)
        for prog in self.lit_progs:
            self._uniform(prog, "u_camera_pos", eye)
        for prog in (*self.ground_progs, self.sky_prog):
            self._write((prog,), "u_inv_view_proj", inv_bytes)
            self._uniform(prog, "u_viewport", (float(width), float(height)))
        for prog in self.tree_progs:
            self._uniform(prog, "u_season", season)
            self._uniform(prog, "u_pixels_per_metre", 0.5 * height / math.tan(math.radians(camera.fov_y) / 2))
            self._uniform(prog, "u_thin_pixels", float(self.scene.thin_pixels))
        cached = self._cache_background(camera, vp, width, height)
        target.use()
        ctx.viewport = (0, 0, width, height)

        s = self.scene
        hz = _lin(s.sky_horizon)
        ctx.clear(hz[0] ** (1 / 2.2), hz[1] ** (1 / 2.2), hz[2] ** (1 / 2.2), 1.0, depth=1.0)
        ctx.disable(moderngl.CULL_FACE | moderngl.BLEND)
        ctx.enable(moderngl.DEPTH_TEST)
        ctx.depth_func = "<"
        self.shadow.texture.use(2)
        # The leaves first: solid, so the ground and sky under them are never shaded. Then the
        # ground over the shadow's footprint, with its shadow, and where neither was drawn the
        # background: sky and the rest of the ground (a copy of the cache, or drawn here).
        self.parts["LEAVES"].render()
        if s.shadow and self._ground_shown(camera):
            self._ground(self.ground_vaos[1], self.shadow.footprint, vp, DEPTH_FOOTPRINT)
        if cached:
            ctx.depth_func = "<="
            self.background_texture.use(3)
            self.background_vao.render(moderngl.TRIANGLES, vertices=3)
            ctx.depth_func = "<"
        else:
            self._draw_background(camera, vp)
        # Blended: twigs and blades thinner than a pixel are drawn faint over what lies behind.
        ctx.enable(moderngl.BLEND)
        ctx.blend_func = moderngl.SRC_ALPHA, moderngl.ONE_MINUS_SRC_ALPHA
        self.parts["BARK"].render()
        self.parts["BLADES"].render()
        ctx.disable(moderngl.BLEND)
        overlays = [o for o in overlays if o is not None]
        if overlays:
            self._draw_overlays(overlays, width, height)
        self._collect_lines({id(o) for o in overlays})

    def _ground_shown(self, camera: OrbitCamera) -> bool:
        return bool(self.scene.show_ground and camera.eye[1] > 0.0)

    def _ground(self, vao: moderngl.VertexArray, polygon: np.ndarray, vp: np.ndarray, depth: float) -> None:
        """One convex polygon of the ground ((K, 2) corners x, z), drawn by ``vao``'s program at
        ``depth`` (NDC z)."""
        tris = clip_ground(polygon, vp, depth)
        if len(tris):
            if self.ground_vbo.size < tris.nbytes:
                self.ground_vbo.orphan(2 * tris.nbytes)
            self.ground_vbo.write(tris.tobytes())
            vao.render(moderngl.TRIANGLES, vertices=len(tris))

    def _draw_background(self, camera: OrbitCamera, vp: np.ndarray) -> None:
        """The background, where nothing was drawn yet (depth test on): the ground without
        shadows, a square out to the horizon round the eye, behind the footprint's, then the
        sky at the far plane."""
        if self._ground_shown(camera):
            eye = np.asarray(camera.eye, float)
            square = eye[[0, 2]] + HORIZON_REACH * eye[1] * np.array([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]])
            self._ground(self.ground_vaos[0], square, vp, DEPTH_GROUND)
        self.ctx.depth_func = "<="
        self.sky_vao.render(moderngl.TRIANGLES, vertices=3)
        self.ctx.depth_func = "<"

    def _cache_background(self, camera: OrbitCamera, vp: np.ndarray, width: int, height: int) -> bool:
        """Whether the background cache holds this frame's background; drawn into it on the
        second frame in a row with the same viewport, camera and scene. Neither sky nor the
        ground without shadows moves with the tree, so while the camera is still each frame
        copies them (a copy costs llvmpipe a fifth of shading them); while it moves they are
        drawn in the frame as before, so a moving camera pays nothing for the cache."""
        key = (width, height, vp.tobytes(), tuple(camera.eye), self._applied_scene)
        if key == self._background_key:
            return True
        if key != self._last_view:
            self._last_view = key
            return False
        ctx = self.ctx
        if self.background_texture is None or self.background_texture.size != (width, height):
            for o in (self.background_fbo, self.background_depth, self.background_texture):
                if o is not None:
                    o.release()
            self.background_fbo = self.background_depth = None  # made next: released again if that fails
            self.background_texture = ctx.texture((width, height), 4)
            self.background_texture.filter = (moderngl.NEAREST, moderngl.NEAREST)
            self.background_depth = ctx.depth_renderbuffer((width, height))
            self.background_fbo = ctx.framebuffer(self.background_texture, self.background_depth)
        self.background_fbo.use()
        ctx.viewport = (0, 0, width, height)
        self.background_fbo.clear(depth=1.0)
        ctx.disable(moderngl.BLEND | moderngl.CULL_FACE)
        ctx.enable(moderngl.DEPTH_TEST)
        ctx.depth_func = "<"
        self._draw_background(camera, vp)
        self._background_key = key
        return True

    # ------------------------------------------------------------------ overlays
    def _draw_overlays(self, overlays, width: int, height: int) -> None:
        ctx = self.ctx
        ctx.enable(moderngl.BLEND)
        ctx.blend_func = moderngl.SRC_ALPHA, moderngl.ONE_MINUS_SRC_ALPHA
        self._uniform(self.line_prog, "u_viewport", (float(width), float(height)))
        for ov in overlays:
            buf = self._lines.get(id(ov))
            if buf is None or buf.ref() is not ov:
                if buf is not None:
                    buf.release()
                buf = self._lines[id(ov)] = _Lines(ov)
            if not (ov.static and buf.uploaded):
                ls = ov.lines(self.tree)
                data = ls.packed().tobytes() if ls is not None and len(ls.points) >= 2 else b""
                buf.count = len(data) // 32
                buf.uploaded = True
                if buf.count:
                    if buf.vbo is None or buf.vbo.size < len(data):
                        buf.release()
                        buf.vbo = ctx.buffer(reserve=max(len(data), 4096) * 2, dynamic=True)
                        buf.vao = ctx.vertex_array(self.line_prog, [(buf.vbo, LINE_FORMAT, *LINE_ATTRIBUTES)])
                    buf.vbo.write(data)
            if not buf.count:
                continue
            if ov.on_top:
                ctx.disable(moderngl.DEPTH_TEST)
            else:
                ctx.enable(moderngl.DEPTH_TEST)
            self._uniform(self.line_prog, "u_width", float(ov.width))
            buf.vao.render(moderngl.LINES, vertices=buf.count - buf.count % 2)
        ctx.disable(moderngl.BLEND)
        ctx.enable(moderngl.DEPTH_TEST)

    def _collect_lines(self, live: set[int]) -> None:
        for key in [k for k, b in self._lines.items() if k not in live or b.ref() is None]:
            self._lines.pop(key).release()

    # ------------------------------------------------------------------ teardown
    def release(self) -> None:
        """Free every GPU resource (idempotent)."""
        if self._released:
            return
        self._released = True
        for b in self._lines.values():
            b.release()
        self._lines.clear()
        if self.shadow is not None:
            self.shadow.release()
        for o in (*[p.vao for p in self.parts.values()], *self.tree_progs, self.vbo, self.ibo, self.sky_vao,
                  *self.ground_vaos, self.ground_vbo, self.node_texture, self.object_texture, self.sky_prog,
                  *self.ground_progs, self.background_vao, self.background_fbo, self.background_texture,
                  self.background_depth,
                  self.background_prog, self.line_prog):
            if o is not None:
                o.release()
