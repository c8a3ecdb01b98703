// Node transforms from the per-frame node texture (RGBA32F, 2D layout, texelFetch).
// Node j occupies texels 3j, 3j+1, 3j+2 in row-major order over the texture's width:
//   texel 3j   = (p.x, p.y, p.z, r00)
//   texel 3j+1 = (r01, r02, r10, r11)
//   texel 3j+2 = (r12, r20, r21, r22)
// p is the node's world position, r its rotation relative to rest (row-major).

#include "uniforms.glsl"

vec4 fetch_texel(sampler2D tex, int i) {
    int w = textureSize(tex, 0).x;
    return texelFetch(tex, ivec2(i % w, i / w), 0);
}

void node_transform(int j, out vec3 p, out mat3 R) {
    vec4 a = fetch_texel(u_nodes, 3 * j);
    vec4 b = fetch_texel(u_nodes, 3 * j + 1);
    vec4 c = fetch_texel(u_nodes, 3 * j + 2);
    p = a.xyz;
    R = mat3(a.w, b.z, c.y,   // column 0 = (r00, r10, r20)
             b.x, b.w, c.z,   // column 1
             b.y, c.x, c.w);  // column 2
}

vec3 node_position(int j) {
    return fetch_texel(u_nodes, 3 * j).xyz;
}

mat3 orthonormal(mat3 m) {  // Gram-Schmidt on the columns
    vec3 c0 = normalize(m[0]);
    vec3 c1 = normalize(m[1] - dot(m[1], c0) * c0);
    return mat3(c0, c1, cross(c0, c1));
}

// Where a mesh vertex goes and the frame it turns with (render/skinning.py's notes; it is the
// same on the CPU). The vertex lies at t along the segment leaving `node`; T0 is the segment's
// frame at the node (R[node] blended with R[prev], the ground's identity for prev < 0), T1 at
// its far end (a joint's mean, or at an object's tip 1.5 R - 0.5 T0). Inside a segment the
// vertex rides the cubic Hermite curve between the ends with tangents T0 d0 and T1 d1, d0 and
// d1 the rest curve's (tangent0, tangent1), turned by the frame that carries the rest curve's
// tangent onto the bent one. `centre` is the point on the axis (the node itself where t = 0)
// the vertex is offset from.
void skin_transform(int node, int prev, float weight, vec2 curve, vec3 offset, vec3 d0, vec3 d1, out vec3 world,
                    out mat3 R, out vec3 centre) {
    vec3 p0;
    mat3 Rs;
    node_transform(node, p0, Rs);
    mat3 T0 = Rs;
    if (weight > 0.0) {
        vec3 pp;
        mat3 Rp = mat3(1.0);
        if (prev >= 0) node_transform(prev, pp, Rp);
        T0 = orthonormal(Rs * (1.0 - weight) + Rp * weight);
    }
    float t = curve.x;
    if (t <= 0.0) {
        R = T0;
        centre = p0;
        world = p0 + R * offset;
        return;
    }
    vec3 p1;
    mat3 R1;
    node_transform(node + 1, p1, R1);
    vec3 c = transpose(Rs) * (p1 - p0);
    mat3 T1 = orthonormal(curve.y > 0.5 ? 1.5 * Rs - 0.5 * T0 : 0.5 * (Rs + R1));
    float t2 = t * t;
    float t3 = t2 * t;
    vec3 h = vec3(3.0 * t2 - 2.0 * t3, t3 - 2.0 * t2 + t, t3 - t2);   // Hermite weights of p1 - p0, d0, d1
    vec3 rest = h.x * c + h.y * d0 + h.z * d1;
    centre = p0 + h.x * (p1 - p0) + h.y * (T0 * d0) + h.z * (T1 * d1);
    R = orthonormal((3.0 * t2 - 4.0 * t + 1.0) * T0 + (6.0 * t - 6.0 * t2) * Rs + (3.0 * t2 - 2.0 * t) * T1);
    world = centre + R * (offset - rest);
}
