#version 330 core

#include "common.glsl"

in vec3 v_world;
uniform vec3 u_ground_centre;   // the trunk's foot
uniform float u_ground_half;
uniform float u_earth_radius;   // bare earth around the trunk (0: none)
uniform vec3 u_shadow_centre;   // where the crown's shadow falls
uniform float u_shadow_radius;
uniform float u_grid;           // 0: no grid; else grid line strength (1 m cells)
out vec4 f_color;

void main() {
    vec2 xz = v_world.xz;
    float n1 = vnoise(xz * 0.23);
    float n2 = vnoise(xz * 1.9 + 17.0);
    // Fine detail, faded out where a pixel covers more than a cell (no shimmer far away).
    float fine = vnoise(xz * 9.0 + 3.0);
    float fade = 1.0 - smoothstep(0.05, 0.2, length(fwidth(xz)) * 9.0 * 0.1);
    vec3 grass = mix(srgb_to_linear(vec3(0.25, 0.39, 0.12)), srgb_to_linear(vec3(0.33, 0.45, 0.15)), n1);
    grass *= 0.9 + 0.2 * n2;
    grass *= 1.0 + 0.18 * (fine - 0.5) * fade;
    vec3 earth = srgb_to_linear(vec3(0.36, 0.28, 0.19)) * (0.85 + 0.3 * n2);
    float r = length(xz - u_ground_centre.xz);
    float bare = 1.0 - smoothstep(0.4 * u_earth_radius, u_earth_radius, r + 0.3 * u_earth_radius * (n2 - 0.5));
    vec3 albedo = mix(grass, earth, bare * step(1e-6, u_earth_radius));

    float ds = length(xz - u_shadow_centre.xz) / max(u_shadow_radius, 1e-6);
    float shadow = 0.7 * exp(-2.2 * ds * ds) * step(1e-6, u_shadow_radius);
    vec3 light = hemisphere(vec3(0.0, 1.0, 0.0)) + u_sun_color * max(u_sun_dir.y, 0.0) * (1.0 - shadow);
    vec3 c = albedo * light * (1.0 - 0.35 * shadow);

    if (u_grid > 0.0) {
        vec2 g = abs(fract(xz - 0.5) - 0.5) / fwidth(xz);
        float line = 1.0 - min(min(g.x, g.y), 1.0);
        c = mix(c, c * 1.6 + 0.02, u_grid * line);
    }
    c = apply_haze(c, v_world);
    float edge = smoothstep(0.6, 1.0, max(abs(xz.x - u_ground_centre.x), abs(xz.y - u_ground_centre.z)) / u_ground_half);
    c = mix(c, u_sky_horizon, edge);
    f_color = to_display(c);
}
