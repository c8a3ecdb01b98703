// The ground's albedo and where it is bare soil (ground.frag, turf.frag): include after
// common.glsl.

#include "fbm.glsl"

// The ground maps (ground_maps.py) repeat every TILE_FINE metres and, turned and shifted so the
// two never line up, every TILE_WIDE: mipmapped, so their detail fades to its mean where a
// pixel spans more ground than it.
const float TILE_FINE = 2.5, TILE_WIDE = 13.0;
const mat2 TILE_TURN = mat2(0.8, 0.6, -0.6, 0.8);

// The ground's colour at xz (linear, rgb), `px` a pixel's size there (metres): grass greener or
// yellower in patches tens of metres across (fbm), clumps a metre or so across and tufts of a
// few centimetres (the maps), with dry tints; and here and there bare, dry soil, crumbly and
// pebbled, its edge ragged with grass tufts reaching into it; how bare it is (a: 0 grass .. 1
// soil). Far away, where the maps fade to their means, it is grass of the mean colour (the
// soil's patches fade out).
vec4 ground_albedo(vec2 xz, float px) {
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
    bare = smoothstep(0.72, 0.9, bare);
    return vec4(mix(grass, soil, bare), bare);
}
