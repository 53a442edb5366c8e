// Eqs. 3-4: multi-peak MDF, ½·max(hz,0)·(cos(2π·mu_f·r) + 1), r = sqrt(α·hx² + β·hy²).
// The phase is reduced to [0, 1) cycles before the cosine so float trig never
// sees a large argument. AA_ANALYTIC box-filters the cosine over the pixel's
// phase footprint: mean of cos over [x-Δ/2, x+Δ/2] is cos(x)·sinc(Δ/2). With N
// supersamples each covers about 1/√N of the pixel's width, so the footprint
// is scaled by u_aa_scale = 1/√N; filtering the whole pixel on every sample
// would blur twice.
#ifndef MDF_MULTIPEAK_GLSL
#define MDF_MULTIPEAK_GLSL
#include "lib/common.glsl"

uniform real u_mu_f;
uniform real u_alpha;
uniform real u_beta;
#ifdef AA_ANALYTIC
uniform float u_aa_scale;
#endif

float sinc_half(float footprint) {
    float half_width = 0.5 * footprint;
    return half_width > 1e-4 ? sin(half_width) / half_width : 1.0 - half_width * half_width / 6.0;
}

float mdf_multipeak(real2 h, float hz) {
    real r = sqrt(u_alpha * h.x * h.x + u_beta * h.y * h.y);
    real cycles = u_mu_f * r;
    float phase = TWO_PI * float(cycles - floor(cycles));
    float band = cos(phase);
#ifdef AA_ANALYTIC
    band *= sinc_half(TWO_PI * u_aa_scale * fwidth(float(cycles)));
#endif
    return 0.5 * max(hz, 0.0) * (band + 1.0);
}

#endif
