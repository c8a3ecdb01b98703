#version 330 core
// One full-screen triangle at the far plane: the background (sky and ground), drawn after
// the tree with depth test <= so that only uncovered pixels are shaded.
out vec2 v_ndc;
void main() {
    vec2 p = vec2(gl_VertexID == 1 ? 3.0 : -1.0, gl_VertexID == 2 ? 3.0 : -1.0);
    v_ndc = p;
    gl_Position = vec4(p, 1.0, 1.0);
}
