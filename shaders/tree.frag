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
flat in float v_fade;

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

// The normal `n` tilted by a normal map's (x, y) in the surface's uv frame, the frame found from
// the screen derivatives of the position and the uv (no tangents in the mesh).
vec3 relief(vec3 n, vec2 tilt) {
    vec3 dpx = dFdx(v_world), dpy = dFdy(v_world);
    vec2 dux = dFdx(v_uv), duy = dFdy(v_uv);
    vec3 px = cross(n, dpx), py = cross(dpy, n);
    vec3 T = py * dux.x + px * duy.x;
    vec3 B = py * dux.y + px * duy.y;
    float scale = inversesqrt(max(max(dot(T, T), dot(B, B)), 1e-30));
    return normalize(n + scale * (tilt.x * T + tilt.y * B));
}

// The integral of max(1 - |t|, 0) from -infinity to x.
float tent_integral(float x) {
    return x < 0.0 ? 0.5 * max(1.0 + x, 0.0) * max(1.0 + x, 0.0) : 1.0 - 0.5 * max(1.0 - x, 0.0) * max(1.0 - x, 0.0);
}

// A 4 x 4 ordered dither's threshold at a pixel, in (0, 1).
float dither4(vec2 pixel) {
    const float bayer[16] = float[16](0.0, 8.0, 2.0, 10.0, 12.0, 4.0, 14.0, 6.0, 3.0, 11.0, 1.0, 9.0, 15.0, 7.0, 13.0, 5.0);
    ivec2 i = ivec2(pixel) & 3;
    return (bayer[i.x + 4 * i.y] + 0.5) / 16.0;
}

void main() {
#if LOD_FADE != 0
    // A leaf or branch in the hand-over band: its full mesh keeps the pixels whose threshold is
    // at least its fade, its coarse mesh the others, so between them it is whole. (Blades hand
    // over by weight: below.)
    if (PART != PART_BLADES && (dither4(gl_FragCoord.xy) >= v_fade) != (LOD_FADE == 1)) discard;
#endif
    if (PART == PART_BARK && !gl_FrontFacing) discard;  // a closed tube's far side; a thin twig's, flat
    vec3 n = normalize(v_normal);
    if (!gl_FrontFacing) n = -n;                 // double-sided: laminas, blades
    vec3 V = normalize(u_camera_pos - v_world);
    float through = PART == PART_BARK ? 0.0 : 1.0;  // the share of the sun the surface lets through
    vec3 albedo = v_albedo;
    if (PART == PART_BARK) {
        albedo *= bark(v_uv);
    } else if (PART == PART_LEAVES && v_material == LAMINA) {
        // The species' leaf maps (render/leaf_maps.py): veins, translucency, relief. The
        // lower face is paler and greyer than the upper.
        vec4 m = texture(u_leaf_maps, vec2(0.5 + 0.5 * v_uv.x / u_lamina_box.x, v_uv.y / u_lamina_box.y));
        albedo *= m.r * LEAF_ALBEDO_SCALE;
        if (!gl_FrontFacing) albedo = 1.6 * mix(albedo, vec3(dot(albedo, vec3(0.2126, 0.7152, 0.0722))), 0.25);
        through = m.g;
        n = relief(n, 2.0 * m.ba - 1.0);
    }
    // A blade is lit at its vertices (tree.vert), and only shaded across here.
    float sun = PART == PART_LEAVES ? sun_visibility_tap(v_world, n) : sun_visibility(v_world, n);
    vec3 c = PART == PART_BLADES ? v_light * (0.85 + 0.3 * (1.0 - abs(v_uv.x)))
                                 : tree_light(albedo, n, V, v_ao, sun, through, v_highlight);
    // A thin twig or blade: its true width filtered by a tent one pixel either side (pixels
    // a column apart then sum to its width, wherever it falls between them).
    float cover = PART == PART_LEAVES || v_half < 0.0 ? 1.0 : tent_integral(v_edge + v_half) - tent_integral(v_edge - v_half);
    // A far clump's copies fade out as its simulated blade widens (tree.vert).
    if (PART == PART_BLADES && LOD_FADE == 1) {
        cover *= 1.0 - v_fade;
        if (cover <= 0.0) discard;
    }
    float air = PART == PART_BLADES ? v_haze : haze(v_world);
    f_color = vec4(to_display(apply_haze(c, v_world, air)).rgb, cover);
}
