#version 330 core
// Sky gradient with the sun's disc and glow; below the horizon (where no ground is drawn) haze.

#include "common.glsl"
#include "pixel.glsl"

out vec4 f_color;

vec3 sky_color(vec3 dir) {
    if (u_show_sky == 0) return u_sky_horizon;
    float h = dir.y;
    vec3 c = mix(u_sky_horizon, u_sky_zenith, pow(clamp(h, 0.0, 1.0), 0.6));
    c = mix(c, u_sky_horizon * 0.92, smoothstep(0.0, -0.2, h));   // below the horizon: haze
    float s = max(dot(dir, u_sun_dir), 0.0);
    float disc = smoothstep(0.99985, 0.99993, s);            // about 1.4 degrees across
    return c + u_sun_color * (0.05 * pow(s, 8.0) + 0.35 * pow(s, 600.0) + 2.5 * disc);
}

void main() {
    f_color = to_display(sky_color(pixel_ray()));
}
