#version 330 core
// Overlay lines: world points, or points carried by a node (offset from it, skinned).

#include "uniforms.glsl"
#include "skin.glsl"

in vec3 in_position;
in vec4 in_color;
in int in_node;       // -1: in_position is a world point
out vec4 g_color;

void main() {
    vec3 p = in_position;
    if (in_node >= 0) {
        vec3 base;
        mat3 R;
        node_transform(in_node, base, R);
        p = base + R * in_position;
    }
    g_color = in_color;
    gl_Position = u_view_proj * vec4(p, 1.0);
}
