#version 330 core
// One part of the tree (PART: see tree.vert).

#include "common.glsl"
#include "constants.glsl"

in vec3 v_world;
in vec3 v_normal;
in vec3 v_albedo;
in float v_ao;
in vec2 v_uv;
flat in int v_material;
flat in float v_highlight;
noperspective in float v_edge;
in float v_half;
uniform float u_translucency;   // 0: leaves pass no sunlight through
uniform vec4 u_bark;            // furrows around a branch, furrow depth, interlacing, lenticels

out vec4 f_color;

// Bark: ridges and furrows along the branch (u_bark.x of them round it, as deep as u_bark.y,
// wandering and merging as much as u_bark.z: a poplar's interlaced diamonds), with horizontal
// lenticels (u_bark.w: a cherry's). uv = (turn round the tube in [0, 1), metres along). The
// turn jumps from 1 back to 0 on one side of the tube: of u and fract(u + 0.5), the one that
// does not jump within this pixel is used. The pattern fades out where it would be finer than
// a pixel (thin twigs stay smooth rather than shimmer).
float bark(vec2 uv) {
    float u1 = uv.x, u2 = fract(uv.x + 0.5);
    float u = fwidth(u1) <= fwidth(u2) + 1e-6 ? u1 : u2 - 0.5;
    float x = u * u_bark.x;
    float wander = vnoise(vec2(x * 0.7, uv.y * 1.6));
    x += u_bark.z * (2.0 * wander - 1.0) + 0.4 * u_bark.z * sin(uv.y * 3.1 + 2.0 * floor(x));
    float ridge = smoothstep(0.08, 0.32, abs(fract(x) - 0.5));   // 0 in a furrow, 1 on a ridge
    float detail = 1.0 - smoothstep(0.25, 0.6, fwidth(x));
    float shade = 1.0 - u_bark.y * (1.0 - ridge) * detail;
    vec2 cell = vec2(floor(u * 9.0), floor(uv.y * 28.0));        // lenticels: short dashes across
    vec2 f = vec2(fract(u * 9.0), fract(uv.y * 28.0));
    float dash = step(0.62, hash12(cell)) * (1.0 - smoothstep(0.25, 0.45, abs(f.x - 0.5)))
               * (1.0 - smoothstep(0.08, 0.2, abs(f.y - 0.5)));
    float lenticel = u_bark.w * dash * (1.0 - smoothstep(0.25, 0.6, fwidth(u * 9.0) + fwidth(uv.y * 28.0)));
    return shade * (0.9 + 0.2 * wander) * (1.0 + 0.45 * lenticel);
}

// The integral of max(1 - |t|, 0) from -infinity to x.
float tent_integral(float x) {
    return x < 0.0 ? 0.5 * max(1.0 + x, 0.0) * max(1.0 + x, 0.0) : 1.0 - 0.5 * max(1.0 - x, 0.0) * max(1.0 - x, 0.0);
}

void main() {
    if (PART == PART_BARK && v_half >= 0.0 && !gl_FrontFacing) discard;  // a thin twig, flat: its far half
    vec3 n = normalize(v_normal);
    if (!gl_FrontFacing) n = -n;                 // double-sided: laminas, blades
    vec3 V = normalize(u_camera_pos - v_world);
    float ndl = dot(n, u_sun_dir);
    bool foliage = PART != PART_BARK;
    vec3 albedo = v_albedo;
    if (PART == PART_BARK) {
        albedo *= bark(v_uv);
    } else if (PART == PART_LEAVES && v_material == LAMINA) {
        // Lamina: a lighter midrib and faint side veins; darker towards the base.
        float ax = abs(v_uv.x);
        float rib = (1.0 - smoothstep(0.008, 0.022, ax)) * step(0.02, v_uv.y) * (1.0 - smoothstep(0.85, 1.0, v_uv.y));
        float side = 1.0 - smoothstep(0.0, 0.07, abs(fract((v_uv.y - 0.9 * ax) * 7.0) - 0.5) - 0.43);
        albedo *= (0.88 + 0.16 * v_uv.y) * (1.0 + 0.45 * rib + 0.12 * side * (1.0 - rib));
    } else if (PART == PART_BLADES) {
        albedo *= 0.85 + 0.3 * (1.0 - abs(v_uv.x));
    }
    float sun = sun_visibility(v_world, n);
    vec3 c = albedo * hemisphere(n) * v_ao;
    c += albedo * u_sun_color * max(ndl, 0.0) * mix(0.55, 1.0, v_ao) * sun;
    if (foliage) {
        // Light through the leaf: its unlit face glows in the sun's colour, tinted by the leaf.
        float back = max(-ndl, 0.0) * (0.55 + 0.45 * pow(max(dot(-V, u_sun_dir), 0.0), 2.0));
        c += albedo * sqrt(albedo) * u_sun_color * 1.1 * back * v_ao * sun * u_translucency;
        c += albedo * hemisphere(n) * v_ao * 0.25;   // sky light scattered through the crown
        vec3 H = normalize(V + u_sun_dir);
        c += u_sun_color * 0.06 * pow(max(dot(n, H), 0.0), 40.0) * step(0.0, ndl) * sun;
    }
    c = mix(c, vec3(1.0, 0.45, 0.05) * 1.5, 0.55 * v_highlight);
    // A thin twig or blade: its true width filtered by a tent one pixel either side (pixels
    // a column apart then sum to its width, wherever it falls between them).
    float cover = PART == PART_LEAVES || v_half < 0.0 ? 1.0 : tent_integral(v_edge + v_half) - tent_integral(v_edge - v_half);
    f_color = vec4(to_display(apply_haze(c, v_world)).rgb, cover);
}
