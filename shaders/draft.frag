#version 330 core
// Draft mode (app/draft.py): the scene drawn smaller, scaled up onto the window (bilinear).

#include "uniforms.glsl"

in vec2 v_uv;
out vec4 f_color;

void main() {
    f_color = texture(u_draft, v_uv);
}
