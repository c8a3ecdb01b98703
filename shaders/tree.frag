#version 330 core
// One part of the tree (PART: see tree.vert).

#include "tree_light.glsl"
#include "pixel.glsl"
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
in vec3 v_light;
in float v_haze;

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
    if (PART == PART_BARK && !gl_FrontFacing) discard;  // a closed tube's far side; a thin twig's, flat
    vec3 n = normalize(v_normal);
    if (!gl_FrontFacing) n = -n;                 // double-sided: laminas, blades
    vec3 V = normalize(u_camera_pos - v_world);
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
    }
    // A blade is lit at its vertices (tree.vert), and only shaded across here.
    vec3 c = PART == PART_BLADES ? v_light * (0.85 + 0.3 * (1.0 - abs(v_uv.x)))
                                 : tree_light(albedo, n, V, v_ao, sun_visibility(v_world, n), foliage, v_highlight);
    // A thin twig or blade: its true width filtered by a tent one pixel either side (pixels
    // a column apart then sum to its width, wherever it falls between them).
    float cover = PART == PART_LEAVES || v_half < 0.0 ? 1.0 : tent_integral(v_edge + v_half) - tent_integral(v_edge - v_half);
    float air = PART == PART_BLADES ? v_haze : haze(v_world);
    f_color = vec4(to_display(apply_haze(c, v_world, air)).rgb, cover);
}
