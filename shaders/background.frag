#version 330 core
// The background (sky and the ground without shadows) copied from the renderer's cache: drawn
// there, pixel for pixel, by sky.frag and ground.frag when the camera or the scene changed.

#include "uniforms.glsl"

out vec4 f_color;

void main() {
    f_color = texelFetch(u_background, ivec2(gl_FragCoord.xy), 0);
}
