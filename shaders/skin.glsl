// Node transforms from the per-frame node texture (RGBA32F, 2D layout, texelFetch).
// Node j occupies texels 3j, 3j+1, 3j+2 in row-major order over the texture's width:
//   texel 3j   = (p.x, p.y, p.z, r00)
//   texel 3j+1 = (r01, r02, r10, r11)
//   texel 3j+2 = (r12, r20, r21, r22)
// p is the node's world position, r its rotation relative to rest (row-major).

uniform sampler2D u_nodes;

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

// The rotation a vertex follows: node's, or at an inner joint the blend of the two
// segments' rotations made orthonormal again (Gram-Schmidt), so tubes bend smoothly.
void skin_transform(int node, int node2, float weight, out vec3 p, out mat3 R) {
    node_transform(node, p, R);
    if (weight > 0.0) {
        vec3 p2;
        mat3 R2;
        node_transform(node2, p2, R2);
        mat3 m = R * (1.0 - weight) + R2 * weight;
        vec3 c0 = normalize(m[0]);
        vec3 c1 = normalize(m[1] - dot(m[1], c0) * c0);
        R = mat3(c0, c1, cross(c0, c1));
    }
}
