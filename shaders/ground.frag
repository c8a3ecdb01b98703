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

// The ground maps (ground_maps.py) repeat every TILE_FINE metres and, turned and shifted so the
// two never line up, every TILE_WIDE: mipmapped, so their detail fades to its mean where a
// pixel spans more ground than it.
const float TILE_FINE = 2.5, TILE_WIDE = 13.0;
const mat2 TILE_TURN = mat2(0.8, 0.6, -0.6, 0.8);

// The ground's colour at xz (linear), `px` a pixel's size there (metres): grass greener or
// yellower in patches tens of metres across (fbm), clumps a metre or so across and tufts of a
// few centimetres (the maps), with dry tints; and here and there bare, dry soil, crumbly and
// pebbled, its edge ragged with grass tufts reaching into it. Far away, where the maps fade
// to their means, it is grass of the mean colour (the soil's patches fade out).
vec3 ground_albedo(vec2 xz, float px) {
    float broad = fbm(xz * 0.04, px * 0.04, 2, 0.5);
    vec4 fine = texture(u_ground_maps, xz / TILE_FINE);
    vec4 wide = texture(u_ground_maps, TILE_TURN * xz / TILE_WIDE + 0.37);
    vec3 grass = mix(srgb_to_linear(vec3(0.24, 0.38, 0.11)), srgb_to_linear(vec3(0.36, 0.47, 0.15)),
                     smoothstep(0.3, 0.7, broad));
    vec3 dry = srgb_to_linear(vec3(0.56, 0.53, 0.30));
    grass = mix(grass, dry, 0.5 * smoothstep(0.5, 0.8, 0.4 * wide.a + 0.6 * broad + 0.4 * (fine.a - 0.5)));
    grass *= (1.0 + 1.2 * (fine.r - 0.5)) * (1.0 + 0.8 * (wide.r - 0.5));
    vec3 soil = mix(srgb_to_linear(vec3(0.36, 0.31, 0.24)), srgb_to_linear(vec3(0.52, 0.46, 0.35)), fine.b);
    soil *= 0.85 + 0.3 * fine.g;
    float bare = wide.g + 0.6 * (broad - 0.5) + 0.3 * (fine.g - 0.5) - 0.35 * (fine.r - 0.5);
    return mix(grass, soil, smoothstep(0.72, 0.9, bare));
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
