#version 330 core
// The skinned tree's depth seen from the sun (render/shadow.py): the same skinning as
// tree.vert, so the shadow follows every bent branch and fluttering leaf.

#include "uniforms.glsl"
#include "skin.glsl"

in ivec4 in_ids;     // node, prev, object, material
in vec3 in_offset;   // rest offset from the node
in vec4 in_extra;    // x: weight of prev
in vec2 in_curve;    // t along the segment, 1 where it ends at the object's tip
in vec3 in_tangent0; // the rest curve's tangents at the segment's ends
in vec3 in_tangent1;

void main() {
    if (fetch_texel(u_objects, in_ids.z).r < 0.5) {   // hidden: outside the clip volume
        gl_Position = vec4(0.0, 0.0, 2.0, 1.0);
        return;
    }
    vec3 world, centre;
    mat3 R;
    skin_transform(in_ids.x, in_ids.y, in_extra.x, in_curve, in_offset, in_tangent0, in_tangent1, world, R, centre);
    gl_Position = u_light_view_proj * vec4(world, 1.0);
}
