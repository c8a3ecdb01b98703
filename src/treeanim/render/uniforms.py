"""Every uniform the shaders read, declared once: the tables here.

Values set per scene or per frame live in std140 uniform blocks (:data:`BLOCKS`), textures in
samplers on fixed texture units (:data:`SAMPLERS`). The shaders get both from ``#include
"uniforms.glsl"``, written from these tables (:func:`uniforms_glsl`), so GLSL and Python cannot
disagree about a name, a type or an offset. Python sets a block's members through
:class:`UniformBlock`, which refuses a name its block lacks and will not draw with a member
never set; :func:`bind_program` checks every program as it is linked (a uniform outside these
tables is an error) and gives each block its binding point and each sampler its unit. Nothing
is set on a program by name, so nothing can be skipped.

A member ``name`` of a block is ``u_name`` in GLSL. The std140 layout holds a block's members
in their order here, and keeps every block and member active whether a program reads it or
not: one buffer a block serves every program, and the checks do not depend on what a compiler
strips.
"""

from __future__ import annotations

from typing import NamedTuple

import moderngl
import numpy as np

#: The uniform blocks: name → members (GLSL type, name without ``u_``, what it holds). A
#: block's binding point is its place here; the comment names the pass that owns it.
BLOCKS: dict[str, tuple[tuple[str, str, str], ...]] = {
    # The renderer's, set when the scene changes: the light of every lit surface (common.glsl).
    "Light": (
        ("vec3", "sun_dir", "unit, towards the sun"),
        ("vec3", "sun_color", "linear"),
        ("vec3", "sky_zenith", "linear"),
        ("vec3", "sky_horizon", "linear (the air's colour away from the sun: haze)"),
        ("vec3", "ground_bounce", "linear, light from below"),
        ("float", "ambient", "strength of the sky/ground hemisphere light"),
        ("float", "haze_distance", "metres at which haze reaches 63 %"),
        ("float", "exposure", "a factor on the linear colour before display"),
    ),
    # The renderer's, set each frame: the camera.
    "View": (
        ("mat4", "view_proj", "world -> clip"),
        ("mat4", "inv_view_proj", "clip -> world (sky and ground)"),
        ("vec3", "camera_pos", "the eye, world"),
        ("vec2", "viewport", "pixels"),
        ("float", "pixels_per_metre", "at one metre from the eye: a length's size on screen"),
    ),
    # ShadowMap's (shadow.py): the sun's view, for the map's pass and for its lookups (sun.glsl).
    "Shadow": (
        ("mat4", "light_view_proj", "world -> the shadow map's clip space"),
        ("int", "shadow_on", "0: everything in sunlight"),
        ("float", "shadow_texel", "one shadow-map texel, metres"),
        ("float", "shadow_edge", "shadows fade out over this share of the map's half side at its border (0: none)"),
    ),
    # TreePass's (tree.vert, tree.frag, tree_light.glsl).
    "Tree": (
        ("float", "season", "0 summer .. 1 winter"),
        ("float", "thin_pixels", "twigs and blades with a half width below this (px) get soft edges"),
        ("float", "translucency", "0: leaves pass no sunlight through"),
        ("vec3", "bark_color", "sRGB"),
        ("vec4", "bark", "furrows around a branch, furrow depth, interlacing, lenticels"),
        ("vec2", "lamina_box", "the lamina's half width and length: its uv over the leaf maps"),
        ("vec2", "lod_band", "metres from the eye where a scene's leaves hand over from full to coarse"),
        ("vec2", "blade_band", "metres from the eye where grass hands over from whole clumps to one blade a clump"),
    ),
    # GroundPass's (ground.frag).
    "Ground": (
        ("vec3", "ground_centre", "the trunk's foot"),
        ("vec3", "occlusion_centre", "below the crown's centre: the sky is hidden there"),
        ("float", "occlusion_radius", "0: none"),
        ("float", "trunk_radius", "contact shadow round the trunk's foot (0: none)"),
        ("float", "grid", "0: no grid; else grid line strength (1 m cells)"),
    ),
    # TurfPass's (turf.frag).
    "Turf": (
        ("vec4", "turf_grid", "the wind grid's corner (world x, z), its side and texels a side (m, count)"),
        ("vec2", "turf_lean", "the blades' lean atan((U / x)^y): U45 (m/s), the exponent"),
    ),
    # SkyPass's (sky.frag).
    "Sky": (
        ("int", "show_sky", "0: flat horizon colour"),
        ("float", "clouds", "how much of the sky clouds cover: 0 clear .. 1"),
    ),
    # OverlayPass's (line_geom.glsl), set before each overlay.
    "Lines": (
        ("float", "width", "pixels"),
    ),
}


class Sampler(NamedTuple):
    """A sampler uniform: its GLSL type, the texture unit it reads, what it holds."""

    type: str
    unit: int
    doc: str


#: The samplers: name (``u_name`` in GLSL) → type, unit and contents. Whoever draws binds the
#: texture to ``SAMPLERS[name].unit``.
SAMPLERS: dict[str, Sampler] = {
    "nodes": Sampler("sampler2D", 0, "per node: position and rotation (skin.glsl)"),
    "objects": Sampler("sampler2D", 1, "per object: r = visible, g = highlight"),
    "shadow_map": Sampler("sampler2DShadow", 2, "depth seen from the sun (shadow.py)"),
    "background": Sampler("sampler2D", 3, "the background cache (background.frag)"),
    "leaf_maps": Sampler("sampler2D", 4, "the lamina's albedo, translucency and relief (leaf_maps.py)"),
    "draft": Sampler("sampler2D", 5, "draft mode's smaller picture, scaled up (app/draft.py)"),
    "ground_maps": Sampler("sampler2D", 6, "the ground's tufts, patches, grain and tint (ground_maps.py)"),
    "turf_wind": Sampler("sampler2D", 7, "the wind over the turf: rg = its x and z components, m/s (turf.py)"),
}

#: std140 base alignment and size (bytes) of each member type.
_STD140 = {"float": (4, 4), "int": (4, 4), "vec2": (8, 8), "vec3": (16, 12), "vec4": (16, 16), "mat4": (16, 64)}
_NUMPY = {"float": ("<f4", ()), "int": ("<i4", ()), "vec2": ("<f4", (2,)), "vec3": ("<f4", (3,)),
          "vec4": ("<f4", (4,)), "mat4": ("<f4", (4, 4))}


def block_dtype(name: str) -> np.dtype:
    """The numpy structured dtype of block ``name``: its members at their std140 offsets.

    A ``mat4`` member is a (4, 4) array holding the matrix in GLSL's column-major byte order
    (as :meth:`OrbitCamera.view_projection` returns it: its ``tobytes()`` is what GLSL reads).

    Parameters
    ----------
    name : str
        A key of :data:`BLOCKS`.

    Returns
    -------
    numpy.dtype
        Fields named as the members (without ``u_``); itemsize a multiple of 16.
    """
    names, formats, offsets, end = [], [], [], 0
    for gl_type, member, _ in BLOCKS[name]:
        align, size = _STD140[gl_type]
        offset = -(-end // align) * align
        names.append(member)
        formats.append(_NUMPY[gl_type])
        offsets.append(offset)
        end = offset + size
    return np.dtype({"names": names, "formats": formats, "offsets": offsets, "itemsize": -(-end // 16) * 16})


def uniforms_glsl() -> str:
    """The text of ``uniforms.glsl``: every block of :data:`BLOCKS` (``layout(std140)``, members
    ``u_`` + name) and every sampler of :data:`SAMPLERS`."""
    lines = ["// Generated from treeanim/render/uniforms.py: every uniform the shaders read."]
    for name, members in BLOCKS.items():
        lines.append(f"layout(std140) uniform {name} {{")
        lines += [f"    {gl_type} u_{member};  // {doc}" for gl_type, member, doc in members]
        lines.append("};")
    lines += [f"uniform {s.type} u_{name};  // {s.doc}" for name, s in SAMPLERS.items()]
    return "\n".join(lines) + "\n"


def bind_program(program: moderngl.Program, label: str) -> None:
    """Check a linked program's uniforms against the tables, and bind them: each block to its
    binding point, each sampler to its unit.

    Parameters
    ----------
    program : moderngl.Program
    label : str
        The program's name in errors (its shader files).

    Raises
    ------
    RuntimeError
        The program has a uniform or block that is not in :data:`BLOCKS` or :data:`SAMPLERS`
        (declared by hand in a shader), or a block whose size is not the table's.
    """
    bindings = {name: k for k, name in enumerate(BLOCKS)}
    for name in program:
        member = program[name]
        if isinstance(member, moderngl.UniformBlock):
            if name not in BLOCKS:
                raise RuntimeError(f"{label}: uniform block {name} is not declared in render/uniforms.py")
            if member.size != block_dtype(name).itemsize:
                raise RuntimeError(f"{label}: uniform block {name} is {member.size} bytes, "
                                   f"render/uniforms.py lays it out in {block_dtype(name).itemsize}")
            member.binding = bindings[name]
        elif isinstance(member, moderngl.Uniform):
            sampler = SAMPLERS.get(name.removeprefix("u_")) if name.startswith("u_") else None
            if sampler is None:
                raise RuntimeError(f"{label}: uniform {name} is declared outside render/uniforms.py "
                                   "(a block's member or a sampler there)")
            member.value = sampler.unit


class UniformBlock:
    """The values of one uniform block of :data:`BLOCKS` and the buffer that takes them to the GPU.

    Parameters
    ----------
    ctx : moderngl.Context
    name : str
        A key of :data:`BLOCKS`.

    Example
    -------
    >>> ground = UniformBlock(ctx, "Ground")
    >>> ground.set(grid=0.5, trunk_radius=0.2, ...)   # every member, before the first use()
    >>> ground.use()                                   # before drawing
    """

    def __init__(self, ctx: moderngl.Context, name: str) -> None:
        if name not in BLOCKS:
            raise KeyError(f"no uniform block {name!r} in render/uniforms.py (there are {', '.join(BLOCKS)})")
        self.name = name
        self.binding = list(BLOCKS).index(name)
        self._values = np.zeros((), block_dtype(name))
        self._unset = set(self._values.dtype.names)
        self._written: bytes | None = None  # what the buffer holds
        self.buffer: moderngl.Buffer | None = ctx.buffer(reserve=self._values.nbytes)

    def set(self, **values) -> None:
        """Set members by name (without ``u_``); the GPU gets them at the next :meth:`use`.

        Raises
        ------
        KeyError
            A name the block does not declare (nothing is set then).
        """
        fields = self._values.dtype.names
        unknown = [k for k in values if k not in fields]
        if unknown:
            raise KeyError(f"uniform block {self.name} has no member {', '.join(map(repr, unknown))} "
                           f"(it has {', '.join(fields)}; see render/uniforms.py)")
        for key, value in values.items():
            self._values[key] = value
            self._unset.discard(key)

    def __getitem__(self, name: str):
        """A member's value, as set (a copy)."""
        return self._values[name].copy()

    def use(self) -> None:
        """Write the values if they changed and bind the buffer to the block's binding point, for the draws
        that follow.

        Raises
        ------
        RuntimeError
            A member was never set.
        """
        if self._unset:
            raise RuntimeError(f"uniform block {self.name}: {', '.join(sorted(self._unset))} never set")
        data = self._values.tobytes()
        if data != self._written:
            self.buffer.write(data)
            self._written = data
        self.buffer.bind_to_uniform_block(self.binding)

    def release(self) -> None:
        """Free the buffer (idempotent)."""
        if self.buffer is not None:
            self.buffer.release()
            self.buffer = None
