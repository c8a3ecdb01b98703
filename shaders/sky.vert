#version 330 core
// One full-screen triangle at the far plane: the sky into the background cache, and the copy
// of the cache each frame, with depth test <=: only where nothing was drawn.
void main() {
    vec2 p = vec2(gl_VertexID == 1 ? 3.0 : -1.0, gl_VertexID == 2 ? 3.0 : -1.0);
    gl_Position = vec4(p, 1.0, 1.0);
}
