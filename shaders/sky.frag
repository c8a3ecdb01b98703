#version 330 core

#include "common.glsl"

in vec2 v_ndc;
uniform mat4 u_inv_view_proj;
out vec4 f_color;

void main() {
    vec4 far = u_inv_view_proj * vec4(v_ndc, 1.0, 1.0);
    vec3 dir = normalize(far.xyz / far.w - u_camera_pos);
    float h = dir.y;
    vec3 c = mix(u_sky_horizon, u_sky_zenith, pow(clamp(h, 0.0, 1.0), 0.6));
    c = mix(c, u_sky_horizon * 0.92, smoothstep(0.0, -0.2, h));   // below the horizon: haze
    float s = max(dot(dir, u_sun_dir), 0.0);
    c += u_sun_color * (0.05 * pow(s, 8.0) + 0.6 * pow(s, 600.0));
    f_color = to_display(c);
}
