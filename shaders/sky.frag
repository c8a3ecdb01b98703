#version 330 core
// The sky: from the air's colour at the horizon (common.glsl's air_color, which haze lays over
// the far ground and trees) to the zenith's blue, soft clouds (their cover u_clouds), lit from
// the sun's side and fading into the haze towards the horizon, and the sun's disc and glow where
// the light comes from. Below the horizon (where no ground is drawn) the air's colour.

#include "common.glsl"
#include "pixel.glsl"
#include "fbm.glsl"

out vec4 f_color;

// A cloud layer seen as a dome: p on it for a ray rising by h, so clouds shrink and crowd towards
// the horizon. CLOUD_SCALE sets their size: a noise cell is about 30 degrees across overhead.
const float CLOUD_SCALE = 2.0;

// How much cloud covers the sky towards `dir` (0 .. 1), and how lit it is there (0 its shaded
// underside .. 1 its sunlit side): lit where the density falls towards the sun, greyer where
// the cloud is thick.
vec2 clouds(vec3 dir) {
    float h = max(dir.y, 0.0);
    vec2 p = CLOUD_SCALE * dir.xz / (h + 0.1);
    float px = length(fwidth(p));
    float d = fbm(p, px, 5, 0.5);
    float edge = mix(0.75, 0.3, u_clouds);
    float cover = smoothstep(edge, edge + 0.25, d) * smoothstep(0.0, 0.12, h) * step(1e-3, u_clouds);
    float towards_sun = fbm(p + 0.35 * normalize(u_sun_dir.xz + 1e-6), px, 3, 0.5);
    float lit = clamp(0.6 + 4.0 * (d - towards_sun), 0.0, 1.0) * (1.0 - 0.5 * smoothstep(edge + 0.1, edge + 0.45, d));
    return vec2(cover, lit);
}

vec3 sky_color(vec3 dir) {
    if (u_show_sky == 0) return u_sky_horizon;
    float h = dir.y;
    vec3 air = air_color(dir);
    vec3 c = mix(air, u_sky_zenith, pow(clamp(h, 0.0, 1.0), 0.6));
    c = mix(c, air * 0.92, smoothstep(0.0, -0.2, h));   // below the horizon: haze
    float s = max(dot(dir, u_sun_dir), 0.0);
    vec2 cl = clouds(dir);
    vec3 shade = 0.45 * u_sky_horizon + 0.2 * u_sky_zenith;
    vec3 sunlit = 0.4 * u_sun_color + 0.3 * u_sky_horizon;
    vec3 cloud = mix(shade, sunlit, cl.y) + u_sun_color * 0.25 * pow(s, 24.0);   // bright round the sun
    cloud = mix(cloud, air, 1.0 - smoothstep(0.0, 0.35, h));                      // far clouds: into the haze
    c = mix(c, cloud, cl.x);
    float disc = smoothstep(0.99985, 0.99993, s);            // about 1.4 degrees across
    // The glow round the sun; at the horizon the air's colour holds it already.
    float glow = 0.08 * pow(s, 16.0) * smoothstep(0.0, 0.2, h) + 0.35 * pow(s, 600.0);
    return c + u_sun_color * (glow * (1.0 - 0.6 * cl.x) + 2.5 * disc * (1.0 - 0.8 * cl.x));
}

void main() {
    f_color = to_display(sky_color(pixel_ray()));
}
