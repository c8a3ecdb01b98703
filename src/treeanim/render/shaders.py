"""Loading GLSL sources shipped as package data (``treeanim.shaders``), with ``#include``.

``#include "constants.glsl"`` is made here from the Python constants the shaders share (the
mesh's material ids, the leaves' and blades' colours), so the two can never drift apart.
"""

from __future__ import annotations

import re
from functools import lru_cache
from importlib.resources import files

import moderngl

_INCLUDE = re.compile(r'^\s*#include\s+"([^"]+)"\s*$', re.MULTILINE)


@lru_cache(maxsize=None)
def shader_source(name: str) -> str:
    """The text of shader file ``name`` with every ``#include "file"`` line replaced by that
    file's text (recursively; each file at most once)."""

    def expand(fname: str, seen: tuple[str, ...]) -> str:
        if fname in seen:
            raise ValueError(f"shader include cycle: {' -> '.join(seen + (fname,))}")
        if fname == "constants.glsl":
            return constants_glsl()
        text = files("treeanim.shaders").joinpath(fname).read_text(encoding="utf-8")
        return _INCLUDE.sub(lambda m: expand(m.group(1), seen + (fname,)), text)

    return expand(name, ())


def constants_glsl() -> str:
    """GLSL constants generated from Python: the materials of :mod:`treeanim.render.mesh` and
    the colours of :mod:`treeanim.render.palette` (sRGB, as ``C_`` + name)."""
    from . import mesh, palette

    names = ("BARK", "PETIOLE", "LAMINA", "BLADE")
    lines = [f"const int {n} = {getattr(mesh, 'MATERIAL_' + n)};" for n in names]
    lines += [f"const vec3 C_{n} = vec3({r!r}, {g!r}, {b!r});" for n, (r, g, b) in palette.COLOURS.items()]
    return "\n".join(lines) + "\n"


def load_program(ctx: moderngl.Context, vertex: str, fragment: str, geometry: str | None = None) -> moderngl.Program:
    """Compile and link a program from shader file names (e.g. ``"tree.vert"``)."""
    try:
        return ctx.program(
            vertex_shader=shader_source(vertex),
            fragment_shader=shader_source(fragment),
            geometry_shader=shader_source(geometry) if geometry else None,
        )
    except moderngl.Error as exc:
        raise RuntimeError(f"shader program {vertex} + {fragment} failed to build: {exc}") from exc
