#version 330 core
// A square of ground at y = 0, centred under the tree.
in vec2 in_xz;            // corners in [-1, 1]
uniform mat4 u_view_proj;
uniform vec3 u_ground_centre;
uniform float u_ground_half;
out vec3 v_world;
void main() {
    v_world = vec3(u_ground_centre.x + in_xz.x * u_ground_half, 0.0,
                   u_ground_centre.z + in_xz.y * u_ground_half);
    gl_Position = u_view_proj * vec4(v_world, 1.0);
}
