#version 330 core
// The turf in the wind (render/turf.py): drawn over the ground already in the frame (the
// ground's colours are upright turf's), it scales each pixel by how the turf's blades, leaned by
// the simulated wind there, catch the sun. The blending (DST_COLOR, SRC_ALPHA) makes the pixel
// dst * (rgb + a): a grey gain g from 0 to 2 as rgb = min(g, 1), a = max(g - 1, 0).

#include "common.glsl"
#include "pixel.glsl"
#include "ground.glsl"

out vec4 f_color;

// Kajiya-Kay's fibre, its diffuse part: the sun on a blade along `t` (unit), sin(t, sun). The
// ground (ground.frag) is lit as diffuse turf, no sheen, so a leaned blade's light is that of an
// upright one times the ratio of their diffuse parts, the same in every channel: a gust shades
// the grass lighter or darker, never another hue. (A white waxy sheen on the blades, 0.06 of a
// Kajiya-Kay lobe, tinted the gale's turf pale cyan, a colour no still ground shows.)
float fibre(vec3 t) {
    float tl = dot(t, u_sun_dir);
    return sqrt(max(1.0 - tl * tl, 0.0));
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
    vec4 ground = ground_albedo(world.xz, length(fwidth(world.xz)));
    float gain = fibre(blade) / max(fibre(up), 1e-4);
    // Only the sun's share of the ground's light is the blades': the sky's comes from all round.
    float sun = dot(u_sun_color, vec3(0.3333)) * max(u_sun_dir.y, 0.0) * sun_visibility(world, up);
    float sky = dot(hemisphere(up), vec3(0.3333));
    // Bare soil has no blades; the grid's edge and the haze fade the turf's gain out.
    float turf = (1.0 - ground.a) * smoothstep(0.0, 0.3, edge) * (1.0 - haze(world));
    gain = mix(1.0, gain, turf * sun / max(sun + sky, 1e-6));
    // The frame holds display values, the linear colour to the power 1 / 2.2 (pixel.glsl).
    float g = pow(clamp(gain, 0.0, 4.0), 1.0 / 2.2);
    float over = clamp(g - 1.0, 0.0, g);
    f_color = vec4(vec3(g - over), over);
}
