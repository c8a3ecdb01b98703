#version 330 core
// Expands each line into a screen-space quad u_width pixels wide (core profile has no wide lines).

layout(lines) in;
layout(triangle_strip, max_vertices = 4) out;

#include "uniforms.glsl"

in vec4 g_color[];
out vec4 f_color;

void main() {
    vec4 p0 = gl_in[0].gl_Position;
    vec4 p1 = gl_in[1].gl_Position;
    float d0 = p0.z + p0.w;   // distance inside the near plane
    float d1 = p1.z + p1.w;
    if (d0 < 0.0 && d1 < 0.0) return;
    vec4 c0 = g_color[0];
    vec4 c1 = g_color[1];
    if (d0 < 0.0) { float t = d0 / (d0 - d1); p0 = mix(p0, p1, t); c0 = mix(c0, c1, t); }
    if (d1 < 0.0) { float t = d1 / (d1 - d0); p1 = mix(p1, p0, t); c1 = mix(c1, c0, t); }
    vec2 s0 = p0.xy / p0.w * u_viewport * 0.5;
    vec2 s1 = p1.xy / p1.w * u_viewport * 0.5;
    vec2 d = s1 - s0;
    float len = length(d);
    d = len > 1e-6 ? d / len : vec2(1.0, 0.0);
    vec2 n = vec2(-d.y, d.x) * (0.5 * u_width) / (0.5 * u_viewport);
    vec2 e = d * (0.5 * u_width) / (0.5 * u_viewport);   // extend the ends half a width
    f_color = c0; gl_Position = vec4(p0.xy + (n - e) * p0.w, p0.zw); EmitVertex();
    f_color = c0; gl_Position = vec4(p0.xy + (-n - e) * p0.w, p0.zw); EmitVertex();
    f_color = c1; gl_Position = vec4(p1.xy + (n + e) * p1.w, p1.zw); EmitVertex();
    f_color = c1; gl_Position = vec4(p1.xy + (-n + e) * p1.w, p1.zw); EmitVertex();
    EndPrimitive();
}
