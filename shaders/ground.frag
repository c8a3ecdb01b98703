#version 330 core
// The ground plane y = 0 found by casting each pixel's view ray: grass at several scales with
// patches of dry grass and soil, the sky the crown hides and a contact shadow at the trunk's
// foot, an optional 1 m grid, hazed into the air's colour towards the horizon. With SUN_SHADOW 1
// (the program the renderer draws over the shadow's footprint only) also the tree's shadow from
// the sun's shadow map.

#include "common.glsl"
#include "pixel.glsl"
#include "fbm.glsl"

out vec4 f_color;

// The ground's colour at xz (linear), `px` a pixel's size there (metres): grass greener or
// yellower in patches tens of metres across, clumps a metre or two across, tufts of a few
// centimetres; dry grass and small patches of soil where the clumps' noise runs high. Detail
// finer than a pixel fades to its mean (fbm).
vec3 ground_albedo(vec2 xz, float px) {
    float broad = fbm(xz * 0.04, px * 0.04, 3, 0.5);
    float clump = fbm(xz * 0.45 + 7.0, px * 0.45, 4, 0.65);
    float tuft = fbm(xz * 6.0 + 3.0, px * 6.0, 5, 0.8);
    vec3 grass = mix(srgb_to_linear(vec3(0.22, 0.36, 0.10)), srgb_to_linear(vec3(0.36, 0.47, 0.14)),
                     smoothstep(0.3, 0.7, broad));
    vec3 dry = srgb_to_linear(vec3(0.58, 0.54, 0.32));
    grass = mix(grass, dry, 0.5 * smoothstep(0.47, 0.7, 0.5 * clump + 0.5 * broad + 0.2 * (tuft - 0.5)));
    grass *= (1.0 + 2.0 * (tuft - 0.5)) * (0.7 + 0.6 * clump);
    vec3 soil = srgb_to_linear(vec3(0.35, 0.30, 0.23)) * (0.8 + 0.4 * tuft);
    return mix(grass, soil, 0.7 * smoothstep(0.69, 0.79, clump + 0.3 * (tuft - 0.5)));
}

vec3 ground_color(vec2 xz, float px) {
    vec3 up = vec3(0.0, 1.0, 0.0);
#if SUN_SHADOW
    float sun = sun_visibility(vec3(xz.x, 0.0, xz.y), up);
#else
    float sun = 1.0;   // off the footprint: nothing casts a shadow here
#endif
    float ds = length(xz - u_occlusion_centre.xz) / max(u_occlusion_radius, 1e-6);
    float sky = 1.0 - 0.45 * exp(-2.0 * ds * ds) * step(1e-6, u_occlusion_radius);
    float dt = max(length(xz - u_ground_centre.xz) - u_trunk_radius, 0.0) / max(1.5 * u_trunk_radius, 1e-6);
    float contact = 1.0 - 0.6 * exp(-dt * dt) * step(1e-6, u_trunk_radius);
    vec3 light = hemisphere(up) * sky + u_sun_color * max(u_sun_dir.y, 0.0) * sun;
    return ground_albedo(xz, px) * light * contact;
}

void main() {
    vec3 dir = pixel_ray();
    float t = u_camera_pos.y / max(-dir.y, 1e-5);
    vec2 xz = u_camera_pos.xz + min(t, 1e5) * dir.xz;
    vec2 fw = fwidth(xz);
    vec3 c = ground_color(xz, length(fw));
    if (u_grid > 0.0) {
        float fade = 1.0 - smoothstep(0.05, 0.2, length(fw) * 0.9);   // no shimmer far away
        vec2 g = abs(fract(xz - 0.5) - 0.5) / max(fw, vec2(1e-6));
        float line = (1.0 - min(min(g.x, g.y), 1.0)) * fade;
        c = mix(c, c * 1.6 + 0.02, u_grid * line);
    }
    vec3 world = vec3(xz.x, 0.0, xz.y);
    f_color = to_display(apply_haze(c, world, haze(world)));
}
