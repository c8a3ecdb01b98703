"""Loading GLSL sources shipped as package data (``treeanim.shaders``), with ``#include``.

``#include "constants.glsl"`` is made here from the Python constants the shaders share (the
mesh's material ids, the leaves' and blades' colours), and ``#include "uniforms.glsl"`` from
the uniform tables of :mod:`treeanim.render.uniforms`, so the two sides can never drift apart.
"""

from __future__ import annotations

import re
from functools import lru_cache
from importlib.resources import files

import moderngl

from .uniforms import bind_program, uniforms_glsl

#: Where the renderer draws in the depth range (NDC z), behind every surface of the tree: twigs
#: thinner than a few pixels (they lose to every solid surface, see shaders/tree.vert), then the
#: turf in the wind over all the ground (:mod:`.turf`), the ground over the shadow's footprint, then the
#: rest of the ground (the sky: 1). Each 25 steps or more of a 24-bit depth buffer from the next,
#: far above the rounding of their interpolation.
DEPTH_THIN = 0.99999
DEPTH_TURF = 0.999992
DEPTH_FOOTPRINT = 0.999994
DEPTH_GROUND = 0.999997

_INCLUDE = re.compile(r'^\s*#include\s+"([^"]+)"\s*$', re.MULTILINE)


@lru_cache(maxsize=None)
def shader_source(name: str) -> str:
    """The text of shader file ``name`` with every ``#include "file"`` line replaced by that
    file's text (recursively; each file at most once: a second include of it is dropped)."""
    included: set[str] = set()

    def expand(fname: str, seen: tuple[str, ...]) -> str:
        if fname in seen:
            raise ValueError(f"shader include cycle: {' -> '.join(seen + (fname,))}")
        if fname in included:
            return ""
        included.add(fname)
        if fname in _GENERATED:
            return _GENERATED[fname]()
        text = files("treeanim.shaders").joinpath(fname).read_text(encoding="utf-8")
        return _INCLUDE.sub(lambda m: expand(m.group(1), seen + (fname,)), text)

    return expand(name, ())


def constants_glsl() -> str:
    """GLSL constants generated from Python: the materials and parts of
    :mod:`treeanim.render.mesh` (``PART_`` + name, numbered in order), ``DEPTH_THIN``,
    ``CLUMP_WIDTH`` (:mod:`treeanim.render.lod`), ``LEAF_ALBEDO_SCALE``
    (:mod:`treeanim.render.leaf_maps`) and the colours of :mod:`treeanim.render.palette` (sRGB,
    as ``C_`` + name)."""
    from . import leaf_maps, lod, mesh, palette

    names = ("BARK", "PETIOLE", "LAMINA", "BLADE")
    lines = [f"const int {n} = {getattr(mesh, 'MATERIAL_' + n)};" for n in names]
    lines += [f"const int PART_{n} = {i};" for i, n in enumerate(mesh.PARTS)]
    lines.append(f"const float DEPTH_THIN = {DEPTH_THIN!r};")
    lines.append(f"const float CLUMP_WIDTH = {lod.CLUMP_WIDTH!r};")
    lines.append(f"const float LEAF_ALBEDO_SCALE = {leaf_maps.ALBEDO_SCALE!r};")
    lines += [f"const vec3 C_{n} = vec3({r!r}, {g!r}, {b!r});" for n, (r, g, b) in palette.COLOURS.items()]
    return "\n".join(lines) + "\n"


#: Includes written from Python: name → the function that writes the text.
_GENERATED = {"constants.glsl": constants_glsl, "uniforms.glsl": uniforms_glsl}


def with_defines(source: str, defines: dict | None) -> str:
    """A shader's variant: ``source`` with a ``#define NAME value`` line for each item of
    ``defines`` after its ``#version`` line (conditions on them fold away when compiled).

    Parameters
    ----------
    source : str
        GLSL, its first line ``#version ...`` (else the defines go first).
    defines : dict or None
        Name: value (written with ``str``).

    Returns
    -------
    str
    """
    if not defines:
        return source
    head, sep, rest = source.partition("\n")
    if not head.startswith("#version"):
        head, sep, rest = "", "", source
    lines = "".join(f"#define {k} {v}\n" for k, v in defines.items())
    return head + sep + lines + rest


def load_program(ctx: moderngl.Context, vertex: str, fragment: str, geometry: str | None = None,
                 defines: dict | None = None) -> moderngl.Program:
    """Compile and link a program from shader file names (e.g. ``"tree.vert"``), with
    ``defines`` (name: value) set in every stage, its uniforms checked and bound
    (:func:`~treeanim.render.uniforms.bind_program`).

    Raises
    ------
    RuntimeError
        The program does not build, or declares a uniform outside ``uniforms.glsl``.
    """
    label = " + ".join(n for n in (vertex, geometry, fragment) if n)
    if defines:
        label += " (" + ", ".join(f"{k}={v}" for k, v in defines.items()) + ")"
    try:
        prog = ctx.program(
            vertex_shader=with_defines(shader_source(vertex), defines),
            fragment_shader=with_defines(shader_source(fragment), defines),
            geometry_shader=with_defines(shader_source(geometry), defines) if geometry else None,
        )
    except moderngl.Error as exc:
        raise RuntimeError(f"shader program {vertex} + {fragment} failed to build: {exc}") from exc
    try:
        bind_program(prog, label)
    except BaseException:
        prog.release()
        raise
    return prog
