// The sun and its shadow map: how much of the sun reaches a point (any shader stage).

#include "uniforms.glsl"

// Where `world` (normal `n`) falls in the shadow map: pushed off the surface towards the sun's
// side by a texel and a half, so a surface never shadows itself (acne) and a leaf lit from
// behind is looked up on its lit face.
vec3 shadow_coord(vec3 world, vec3 n) {
    vec3 towards = dot(n, u_sun_dir) < 0.0 ? -n : n;
    vec4 p = u_light_view_proj * vec4(world + 1.5 * u_shadow_texel * towards + 0.5 * u_shadow_texel * u_sun_dir, 1.0);
    return p.xyz / p.w * 0.5 + 0.5;
}

// The share of the sun at s (shadow_coord) from the map's lookups there, `lit`: all of it with
// shadows off or beyond the map's depth; a map fitted to the view (u_shadow_edge > 0) leaves
// trees beyond it lit, faded in.
float sun_at(vec3 s, float lit) {
    vec2 border = abs(2.0 * s.xy - 1.0);
    float beyond = clamp((max(border.x, border.y) - 1.0 + u_shadow_edge) / max(u_shadow_edge, 1e-6), 0.0, 1.0);
    return u_shadow_on == 0 || s.z >= 1.0 ? 1.0 : mix(lit, 1.0, beyond);
}

// How much of the sun reaches a surface (0 shadowed .. 1 lit): percentage-closer filtering,
// four bilinear taps a texel apart (a soft edge about three texels wide). A software rasteriser
// runs every branch, so there is no early exit for pixels off the map or with shadows off.
float sun_visibility(vec3 world, vec3 n) {
    vec3 s = shadow_coord(world, n);
    vec2 d = 0.5 / vec2(textureSize(u_shadow_map, 0));
    float lit = 0.25 * (texture(u_shadow_map, vec3(s.x - d.x, s.y - d.y, s.z)) + texture(u_shadow_map, vec3(s.x + d.x, s.y - d.y, s.z))
                      + texture(u_shadow_map, vec3(s.x - d.x, s.y + d.y, s.z)) + texture(u_shadow_map, vec3(s.x + d.x, s.y + d.y, s.z)));
    return sun_at(s, lit);
}

// The same from one bilinear tap (2 x 2 texels compared and blended: an edge a texel wide), for
// leaves: they fill most of a crown's pixels, several deep, and a leaf's shadow edge is small;
// a quarter of the lookups cost llvmpipe 7 % of the small cherry's frame.
float sun_visibility_tap(vec3 world, vec3 n) {
    vec3 s = shadow_coord(world, n);
    return sun_at(s, texture(u_shadow_map, s));
}
