#version 330 core
// Depth only: the shadow map keeps the nearest surface to the sun.

void main() {
}
