#version 330 core
// The ground's polygons, in clip space already (render/renderer.py cuts them in front of the
// eye and sets their depth: behind every surface of the tree, in front of the sky).

in vec4 in_clip;

void main() {
    gl_Position = in_clip;
}
