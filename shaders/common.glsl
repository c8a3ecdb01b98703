// Shared lighting: one sun with its shadow map, a sky/ground hemisphere, distance haze, sRGB
// output.

uniform vec3 u_sun_dir;        // unit, towards the sun
uniform vec3 u_sun_color;      // linear
uniform vec3 u_sky_zenith;     // linear
uniform vec3 u_sky_horizon;    // linear (also the haze colour)
uniform vec3 u_ground_bounce;  // linear, light from below
uniform float u_ambient;       // strength of the sky/ground hemisphere light
uniform vec3 u_camera_pos;
uniform float u_haze_distance; // metres at which haze reaches 63 %
uniform float u_exposure;
uniform sampler2DShadow u_shadow_map;  // depth seen from the sun (render/shadow.py)
uniform mat4 u_light_view_proj;        // world -> the shadow map's clip space
uniform int u_shadow_on;               // 0: everything in sunlight
uniform float u_shadow_texel;          // one shadow-map texel, metres
uniform mat4 u_inv_view_proj;          // clip -> world (sky and ground)
uniform vec2 u_viewport;               // pixels

// The view ray through this pixel's centre (unit, world; fragment shaders).
vec3 pixel_ray() {
    vec4 far = u_inv_view_proj * vec4(gl_FragCoord.xy / u_viewport * 2.0 - 1.0, 1.0, 1.0);
    return normalize(far.xyz / far.w - u_camera_pos);
}

vec3 srgb_to_linear(vec3 c) { return pow(c, vec3(2.2)); }

vec3 hemisphere(vec3 n) {
    vec3 sky = mix(u_sky_horizon, u_sky_zenith, 0.5);
    return u_ambient * mix(u_ground_bounce, sky, 0.5 + 0.5 * n.y);
}

vec3 apply_haze(vec3 c, vec3 world) {
    float d = length(world - u_camera_pos);
    float f = 1.0 - exp(-d / u_haze_distance);
    return mix(c, u_sky_horizon, f);
}

// Where `world` (normal `n`) falls in the shadow map: pushed off the surface towards the sun's
// side by a texel and a half, so a surface never shadows itself (acne) and a leaf lit from
// behind is looked up on its lit face.
vec3 shadow_coord(vec3 world, vec3 n) {
    vec3 towards = dot(n, u_sun_dir) < 0.0 ? -n : n;
    vec4 p = u_light_view_proj * vec4(world + 1.5 * u_shadow_texel * towards + 0.5 * u_shadow_texel * u_sun_dir, 1.0);
    return p.xyz / p.w * 0.5 + 0.5;
}

// How much of the sun reaches a surface (0 shadowed .. 1 lit): percentage-closer filtering,
// four bilinear taps a texel apart (a soft edge about three texels wide). A software rasteriser
// runs every branch, so there is no early exit for pixels off the map or with shadows off.
float sun_visibility(vec3 world, vec3 n) {
    vec3 s = shadow_coord(world, n);
    vec2 d = 0.5 / vec2(textureSize(u_shadow_map, 0));
    float lit = 0.25 * (texture(u_shadow_map, vec3(s.x - d.x, s.y - d.y, s.z)) + texture(u_shadow_map, vec3(s.x + d.x, s.y - d.y, s.z))
                      + texture(u_shadow_map, vec3(s.x - d.x, s.y + d.y, s.z)) + texture(u_shadow_map, vec3(s.x + d.x, s.y + d.y, s.z)));
    return u_shadow_on == 0 || s.z >= 1.0 ? 1.0 : lit;
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

vec4 to_display(vec3 linear_color) {
    vec3 c = linear_color * u_exposure;
    // Linear up to 0.8, then a soft shoulder towards 1 (keeps hues; no hard clipping).
    c = mix(c, 0.8 + 0.2 * (1.0 - exp(-(c - 0.8) / 0.2)), step(0.8, c));
    c = pow(c, vec3(1.0 / 2.2));
    c += (hash12(gl_FragCoord.xy) - 0.5) / 255.0;            // dither against banding
    return vec4(c, 1.0);
}
