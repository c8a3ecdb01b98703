"""Every uniform declared once (render/uniforms.py): a misspelt, missing or hand-declared uniform is
an error, and the blocks' layout is the one GLSL reads."""

from __future__ import annotations

import re
from importlib.resources import files

import moderngl
import numpy as np
import pytest

from treeanim.render.camera import OrbitCamera
from treeanim.render.passes import GroundPass, SkyPass
from treeanim.render.uniforms import BLOCKS, SAMPLERS, UniformBlock, bind_program, block_dtype, uniforms_glsl

W, H = 64, 48
CAMERA = OrbitCamera(target=(0.0, 1.0, 0.0), distance=6.0, elevation=10.0)


def test_a_misspelt_uniform_set_by_a_pass_stops_the_frame(offscreen, tree, monkeypatch):
    """A pass that sets a member its block does not declare (a typo) raises from draw(), naming
    the block, the name and the members it has, instead of drawing without it."""
    offscreen.resize(W, H)
    offscreen.load(tree)
    offscreen.render(CAMERA)
    applied = GroundPass.apply

    def typo(self, scene):
        applied(self, scene)
        self.block.set(gird=scene.ground_grid)

    monkeypatch.setattr(GroundPass, "apply", typo)
    r = offscreen.load(tree)
    with pytest.raises(KeyError, match=r"uniform block Ground has no member 'gird' \(it has ground_centre, .*grid"):
        offscreen.render(CAMERA)
    with pytest.raises(KeyError, match="no uniform block 'Gorund'"):
        UniformBlock(offscreen.ctx, "Gorund")
    grid = r.ground_pass.block["grid"]
    with pytest.raises(KeyError, match="'grid_strength'"):
        r.ground_pass.block.set(grid=grid + 1.0, grid_strength=1.0)
    assert r.ground_pass.block["grid"] == grid  # nothing set


def test_a_uniform_never_set_stops_the_frame(offscreen, tree, monkeypatch):
    """A pass that forgets one of its block's members cannot draw with a zero in its place."""
    offscreen.resize(W, H)
    monkeypatch.setattr(SkyPass, "apply", lambda self, scene: None)
    offscreen.load(tree)
    with pytest.raises(RuntimeError, match="uniform block Sky: clouds, show_sky never set"):
        offscreen.render(CAMERA)


def test_a_uniform_declared_outside_the_tables_fails_when_the_program_is_made(offscreen):
    """A shader's own ``uniform`` (say a misspelt copy of a block's member) is refused as the
    program is linked; a misspelt member read in GLSL does not compile."""
    frag = "#version 330 core\nout vec4 c;\nvoid main() { c = vec4(1.0); }\n"

    def vertex(body: str, extra: str = "") -> str:
        return f"#version 330 core\n{uniforms_glsl()}{extra}\nvoid main() {{ gl_Position = vec4({body}); }}\n"

    with offscreen.ctx:
        prog = offscreen.ctx.program(vertex_shader=vertex("u_grid + u_gird", "uniform float u_gird;"),
                                     fragment_shader=frag)
        try:
            with pytest.raises(RuntimeError, match="test.vert: uniform u_gird is declared outside render/uniforms.py"):
                bind_program(prog, "test.vert")
        finally:
            prog.release()
        with pytest.raises(moderngl.Error, match="u_gird"):
            offscreen.ctx.program(vertex_shader=vertex("u_gird"), fragment_shader=frag)


def test_no_shader_file_declares_a_uniform_by_hand():
    declared = re.compile(r"^\s*(layout\s*\([^)]*\)\s*)?uniform\s", re.MULTILINE)
    shaders = files("treeanim.shaders")
    found = [f.name for f in shaders.iterdir() if f.name.endswith((".vert", ".frag", ".glsl"))
             and declared.search(f.read_text(encoding="utf-8"))]
    assert not found, found


def test_the_blocks_hold_their_members_where_glsl_reads_them(offscreen):
    """Each block's std140 layout (block_dtype) matches the driver's: every member read back
    through transform feedback is the value set."""
    rng = np.random.default_rng(0)
    ctx = offscreen.ctx
    with ctx:
        # transform feedback draws too: a complete framebuffer must be bound (a fresh context's
        # own is not; the test failed when it was the first to use the session's context). The
        # one bound before is bound again after, for the tests that share the context.
        previous = ctx.fbo
        target = ctx.simple_framebuffer((1, 1))
        target.use()
        for name, members in BLOCKS.items():
            outs, body, varyings = [], [], []
            for gl_type, member, _ in members:
                if gl_type == "mat4":
                    for c in range(4):
                        outs.append(f"out vec4 o_{member}{c};")
                        body.append(f"o_{member}{c} = u_{member}[{c}];")
                        varyings.append(f"o_{member}{c}")
                else:
                    out_type = "float" if gl_type == "int" else gl_type
                    outs.append(f"out {out_type} o_{member};")
                    body.append(f"o_{member} = {out_type}(u_{member});")
                    varyings.append(f"o_{member}")
            source = f"#version 330 core\n{uniforms_glsl()}{chr(10).join(outs)}\nvoid main() {{ {' '.join(body)} }}\n"
            prog = ctx.program(vertex_shader=source, varyings=varyings)
            block = UniformBlock(ctx, name)
            vao = ctx.vertex_array(prog, [])
            out = ctx.buffer(reserve=4 * 64 * len(members))
            try:
                bind_program(prog, name)
                values = {}
                for gl_type, member, _ in members:
                    shape = block_dtype(name)[member].shape
                    v = rng.integers(-50, 50, shape) if gl_type == "int" else rng.normal(size=shape)
                    values[member] = v
                block.set(**values)
                block.use()
                vao.transform(out, vertices=1)
                got = np.frombuffer(out.read(), np.float32)
                want = np.concatenate([np.ravel(values[m]).astype(np.float32) for _, m, _ in members])
                np.testing.assert_array_equal(got[: len(want)], want, err_msg=name)
            finally:
                for o in (vao, out, block, prog):
                    o.release()
        assert ctx.error == "GL_NO_ERROR"
        if previous is not None:
            previous.use()
            target.release()


def test_every_sampler_has_its_own_unit():
    units = [s.unit for s in SAMPLERS.values()]
    assert len(set(units)) == len(units)
