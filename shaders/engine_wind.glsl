// treeanim's reference shader wind for engines (GLSL ES 3.0; three.js, Unity, Unreal and Godot
// port it line for line). It sways a static mesh written by `treeanim export --motion shader`:
// each vertex carries its object's index (attribute _OBJECT, a float), and the file's table
// (the accessor named by the mesh's extras.treeanim_wind.table, loaded as an RGBA float texture
// of `width` x `height` texels, nearest filtering) holds each object's four levels of the
// branches it hangs from, trunk first (level 0), in 9 texels (tree_wind_fetch):
//   pivot[l]   xyz: the branch's base at rest; w: its frequency in Hz (0: no such level)
//   axis[l]    xyz: the branch's rest direction (unit); w: its compliance c: the mean bend in
//              rad is c U^n in a wind of U m/s at the canopy top (n: the mesh's
//              extras.treeanim_wind.exponent, the tree's; 2 for rigid wood, less with leaves)
//   damping    the damping ratio of each level
// All measured from treeanim's simulation of the tree (docs/design.md §16).
//
// Each level bends about the horizontal axis across the wind, through its pivot, by
//   theta = c U^n (1 + 2 I g(t - x/U) + 2 I R sin(2 pi f t + phi)),   R = 0.28 / sqrt(zeta)
// the mean lean, the background response to the gusts g (unit variance, travelling downwind at U,
// so a gust front crosses a forest) and the resonant sway at the branch's own frequency, whose
// share grows as its damping falls (Davenport's gust factor). Levels apply innermost first,
// so each branch carries what grows on it.
//
// An instanced mesh (`export --instances`: EXT_mesh_gpu_instancing, one template drawn at many
// trees) passes each instance's placement (model and instance matrix, turn and uniform scale;
// the identity for a lone tree): the wind turns into the template's frame, and the gusts' travel
// and the branches' phases follow the world position of each pivot, so the trees of a forest
// do not sway in unison.

const float TREE_WIND_TAU = 6.283185307;

// Gusts: a few incommensurate sines of the time a parcel of air left x = 0, unit variance.
float tree_wind_gust(float t) {
    return 0.8 * (sin(0.21 * TREE_WIND_TAU * t) + 0.7 * sin(0.37 * TREE_WIND_TAU * t + 1.3)
                  + 0.5 * sin(0.61 * TREE_WIND_TAU * t + 2.9));
}

// A branch's phase from where it grows: neighbours do not swing in step.
float tree_wind_phase(vec3 pivot) {
    return TREE_WIND_TAU * fract(sin(dot(pivot, vec3(12.9898, 78.233, 37.719))) * 43758.5453);
}

// Rotate p about the unit axis k through c by angle a (Rodrigues).
vec3 tree_wind_rotate(vec3 p, vec3 c, vec3 k, float a) {
    vec3 d = p - c;
    float s = sin(a), co = cos(a);
    return c + d * co + cross(k, d) * s + k * dot(k, d) * (1.0 - co);
}

// The bend of one level, and its axis, in a wind of `speed` m/s along the unit horizontal
// `dir` (in the mesh's frame) with turbulence intensity `turb` at time `t` s; the tree's bends
// grow as speed^n. `travel` (s) is how long the gusts took from x = 0 to the pivot and `world`
// the pivot's world position.
float tree_wind_bend(vec4 pivot, vec4 axis, float zeta, vec3 dir, float speed, float n, float turb, float t,
                     float travel, vec3 world, out vec3 k) {
    k = cross(axis.xyz, dir);
    float len_k = length(k);
    k = len_k > 1e-3 ? k / len_k : normalize(cross(vec3(0.0, 1.0, 0.0), dir));  // along the wind: bend as a stem
    float load = axis.w * pow(max(speed, 0.0), n);
    float resonant = 0.28 / sqrt(max(zeta, 0.01));
    return load * (1.0 + 2.0 * turb * tree_wind_gust(t - travel)
                   + 2.0 * turb * resonant * sin(TREE_WIND_TAU * pivot.w * t + tree_wind_phase(world)));
}

// Object o's entry: texels (o mod width, 9 floor(o / width) + r), r = 0..8.
void tree_wind_fetch(highp sampler2D table, int width, int object, out vec4 pivot[4], out vec4 axis[4],
                     out vec4 damping) {
    ivec2 at = ivec2(object % width, 9 * (object / width));
    for (int l = 0; l < 4; ++l) {
        pivot[l] = texelFetch(table, at + ivec2(0, l), 0);
        axis[l] = texelFetch(table, at + ivec2(0, 4 + l), 0);
    }
    damping = texelFetch(table, at + ivec2(0, 8), 0);
}

// The swayed position of a vertex at rest position p (and its normal, turned alike), in the
// mesh's frame; `place` puts the mesh in the world, `dir` is the wind's world direction.
void tree_wind(inout vec3 p, inout vec3 normal, vec4 pivot[4], vec4 axis[4], vec4 damping, mat4 place,
               vec3 dir, float speed, float exponent, float turb, float t) {
    vec3 local = normalize(transpose(mat3(place)) * dir);  // a turn and a uniform scale
    for (int l = 3; l >= 0; --l) {
        if (pivot[l].w <= 0.0) continue;
        vec3 k, world = (place * vec4(pivot[l].xyz, 1.0)).xyz;
        float a = tree_wind_bend(pivot[l], axis[l], damping[l], local, speed, exponent, turb, t,
                                 dot(world, dir) / max(speed, 0.1), world, k);
        p = tree_wind_rotate(p, pivot[l].xyz, k, a);
        normal = tree_wind_rotate(normal, vec3(0.0), k, a);
    }
}
