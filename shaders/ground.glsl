// The ground's albedo (ground.frag) and where it is bare soil (turf.frag): include after
// common.glsl.

#include "fbm.glsl"

// The ground maps (ground_maps.py) repeat every TILE_FINE metres and, turned and shifted so the
// two never line up, every TILE_WIDE: mipmapped, so their detail fades to its mean where a
// pixel spans more ground than it.
const float TILE_FINE = 2.5, TILE_WIDE = 13.0;
const mat2 TILE_TURN = mat2(0.8, 0.6, -0.6, 0.8);

// What the ground's colours are made of at xz, `px` a pixel's size there (metres): patches tens
// of metres across (fbm, `broad`) and the maps at their two scales.
void ground_maps(vec2 xz, float px, out float broad, out vec4 fine, out vec4 wide) {
    broad = fbm(xz * 0.04, px * 0.04, 2, 0.5);
    fine = texture(u_ground_maps, xz / TILE_FINE);
    wide = texture(u_ground_maps, TILE_TURN * xz / TILE_WIDE + 0.37);
}

// How bare the ground is (0 turf .. 1 soil), from its maps (ground_maps).
float bare_soil(float broad, vec4 fine, vec4 wide) {
    float bare = wide.g + 0.6 * (broad - 0.5) + 0.3 * (fine.g - 0.5) - 0.35 * (fine.r - 0.5);
    return smoothstep(0.72, 0.9, bare);
}


// The ground's colour at xz (linear), `px` a pixel's size there (metres): grass greener or
// yellower in patches tens of metres across (fbm), clumps a metre or so across and tufts of a
// few centimetres (the maps), with dry tints; and here and there bare, dry soil, crumbly and
// pebbled, its edge ragged with grass tufts reaching into it. Far away, where the maps fade
// to their means, it is grass of the mean colour (the soil's patches fade out).
vec3 ground_albedo(vec2 xz, float px) {
    float broad;
    vec4 fine, wide;
    ground_maps(xz, px, broad, fine, wide);
    vec3 grass = mix(srgb_to_linear(vec3(0.24, 0.38, 0.11)), srgb_to_linear(vec3(0.36, 0.47, 0.15)),
                     smoothstep(0.3, 0.7, broad));
    vec3 dry = srgb_to_linear(vec3(0.56, 0.53, 0.30));
    grass = mix(grass, dry, 0.5 * smoothstep(0.5, 0.8, 0.4 * wide.a + 0.6 * broad + 0.4 * (fine.a - 0.5)));
    grass *= (1.0 + 1.2 * (fine.r - 0.5)) * (1.0 + 0.8 * (wide.r - 0.5));
    vec3 soil = mix(srgb_to_linear(vec3(0.36, 0.31, 0.24)), srgb_to_linear(vec3(0.52, 0.46, 0.35)), fine.b);
    soil *= 0.85 + 0.3 * fine.g;
    return mix(grass, soil, bare_soil(broad, fine, wide));
}

