// Complex arithmetic on vec2 (re, im), for the films over a conductor and the stacks.
#ifndef COMPLEX_GLSL
#define COMPLEX_GLSL

vec2 c_mul(vec2 a, vec2 b) {
    return vec2(a.x * b.x - a.y * b.y, a.x * b.y + a.y * b.x);
}

vec2 c_div(vec2 a, vec2 b) {
    return c_mul(a, vec2(b.x, -b.y)) / max(dot(b, b), 1e-30);
}

// Principal square root: Re ≥ 0, and Im ≥ 0 where Im z ≥ 0 (k ≥ 0: the wave decays
// into the metal). The smaller part is found by division, not by cancellation.
vec2 c_sqrt(vec2 z) {
    float r = length(z);
    if (z.x >= 0.0) {
        float re = sqrt(0.5 * (r + z.x));
        return vec2(re, re > 0.0 ? 0.5 * z.y / re : 0.0);
    }
    float im = sqrt(0.5 * (r - z.x));
    return vec2(0.5 * abs(z.y) / im, z.y < 0.0 ? -im : im);
}

// e^{iφ}
vec2 c_exp_i(float phase) {
    return vec2(cos(phase), sin(phase));
}

#endif
