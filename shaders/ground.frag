#version 330 core
// The ground plane y = 0 found by casting each pixel's view ray: grass at several scales with
// patches of dry grass and soil, the sky the crown hides and a contact shadow at the trunk's
// foot, an optional 1 m grid, hazed into the air's colour towards the horizon. With SUN_SHADOW 1
// (the program the renderer draws over the shadow's footprint only) also the tree's shadow from
// the sun's shadow map.

#include "common.glsl"
#include "pixel.glsl"
#include "ground.glsl"

out vec4 f_color;

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
    return ground_albedo(xz, px).rgb * light * contact;
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
