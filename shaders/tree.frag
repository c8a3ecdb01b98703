#version 330 core

#include "common.glsl"

in vec3 v_world;
in vec3 v_normal;
in vec3 v_albedo;
in float v_ao;
in vec2 v_uv;
flat in int v_material;
flat in float v_highlight;
uniform float u_translucency;   // 0: leaves pass no sunlight through

out vec4 f_color;

void main() {
    vec3 n = normalize(v_normal);
    if (!gl_FrontFacing) n = -n;                 // double-sided: laminas, blades
    vec3 V = normalize(u_camera_pos - v_world);
    float ndl = dot(n, u_sun_dir);
    bool foliage = v_material != 0;
    vec3 albedo = v_albedo;
    if (v_material == 0) {
        // Bark: streaks along the branch.
        float n1 = vnoise(vec2(v_uv.x * 9.0, v_uv.y * 5.0));
        float n2 = vnoise(vec2(v_uv.x * 23.0 + 7.0, v_uv.y * 19.0));
        albedo *= 0.78 + 0.3 * n1 + 0.14 * n2;
    } else if (v_material == 2) {
        // Lamina: a lighter midrib and faint side veins; darker towards the base.
        float ax = abs(v_uv.x);
        float rib = (1.0 - smoothstep(0.008, 0.022, ax)) * step(0.02, v_uv.y) * (1.0 - smoothstep(0.85, 1.0, v_uv.y));
        float side = 1.0 - smoothstep(0.0, 0.07, abs(fract((v_uv.y - 0.9 * ax) * 7.0) - 0.5) - 0.43);
        albedo *= (0.88 + 0.16 * v_uv.y) * (1.0 + 0.45 * rib + 0.12 * side * (1.0 - rib));
    } else if (v_material == 3) {
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
    f_color = to_display(apply_haze(c, v_world));
}
