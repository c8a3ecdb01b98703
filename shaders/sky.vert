#version 330 core
// One full-screen triangle at the far plane: the sky, drawn after the ground and the tree's
// leaves with depth test <=, so that only the pixels they left uncovered are shaded.
void main() {
    vec2 p = vec2(gl_VertexID == 1 ? 3.0 : -1.0, gl_VertexID == 2 ? 3.0 : -1.0);
    gl_Position = vec4(p, 1.0, 1.0);
}
