// Fractal value noise for the sky's clouds and the ground (include after common.glsl).

// `octaves` octaves of vnoise at p, 2p, 4p, ... (each `gain` times the weight of the one before:
// 0.5 soft, towards 1 grainy; turned and shifted so their lattices do not line up), in 0 .. 1
// about 0.5. `px` is a pixel's size in
// p's units (fwidth): an octave finer than about two pixels fades to its mean, so nothing
// shimmers and the far field is smooth rather than noisy.
float fbm(vec2 p, float px, int octaves, float gain) {
    const mat2 TURN = mat2(1.6, 1.2, -1.2, 1.6);   // x2 and turned by 37 degrees
    float sum = 0.0, weight = 0.5, total = 0.0;
    for (int k = 0; k < octaves; ++k) {
        float keep = 1.0 - smoothstep(0.2, 0.5, px);
        sum += weight * mix(0.5, vnoise(p), keep);
        total += weight;
        p = TURN * p + vec2(17.3, -9.1);
        px *= 2.0;
        weight *= gain;
    }
    return sum / total;
}
