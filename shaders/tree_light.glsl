// The light a tree's surface sends to the eye (linear, before haze), for tree.frag (at each
// pixel) and tree.vert (at a blade's vertices): sky and sun, and on foliage (`through` > 0: the
// share of light it lets through) the sun through the lamina (its unlit face glows yellow-green,
// light filtered by the leaf: green and yellow pass, blue is absorbed), sky light scattered
// through the crown and a glint. `n` faces the eye, `V` points to it; `sun` is the share of the
// sun that reaches the point (sun_visibility); `highlight` 1 marks the grabbed object.

#include "common.glsl"
#include "constants.glsl"

vec3 tree_light(vec3 albedo, vec3 n, vec3 V, float ao, float sun, float through, float highlight) {
    float ndl = dot(n, u_sun_dir);
    vec3 c = albedo * hemisphere(n) * ao;
    c += albedo * u_sun_color * max(ndl, 0.0) * mix(0.55, 1.0, ao) * sun;
    if (through > 0.0) {
        float back = max(-ndl, 0.0) * (0.55 + 0.45 * pow(max(dot(-V, u_sun_dir), 0.0), 2.0)) * sun * u_translucency;
        if (back > 0.0) c += pow(albedo, vec3(0.8)) * vec3(1.2, 1.0, 0.4) * u_sun_color * through * back * mix(0.5, 1.0, ao);
        c += albedo * hemisphere(n) * ao * 0.25;
        vec3 H = normalize(V + u_sun_dir);
        c += u_sun_color * 0.06 * pow(max(dot(n, H), 0.0), 40.0) * step(0.0, ndl) * sun;
    }
    return mix(c, C_HIGHLIGHT * 1.5, 0.55 * highlight);
}
