// Shared lighting (any shader stage): one sun with its shadow map (sun.glsl), a sky/ground
// hemisphere, distance haze and the air's colour, noise. Fragment shaders' own helpers are in
// pixel.glsl. Every uniform is declared in uniforms.glsl, written from render/uniforms.py.

#include "uniforms.glsl"
#include "sun.glsl"

vec3 srgb_to_linear(vec3 c) { return pow(c, vec3(2.2)); }

vec3 hemisphere(vec3 n) {
    vec3 sky = mix(u_sky_horizon, u_sky_zenith, 0.5);
    return u_ambient * mix(u_ground_bounce, sky, 0.5 + 0.5 * n.y);
}

// The colour of the air seen towards `dir` (unit, world): the sky's horizon colour, brighter and
// warmer towards the sun (the haze scatters sunlight forwards). The sky meets it at the horizon
// and haze lays it over whatever is far, so sky, ground and trees fade into one colour.
vec3 air_color(vec3 dir) {
    float s = max(dot(dir, u_sun_dir), 0.0);
    return u_sky_horizon + u_sun_color * (0.05 * s * s + 0.12 * pow(s, 8.0));
}

// How much of the air's colour the air between the eye and `world` lays over it (0 .. 1).
float haze(vec3 world) {
    return 1.0 - exp(-length(world - u_camera_pos) / u_haze_distance);
}

// `c` at `world` as the eye sees it through the air: faded by `air` (haze(world)) into the air's colour.
vec3 apply_haze(vec3 c, vec3 world, float air) {
    return mix(c, air_color(normalize(world - u_camera_pos)), air);
}

float hash12(vec2 p) {
    vec3 p3 = fract(vec3(p.xyx) * 0.1031);
    p3 += dot(p3, p3.yzx + 33.33);
    return fract((p3.x + p3.y) * p3.z);
}

float vnoise(vec2 p) {
    vec2 i = floor(p);
    vec2 f = fract(p);
    f = f * f * (3.0 - 2.0 * f);
    float a = hash12(i), b = hash12(i + vec2(1.0, 0.0));
    float c = hash12(i + vec2(0.0, 1.0)), d = hash12(i + vec2(1.0, 1.0));
    return mix(mix(a, b, f.x), mix(c, d, f.x), f.y);
}
