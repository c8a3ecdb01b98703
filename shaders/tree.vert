#version 330 core
// Skinned tree: one part of the mesh (PART, defined by the renderer: PART_LEAVES, petioles and
// laminas; PART_BARK, branch tubes; PART_BLADES, grass blades). Each part has its own program
// with only its own code: a software rasteriser runs both sides of every branch. LOD_FADE
// (leaves and bark of a scene): 0 drawn whole; 1 the full mesh and 2 the coarse one, each
// keeping its share of the pixels of a leaf or branch in the hand-over band (tree.frag).
// Blades: 1 a clump's copies, fading out across the grass's band; 2 its simulated blade,
// widening to stand for the clump (render/lod.py).

#include "uniforms.glsl"
#include "skin.glsl"
#include "tree_light.glsl"

in ivec4 in_ids;     // node, prev, object, material
in vec3 in_offset;   // rest offset from the node
in vec3 in_normal;   // rest normal
in vec4 in_extra;    // weight of prev, per-object jitter, ambient occlusion, key
in vec2 in_uv;       // surface coordinates (see render/mesh.py)
in vec2 in_curve;    // t along the segment, 1 where it ends at the object's tip
in vec3 in_tangent0; // the rest curve's tangents at the segment's ends
in vec3 in_tangent1;

out vec3 v_world;
out vec3 v_normal;
out vec3 v_albedo;
out float v_ao;
out vec2 v_uv;
flat out int v_material;
flat out float v_highlight;
noperspective out float v_edge;  // thin twigs and blades: distance from the axis on screen, px
out float v_half;                // their true half width on screen, px (< 0: solid)
out vec3 v_light;                // blades: their light at the vertex, and ...
out float v_haze;                // ... the haze over it (see below)
flat out float v_fade;           // LOD_FADE: the node's place in the hand-over band, 0 .. 1

#include "constants.glsl"

vec3 lin(vec3 c) { return pow(c, vec3(2.2)); }


vec3 leaf_color(float jitter, float key) {
    // Summer: saturated cherry greens, each leaf a little different in hue and value.
    float j2 = fract(jitter * 13.37);
    vec3 summer = mix(lin(C_LEAF_DARK), lin(C_LEAF_LIGHT), jitter);
    summer = mix(summer, lin(C_LEAF_COOL), 0.35 * j2);
    // Autumn: leaves that fall first turn first (key = drop order, 0 first).
    float prog = smoothstep(0.05 + 0.35 * key, 0.30 + 0.45 * key, u_season);
    vec3 yellow = lin(C_LEAF_YELLOW);
    vec3 orange = lin(C_LEAF_ORANGE);
    vec3 red = lin(C_LEAF_RED);
    vec3 brown = lin(C_LEAF_BROWN);
    vec3 c = mix(summer, yellow, smoothstep(0.0, 0.35, prog));
    c = mix(c, mix(orange, red, j2), smoothstep(0.3, 0.7, prog) * (0.55 + 0.45 * jitter));
    c = mix(c, brown, 0.75 * smoothstep(0.8, 1.0, prog));
    // Winter: the leaves still on the tree are dead, dry and tan (no autumn red left).
    return mix(c, lin(C_LEAF_DRY) * (0.85 + 0.3 * j2), smoothstep(0.75, 1.0, u_season));
}

void main() {
    int obj = in_ids.z;
    vec4 state = fetch_texel(u_objects, obj);
    v_material = in_ids.w;
    v_highlight = state.g;
    v_ao = in_extra.z;
    v_uv = in_uv;
    if (state.r < 0.5) {                         // hidden: collapse beyond the far plane
        v_world = vec3(0.0);
        v_normal = vec3(0.0, 1.0, 0.0);
        v_albedo = vec3(0.0);
        gl_Position = vec4(0.0, 0.0, 2.0, 1.0);
        return;
    }
    // A scene's leaf or branch in the band where its tree hands over from the full mesh to the
    // coarse one, a blade in the grass's (render/lod.py): how far in, from its node's distance
    // (one for a whole leaf).
    vec2 band = PART == PART_BLADES ? u_blade_band : u_lod_band;
    v_fade = LOD_FADE == 0 ? 0.0 : clamp((distance(node_position(in_ids.x), u_camera_pos) - band.x)
                                         / (band.y - band.x), 0.0, 1.0);
    mat3 R;
    vec3 centre;
    skin_transform(in_ids.x, in_ids.y, in_extra.x, in_curve, in_offset, in_tangent0, in_tangent1, v_world, R, centre);
    v_normal = R * in_normal;
    v_edge = 0.0;
    v_half = -1.0;
    bool thin = false;
    if (PART != PART_LEAVES) {
        // Thinner than a few pixels, a twig or a blade would fall between pixel centres and
        // break into dots that crawl as it sways. It is drawn flat, facing the eye, a pixel
        // wider each side, and tree.frag gives each pixel the share of it the true width
        // covers (from its distance to the axis, v_edge, and the true half width, v_half): a
        // soft line whose weight per pixel column stays the same wherever it falls.
        vec3 axis = PART == PART_BLADES && in_uv.y >= 1.0                   // the segment's
                  ? node_position(in_ids.x) - node_position(in_ids.x - 1)
                  : node_position(in_ids.x + 1) - node_position(in_ids.x);
        // A blade of a clump stands off its node: its axis is its half width (in_curve.y) in
        // from the vertex, across it (render/mesh.py).
        if (PART == PART_BLADES) centre = v_world - in_uv.x * in_curve.y * normalize(cross(axis, v_normal));
        vec3 across = v_world - centre;
        float metres = length(across);
        float px = metres * u_pixels_per_metre / max((u_view_proj * vec4(centre, 1.0)).w, 1e-6);
        if (px < u_thin_pixels) {
            vec3 side = cross(axis, u_camera_pos - centre);
            float k = dot(across, side) / max(metres * length(side), 1e-30);  // -1 .. 1 across the axis
            float half_px = PART == PART_BARK ? px : abs(k) * px;            // a blade: as seen
            // a far clump's simulated blade: as wide as its clump's blades together
            if (PART == PART_BLADES && LOD_FADE == 2) half_px *= mix(1.0, CLUMP_WIDTH, v_fade);
            float edge = PART == PART_BARK ? k * (px + 1.0) : sign(k) * (half_px + 1.0);
            if (px > 0.0 && length(side) > 0.0) {
                v_world = centre + normalize(side) * (edge * metres / px);
                v_edge = edge;
            }
            v_half = px > 0.0 ? half_px : 0.0;
            thin = true;
        } else if (PART == PART_BARK) {
            // A tube's vertex: on the axis as far as coverage goes, and whole, so a band from
            // a tube's ring to a twig's flattened one is covered all along its axis (no gap).
            v_half = max(px, 1.0);
        }
    }
    gl_Position = u_view_proj * vec4(v_world, 1.0);
    if (PART == PART_BARK && thin) {
        // A faint twig writes depth like any surface, so a leaf drawn after it, behind it,
        // would be kept out and the sky show through the twig (streaks across a crown in a
        // gale). Drawn at the back of the depth range instead, it loses to every solid
        // surface, whatever the order: over sky, ground and its own wood it shows, blended;
        // among leaves it fades into them.
        gl_Position.z = DEPTH_THIN * gl_Position.w;
    }

    float jitter = in_extra.y;
    float key = in_extra.w;
    if (PART == PART_BARK) {
        v_albedo = lin(u_bark_color) * (0.92 + 0.16 * jitter);
    } else if (PART == PART_LEAVES) {
        v_albedo = leaf_color(jitter, key);
        if (v_material == PETIOLE) v_albedo = mix(v_albedo, lin(C_PETIOLE), 0.4);
    } else {
        vec3 base = lin(C_BLADE_BASE);
        vec3 tip = mix(lin(C_BLADE_TIP), lin(C_BLADE_TIP_DRY), jitter);
        vec3 c = mix(base, tip, key);
        v_albedo = mix(c, lin(C_BLADE_WINTER) * (0.6 + 0.4 * key), 0.6 * u_season);
    }
    v_light = vec3(0.0);
    v_haze = 0.0;
    if (PART == PART_BLADES) {
        // A blade is lit here, at its vertices (a few rows along it), its shadow looked up here
        // too, and the light interpolated: a blade is a pixel or two wide, and lighting each of
        // its pixels would cost a software rasteriser twice as much as all else it does for
        // them. Its edges, darker than its midrib, are shaded in tree.frag. Leaves and bark are
        // lit at each pixel.
        vec3 V = normalize(u_camera_pos - v_world);
        vec3 n = normalize(v_normal);
        if (dot(n, V) < 0.0) n = -n;             // double-sided: the face the eye sees
        v_light = tree_light(v_albedo, n, V, v_ao, sun_visibility(v_world, n), 1.0, v_highlight);
        v_haze = haze(v_world);
    }
}
