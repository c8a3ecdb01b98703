// Fragment shaders' helpers (include after common.glsl): this pixel's view ray, and the colour
// written for the display.

#include "uniforms.glsl"

// The view ray through this pixel's centre (unit, world; fragment shaders).
vec3 pixel_ray() {
    vec4 far = u_inv_view_proj * vec4(gl_FragCoord.xy / u_viewport * 2.0 - 1.0, 1.0, 1.0);
    return normalize(far.xyz / far.w - u_camera_pos);
}

vec4 to_display(vec3 linear_color) {
    vec3 c = linear_color * u_exposure;
    // Linear up to 0.8, then a soft shoulder towards 1 (keeps hues; no hard clipping).
    c = mix(c, 0.8 + 0.2 * (1.0 - exp(-(c - 0.8) / 0.2)), step(0.8, c));
    c = pow(c, vec3(1.0 / 2.2));
    c += (hash12(gl_FragCoord.xy) - 0.5) / 255.0;            // dither against banding
    return vec4(c, 1.0);
}
