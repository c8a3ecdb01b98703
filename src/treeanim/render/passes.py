"""The renderer's passes: each owns its programs, its vertex arrays and buffers, and the uniform
block of its own settings (:mod:`treeanim.render.uniforms`); :class:`~.renderer.Renderer`
makes them, feeds them the scene and the view, and calls them in the frame's order. The sun's
shadow map is the fifth (:class:`~.shadow.ShadowMap`).

- :class:`TreePass`: the skinned mesh, one program per part (``mesh.PARTS``).
- :class:`GroundPass`: the ground plane, as convex polygons cut in front of the eye, with the
  sun's shadow or without.
- :class:`SkyPass`: the sky, a full-screen triangle at the far plane.
- :class:`BackgroundCache`: sky and shadowless ground drawn once into a texture while the view
  holds still, and copied each frame after.
- :class:`OverlayPass`: the overlays' lines.

Each pass frees what it made if its construction fails, and its ``release()`` is idempotent.
A pass binds its own block when it draws; the blocks every pass reads (``Light``, ``View``,
``Shadow``) and the node and object textures are bound by the renderer first.
"""

from __future__ import annotations

import weakref

import moderngl
import numpy as np

from ..model.scene import Scene as TreeScene
from ..model.tree import Tree
from .culling import TreeOrder, blade_cells
from .ground_maps import ground_texture
from .leaf_maps import lamina_box, leaf_texture
from .lod import (
    LOD_LAMINA_CORNERS,
    blade_band,
    clump_copies,
    coarse_laminas,
    coarse_tubes,
    lod_band,
    median_blade,
    median_leaf,
)
from .mesh import MATERIAL_BLADE, PARTS, VERTEX_ATTRIBUTES, VERTEX_FORMAT, TreeMesh
from .overlays import LINE_ATTRIBUTES, LINE_FORMAT, Overlay
from .scene import Scene, clip_ground
from .shaders import load_program
from .uniforms import SAMPLERS, UniformBlock


def release_all(*objects) -> None:
    """Release each GL object or pass that is not None."""
    for o in objects:
        if o is not None:
            o.release()


class TreePass:
    """The tree's skinned mesh: one static vertex buffer, one index buffer part after part, a
    program per part (``PART`` in ``tree.vert``/``tree.frag``: each holds only its own code), and
    the ``Tree`` block.

    Each part's triangles lie tree by tree (:class:`~.culling.TreeOrder`), and after the parts
    a scene's far trees' leaves and bark (:func:`~.lod.coarse_laminas`,
    :func:`~.lod.coarse_tubes`), so :meth:`view` can keep a scene's draws to the trees in view,
    and its far trees coarse: two more programs for leaves and two for bark (``LOD_FADE`` 1 and
    2) draw the full and coarse meshes of the trees in the hand-over band, dithered. A lone
    tree is one range a part, always drawn whole.

    The grass lies square by square of the ground instead (:func:`~.culling.blade_cells`, a
    lone meadow's too): its simulated blades, then its clumps' copies (:func:`~.lod.clump_copies`),
    drawn by two programs (``LOD_FADE`` 2 and 1) that hand a far clump over to its simulated
    blade alone (:func:`~.lod.blade_band`); the squares out of view are not drawn, nor the
    copies of those beyond the band.

    Parameters
    ----------
    ctx : moderngl.Context
    mesh : TreeMesh
    tree : Tree
        The mesh's tree (its bark's look; its trees, if a scene).
    pad : float
        How far the surface reaches beyond the nodes (the trees' spheres).

    Attributes
    ----------
    order : TreeOrder
    cells : TreeOrder
        The grass's squares.
    drawn : dict
        The last frame's draws: ``trees`` in view, ``triangles`` and ``draws`` (calls).
    """

    def __init__(self, ctx: moderngl.Context, mesh: TreeMesh, tree: Tree, pad: float = 0.0) -> None:
        self.vbo = self.ibo = self.block = self.leaf_maps = None
        self.programs: dict[tuple[str, int], tuple[moderngl.Program, moderngl.VertexArray | None]] = {}
        self.order = TreeOrder(tree, mesh, pad)
        self.many = self.order.n_trees > 1
        self.leaf, self.blade = median_leaf(tree), median_blade(tree)
        # a square's sphere holds its clumps' copies, which stand up to about a blade's height off their roots
        blade_tip = np.max(tree.rest_positions[np.asarray(tree.kind)[tree.node_object] == "blade", 1], initial=0.0)
        self.cells = TreeOrder(tree, mesh, pad + float(blade_tip), blade_cells(tree))
        self.drawn = {"trees": 0, "triangles": 0, "draws": 0}
        try:
            self.block = UniformBlock(ctx, "Tree")
            bark = tree.bark
            if tree.lamina is not None and len(tree.lamina.outline):
                self.leaf_maps = leaf_texture(ctx, tree.lamina)
            self.block.set(bark_color=bark.color, bark=(bark.furrows, bark.depth, bark.interlace, bark.lenticels),
                           lamina_box=lamina_box(tree.lamina) if self.leaf_maps is not None else (1.0, 1.0),
                           lod_band=(1e30, 2e30), blade_band=(1e30, 2e30))
            tris, self.ranges, first = [], {}, 0
            blade, copies = mesh.material[mesh.indices[:, 0]] == MATERIAL_BLADE, clump_copies(mesh)
            groups = [(name, self.order, mesh.part_indices(name)) for name in ("LEAVES", "BARK")]
            groups += [("BLADES", self.cells, mesh.indices[blade & ~copies]), ("BLADE_COPIES", self.cells, mesh.indices[copies])]
            if self.many:
                groups += [("COARSE_LEAVES", self.order, coarse_laminas(mesh, tree, LOD_LAMINA_CORNERS)),
                           ("COARSE_BARK", self.order, coarse_tubes(mesh))]
            for name, order, t in groups:
                t, self.ranges[name] = order.group(t, first)
                tris.append(t)
                first += self.ranges[name].total
            if mesh.triangle_count:
                self.vbo = ctx.buffer(mesh.vertices.tobytes())
                self.ibo = ctx.buffer(np.concatenate(tris).astype(np.uint32).tobytes())
            variants = [("LEAVES", 0), ("BARK", 0), ("BLADES", 1), ("BLADES", 2)]
            variants += [(n, f) for n in ("LEAVES", "BARK") for f in (1, 2)] if self.many else []
            for name, fade in variants:
                prog = load_program(ctx, "tree.vert", "tree.frag", defines={"PART": list(PARTS).index(name), "LOD_FADE": fade})
                vao = None
                if self.ranges[name].total:
                    vao = ctx.vertex_array(prog, [(self.vbo, VERTEX_FORMAT, *VERTEX_ATTRIBUTES)],
                                           index_buffer=self.ibo, index_element_size=4)
                self.programs[name, fade] = (prog, vao)
        except BaseException:
            self.release()
            raise
        self.view()

    def apply(self, scene: Scene) -> None:
        """Take the scene's settings (leaves' translucency, thin lines' width)."""
        self.block.set(translucency=scene.translucency, thin_pixels=scene.thin_pixels)

    def view(self, view_proj: np.ndarray | None = None, eye=None, pixels_per_metre: float = 0.0) -> None:
        """Which trees the next frame's draws hold: of a scene, those whose sphere reaches into
        ``view_proj``'s volume, their leaves full or coarse by their distance from the ``eye``
        and how long a leaf is on screen (:func:`~.lod.lod_band`); the grass's squares in view,
        their clumps whole, or one blade each, by how wide a blade is on screen
        (:func:`~.lod.blade_band`); None: every tree and blade, full."""
        n, m = self.order.n_trees, self.cells.n_trees
        keep, full, coarse = np.ones(n, bool), np.ones(n, bool), np.zeros(n, bool)
        grass, clumps = np.ones(m, bool), np.ones(m, bool)
        band = blade = (1e30, 2e30)
        if view_proj is not None:
            eye = np.asarray(eye, float)
            if self.many:
                keep = self.order.visible(view_proj)
                band = lod_band(self.leaf, pixels_per_metre)
                d = np.linalg.norm(self.order.centres - eye, axis=1)
                full, coarse = d + self.order.radii <= band[0], d - self.order.radii >= band[1]
            grass = self.cells.visible(view_proj)
            blade = blade_band(self.blade, pixels_per_metre)
            clumps = np.linalg.norm(self.cells.centres - eye, axis=1) - self.cells.radii < blade[1]
        self.block.set(lod_band=band, blade_band=blade)
        both = keep & ~(full | coarse)
        # each part's draws: (ranges, program variant, trees)
        self._draws = {"LEAVES": [("LEAVES", 0, keep & full), ("COARSE_LEAVES", 0, keep & coarse),
                                  ("LEAVES", 1, both), ("COARSE_LEAVES", 2, both)],
                       "BARK": [("BARK", 0, keep & full), ("COARSE_BARK", 0, keep & coarse),
                                ("BARK", 1, both), ("COARSE_BARK", 2, both)],
                       "BLADES": [("BLADES", 2, grass), ("BLADE_COPIES", 1, grass & clumps)]}
        self.drawn = {"trees": int(keep.sum()), "triangles": 0, "draws": 0}

    def draw(self, *parts: str, season: float) -> None:
        """Draw ``parts`` (names of ``mesh.PARTS``) in order, of the trees :meth:`view` kept, the
        leaves coloured for ``season`` (0 summer .. 1 winter); the shadow map bound to its unit."""
        self.block.set(season=season)
        self.block.use()
        if self.leaf_maps is not None:
            self.leaf_maps.use(SAMPLERS["leaf_maps"].unit)
        for name in parts:
            for ranges, fade, keep in self._draws[name]:
                vao = self.programs[name, fade][1] if keep.any() else None  # a lone tree: no coarse ranges
                for first, count in self.ranges[ranges].runs(keep) if vao is not None else ():
                    vao.render(moderngl.TRIANGLES, vertices=count, first=first)
                    self.drawn["triangles"] += count // 3
                    self.drawn["draws"] += 1

    def release(self) -> None:
        """Free the GL objects (idempotent)."""
        for prog, vao in self.programs.values():
            release_all(vao, prog)
        self.programs = {}
        release_all(self.vbo, self.ibo, self.block, self.leaf_maps)
        self.vbo = self.ibo = self.block = self.leaf_maps = None


class GroundPass:
    """The ground y = 0: grass and soil (``ground.frag``), the sky the crown hides and a contact
    shadow at the trunk's foot; drawn as convex polygons in clip space (``ground.vert``), cut in
    front of the eye (:func:`~.scene.clip_ground`), by one of two programs: with the sun's shadow
    (``SUN_SHADOW`` 1, over the shadow's footprint only) or without.

    Parameters
    ----------
    ctx : moderngl.Context
    tree : Tree
    bounds : ((3,) float, (3,) float)
        The tree's box at rest (:meth:`Renderer.bounds`).
    """

    def __init__(self, ctx: moderngl.Context, tree: Tree, bounds) -> None:
        self.progs: list[moderngl.Program] = []
        self.vaos: list[moderngl.VertexArray] = []
        self.vbo = self.block = self.maps = None
        try:
            self.block = UniformBlock(ctx, "Ground")
            self.maps = ground_texture(ctx)
            for shadowed in (0, 1):
                self.progs.append(load_program(ctx, "ground.vert", "ground.frag", defines={"SUN_SHADOW": shadowed}))
            self.vbo = ctx.buffer(reserve=4096, dynamic=True)
            for prog in self.progs:
                self.vaos.append(ctx.vertex_array(prog, [(self.vbo, "4f", "in_clip")]))
            self._place(tree, *bounds)
        except BaseException:
            self.release()
            raise

    def _place(self, tree: Tree, lo: np.ndarray, hi: np.ndarray) -> None:
        """Where the ground's features lie, from the tree at rest."""
        P = tree.rest_positions
        roots = tree.object_start[tree.parent < 0]
        branch = tree.kind == "branch"
        trunk_foot = P[roots[0]] if len(roots) and branch.any() else 0.5 * (lo + hi)
        trunks = tree.object_start[(tree.parent < 0) & branch]
        leafy = tree.kind != "branch"
        pts = P[np.isin(tree.node_object, np.flatnonzero(leafy))] if leafy.any() else P
        crown = pts.mean(axis=0)
        spread = np.percentile(np.linalg.norm(pts[:, [0, 2]] - crown[[0, 2]], axis=1), 85)
        self.occlusion_radius = float(max(1.1 * spread, 0.1 * float(np.max(hi - lo))))
        self.trunk_radius = float(0.5 * tree.node_diameter[trunks].max()) if len(trunks) else 0.0
        if isinstance(tree, TreeScene) and tree.n_trees > 1:  # one tree's shade and foot: not a scene's
            self.occlusion_radius = self.trunk_radius = 0.0
        self.block.set(ground_centre=(trunk_foot[0], 0.0, trunk_foot[2]), occlusion_centre=(crown[0], 0.0, crown[2]))

    def apply(self, scene: Scene) -> None:
        """Take the scene's settings (the crown's shade and the trunk's contact shadow go with the
        sun's shadows; the grid)."""
        self.block.set(occlusion_radius=self.occlusion_radius if scene.shadow else 0.0,
                       trunk_radius=self.trunk_radius if scene.shadow else 0.0, grid=scene.ground_grid)

    def draw(self, polygon: np.ndarray, view_proj: np.ndarray, depth: float, shadowed: bool) -> None:
        """Draw one convex polygon of the ground at ``depth`` (NDC z).

        Parameters
        ----------
        polygon : (K, 2) float
            Corners (x, z), in order round it.
        view_proj : (4, 4) float
            World → clip (:meth:`OrbitCamera.view_projection`).
        depth : float
        shadowed : bool
            With the sun's shadow (the shadow map bound to its unit).
        """
        tris = clip_ground(polygon, view_proj, depth)
        if len(tris):
            if self.vbo.size < tris.nbytes:
                self.vbo.orphan(2 * tris.nbytes)
            self.vbo.write(tris.tobytes())
            self.block.use()
            self.maps.use(SAMPLERS["ground_maps"].unit)
            self.vaos[int(shadowed)].render(moderngl.TRIANGLES, vertices=len(tris))

    def release(self) -> None:
        """Free the GL objects (idempotent)."""
        release_all(*self.vaos, *self.progs, self.vbo, self.block, self.maps)
        self.vaos, self.progs = [], []
        self.vbo = self.block = self.maps = None


class SkyPass:
    """The sky: gradient, clouds, sun disc and glow (``sky.frag``), one full-screen triangle at the
    far plane drawn with depth test <=, where nothing else was."""

    def __init__(self, ctx: moderngl.Context) -> None:
        self.ctx = ctx
        self.prog = self.vao = self.block = None
        try:
            self.block = UniformBlock(ctx, "Sky")
            self.prog = load_program(ctx, "sky.vert", "sky.frag")
            self.vao = ctx.vertex_array(self.prog, [])
        except BaseException:
            self.release()
            raise

    def apply(self, scene: Scene) -> None:
        """Take the scene's settings (the sky shown, or a flat horizon colour; its clouds)."""
        self.block.set(show_sky=scene.show_sky, clouds=scene.clouds)

    def draw(self) -> None:
        """Draw the sky where the depth buffer is clear."""
        self.block.use()
        self.ctx.depth_func = "<="
        self.vao.render(moderngl.TRIANGLES, vertices=3)
        self.ctx.depth_func = "<"

    def release(self) -> None:
        """Free the GL objects (idempotent)."""
        release_all(self.vao, self.prog, self.block)
        self.vao = self.prog = self.block = None


class BackgroundCache:
    """The background (the sky and the ground without shadows) of the last still view, in a
    texture, and the pass that copies it into a frame (``background.frag``).

    Neither moves with the tree, so while the camera, the viewport and the scene hold still a
    frame copies them (a copy costs llvmpipe a fifth of shading them). A view is cached on the
    second frame in a row it is drawn; while the camera moves the background is drawn in the
    frame, so a moving camera pays nothing for the cache.
    """

    def __init__(self, ctx: moderngl.Context) -> None:
        self.ctx = ctx
        self.prog = self.vao = self.texture = self.depth = self.fbo = None
        self._key: tuple | None = None        # the view the cache holds
        self._last_view: tuple | None = None  # the last frame's
        try:
            self.prog = load_program(ctx, "sky.vert", "background.frag")
            self.vao = ctx.vertex_array(self.prog, [])
        except BaseException:
            self.release()
            raise

    def holds(self, key: tuple, size: tuple[int, int], draw) -> bool:
        """Whether the cache holds the background of view ``key`` (anything that changes the
        background: viewport, camera, scene); on the second frame in a row with the same key, the
        background is drawn into it first by ``draw()`` (depth test on, nothing blended).

        Parameters
        ----------
        key : tuple
        size : (int, int)
            Width and height in pixels.
        draw : callable
            Draws the background into the bound framebuffer.
        """
        if key == self._key:
            return True
        if key != self._last_view:
            self._last_view = key
            return False
        ctx = self.ctx
        if self.texture is None or self.texture.size != size:
            release_all(self.fbo, self.depth, self.texture)
            self.fbo = self.depth = None  # made next: released again if that fails
            self.texture = ctx.texture(size, 4)
            self.texture.filter = (moderngl.NEAREST, moderngl.NEAREST)
            self.depth = ctx.depth_renderbuffer(size)
            self.fbo = ctx.framebuffer(self.texture, self.depth)
        self.fbo.use()
        ctx.viewport = (0, 0, *size)
        self.fbo.clear(depth=1.0)
        ctx.disable(moderngl.BLEND | moderngl.CULL_FACE)
        ctx.enable(moderngl.DEPTH_TEST)
        ctx.depth_func = "<"
        draw()
        self._key = key
        return True

    def draw(self) -> None:
        """Copy the cache into the bound framebuffer where nothing was drawn yet."""
        self.texture.use(SAMPLERS["background"].unit)
        self.ctx.depth_func = "<="
        self.vao.render(moderngl.TRIANGLES, vertices=3)
        self.ctx.depth_func = "<"

    def release(self) -> None:
        """Free the GL objects (idempotent)."""
        release_all(self.vao, self.fbo, self.texture, self.depth, self.prog)
        self.vao = self.fbo = self.texture = self.depth = self.prog = None


class _Lines:
    """GPU buffers of one overlay."""

    def __init__(self, overlay: Overlay) -> None:
        self.ref = weakref.ref(overlay)
        self.vbo: moderngl.Buffer | None = None
        self.vao: moderngl.VertexArray | None = None
        self.count = 0
        self.uploaded = False

    def release(self) -> None:
        release_all(self.vao, self.vbo)
        self.vao = self.vbo = None


class OverlayPass:
    """Overlays (:mod:`~.overlays`) as screen-space lines (``line.vert`` + ``line_geom.glsl``),
    each overlay's in its own buffers, uploaded once if it is static, freed once it is gone."""

    def __init__(self, ctx: moderngl.Context) -> None:
        self.ctx = ctx
        self.prog = self.block = None
        self._lines: dict[int, _Lines] = {}
        try:
            self.block = UniformBlock(ctx, "Lines")
            self.prog = load_program(ctx, "line.vert", "line.frag", "line_geom.glsl")
        except BaseException:
            self.release()
            raise

    def draw(self, overlays: list[Overlay], tree: Tree) -> None:
        """Draw ``overlays`` in order (blended; with or without depth test, as each says), and
        free the buffers of overlays not drawn."""
        ctx = self.ctx
        if overlays:
            ctx.enable(moderngl.BLEND)
            ctx.blend_func = moderngl.SRC_ALPHA, moderngl.ONE_MINUS_SRC_ALPHA
            for ov in overlays:
                buf = self._upload(ov, tree)
                if not buf.count:
                    continue
                if ov.on_top:
                    ctx.disable(moderngl.DEPTH_TEST)
                else:
                    ctx.enable(moderngl.DEPTH_TEST)
                self.block.set(width=ov.width)
                self.block.use()
                buf.vao.render(moderngl.LINES, vertices=buf.count - buf.count % 2)
            ctx.disable(moderngl.BLEND)
            ctx.enable(moderngl.DEPTH_TEST)
        live = {id(o) for o in overlays}
        for key in [k for k, b in self._lines.items() if k not in live or b.ref() is None]:
            self._lines.pop(key).release()

    def _upload(self, ov: Overlay, tree: Tree) -> _Lines:
        buf = self._lines.get(id(ov))
        if buf is None or buf.ref() is not ov:
            if buf is not None:
                buf.release()
            buf = self._lines[id(ov)] = _Lines(ov)
        if not (ov.static and buf.uploaded):
            ls = ov.lines(tree)
            data = ls.packed().tobytes() if ls is not None and len(ls.points) >= 2 else b""
            buf.count = len(data) // 32
            buf.uploaded = True
            if buf.count:
                if buf.vbo is None or buf.vbo.size < len(data):
                    buf.release()
                    buf.vbo = self.ctx.buffer(reserve=max(len(data), 4096) * 2, dynamic=True)
                    buf.vao = self.ctx.vertex_array(self.prog, [(buf.vbo, LINE_FORMAT, *LINE_ATTRIBUTES)])
                buf.vbo.write(data)
        return buf

    def release(self) -> None:
        """Free the GL objects (idempotent)."""
        for b in self._lines.values():
            b.release()
        self._lines.clear()
        release_all(self.prog, self.block)
        self.prog = self.block = None
