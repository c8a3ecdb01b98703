#version 330 core
// The turf's sheen in the wind (render/turf.py): drawn over the ground already in the frame (the
// ground's colours are upright turf's), it scales each pixel by how the turf's blades, leaned by
// the simulated wind there, catch the sun. The blending (DST_COLOR, SRC_ALPHA) makes the pixel
// dst * (rgb + a): f_color holds half the gain in each, so the gain reaches from 0 to 2.

#include "common.glsl"
#include "pixel.glsl"
#include "ground.glsl"

out vec4 f_color;

// Kajiya-Kay's fibre: the sun on a blade along `t` (unit) seen along `v` (towards the eye): its
// diffuse share sin(t, sun) and a sheen round the cone of mirror directions (sin(t, h)^p,
// h the half vector). Grass blades are waxy: the sheen is a third of the light at its peak.
float fibre(vec3 t, vec3 v) {
    float tl = dot(t, u_sun_dir);
    float th = dot(t, normalize(u_sun_dir + v));
    return sqrt(max(1.0 - tl * tl, 0.0)) + 0.5 * pow(max(1.0 - th * th, 0.0), 16.0);
}

void main() {
    vec3 dir = pixel_ray();
    float t = u_camera_pos.y / max(-dir.y, 1e-5);
    vec3 world = u_camera_pos + t * dir;
    vec2 uv = (world.xz - u_turf_grid.xy) / u_turf_grid.z;
    // Texel centres: the grid's samples lie on its texels' centres, its edge fades out.
    vec2 w = texture(u_turf_wind, (0.5 + uv * (u_turf_grid.w - 1.0)) / u_turf_grid.w).rg;
    float edge = min(min(uv.x, 1.0 - uv.x), min(uv.y, 1.0 - uv.y));
    // The blades lean downwind atan((U / U45)^n), as the meadow's simulated ones (turf.py).
    float u = length(w);
    float lean = atan(pow(u / u_turf_lean.x, u_turf_lean.y));
    vec2 d = w / max(u, 1e-6);
    vec3 blade = vec3(d.x * sin(lean), cos(lean), d.y * sin(lean));
    vec3 up = vec3(0.0, 1.0, 0.0);
    vec3 v = -dir;
    float gain = fibre(blade, v) / max(fibre(up, v), 0.1);
    // Only the sun's share of the ground's light is the blades': the sky's comes from all round.
    float sun = dot(u_sun_color, vec3(0.3333)) * max(u_sun_dir.y, 0.0) * sun_visibility(world, up);
    float sky = dot(hemisphere(up), vec3(0.3333));
    gain = mix(1.0, gain, sun / max(sun + sky, 1e-6));
    // Bare soil has no blades; the grid's edge and the haze fade the sheen out.
    float broad;
    vec4 fine, wide;
    ground_maps(world.xz, length(fwidth(world.xz)), broad, fine, wide);
    float turf = 1.0 - bare_soil(broad, fine, wide);
    gain = mix(1.0, gain, turf * smoothstep(0.0, 0.1, edge) * (1.0 - haze(world)));
    // The frame holds display values, the linear colour to the power 1 / 2.2 (pixel.glsl).
    f_color = vec4(0.5 * pow(clamp(gain, 0.0, 4.0), 1.0 / 2.2));
}
