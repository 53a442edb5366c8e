// Eq. 1: Ashikhmin-Shirley MDF, sqrt((ex+1)(ey+1))/(2π) · hz^((ex·hx²+ey·hy²)/(hx²+hy²)).
// Written from the projected components (docs/design.md §2): hz^e = exp(½·e·log1p(-s²)),
// so neither pow with a huge exponent nor 1 - hz² appears.
#ifndef MDF_ASHIKHMIN_GLSL
#define MDF_ASHIKHMIN_GLSL
#include "lib/common.glsl"
#include "lib/rotation.glsl"

// -log1p(-s2)/s2: 1 at the pole, growing toward the rim. GLSL has no log1p,
// and fp32 log(u) near u = 1 is only accurate in absolute terms, which at
// exponents of 1e5-1e6 (lobes at s2 ~ 1e-5) costs percents. Near the pole the
// series 1 + s2/2 + s2²/3 + ... (truncation < 1e-8 below s2 = 1/8) is used;
// further out u - 1 is exact and log(u)/(u - 1) is accurate.
float log1p_ratio(float s2) {
    if (s2 < 0.125) {
        float sum = 1.0 / 9.0;
        sum = 1.0 / 8.0 + s2 * sum;
        sum = 1.0 / 7.0 + s2 * sum;
        sum = 1.0 / 6.0 + s2 * sum;
        sum = 1.0 / 5.0 + s2 * sum;
        sum = 1.0 / 4.0 + s2 * sum;
        sum = 1.0 / 3.0 + s2 * sum;
        sum = 1.0 / 2.0 + s2 * sum;
        return 1.0 + s2 * sum;
    }
    float u = max(1.0 - s2, 1e-12);
    return log(u) / (u - 1.0);
}

float ashikhmin_norm(float ex, float ey) {
    return sqrt((ex + 1.0) * (ey + 1.0)) / TWO_PI;
}

// ½·log(hz²)/|h|² = −½·log1p_ratio(|h|²): what eq. 1's exponent (ex·hx² + ey·hy²) is
// multiplied by before exp. A turn of h keeps |h|, so the rotation source takes it once
// for all its channels or wavelengths (material.glsl, environment_light.glsl).
float ashikhmin_log_scale(real2 h) {
    return -0.5 * log1p_ratio(min(float(dot(h, h)), 1.0));
}

// Eq. 1 without its norm at h turned by cs (eq. 2's rotation), given h's log scale.
float ashikhmin_turned(real2 h, real2 cs, float log_scale, float ex, float ey) {
    vec2 r = vec2(rotate_half(h, cs));
    return exp(log_scale * (ex * r.x * r.x + ey * r.y * r.y));
}

// Eq. 1 at h turned by three angles (the paper's R, G, B channels, eq. 2): one logarithm
// for the three.
vec3 mdf_ashikhmin_three(real2 h, float hz, float ex, float ey, real2 t0, real2 t1,
                         real2 t2) {
    float log_scale = ashikhmin_log_scale(h);
    vec3 d = vec3(ashikhmin_turned(h, t0, log_scale, ex, ey),
                  ashikhmin_turned(h, t1, log_scale, ex, ey),
                  ashikhmin_turned(h, t2, log_scale, ex, ey));
    return hz > 0.0 ? ashikhmin_norm(ex, ey) * d : vec3(0.0);
}

float mdf_ashikhmin(real2 h, float hz, float ex, float ey) {
    float hx2 = float(h.x * h.x);
    float hy2 = float(h.y * h.y);
    float s2 = min(hx2 + hy2, 1.0);
    float log_term = -0.5 * (ex * hx2 + ey * hy2) * log1p_ratio(s2);
    return hz > 0.0 ? ashikhmin_norm(ex, ey) * exp(log_term) : 0.0;
}

#endif
