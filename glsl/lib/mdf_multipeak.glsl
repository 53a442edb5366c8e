// Eqs. 3-4: multi-peak MDF, ½·max(hz,0)·(cos(2π·mu_f·r) + 1), r = sqrt(α·hx² + β·hy²).
// The phase is reduced to [0, 1) cycles before the cosine so float trig never
// sees a large argument. AA_ANALYTIC box-filters the cosine over the sample's
// share of the pixel: across the box the phase is x0 + a·u + b·v (a, b: its
// screen derivatives, u, v in [-½, ½]), and the mean of cos over it is
// cos(x0)·sinc(a/2)·sinc(b/2), a product of two sincs. (One sinc of fwidth =
// |a| + |b| blurred diagonal bands: docs/accuracy.md.) N supersamples on a
// well-stratified pattern each own a cell about 1/√N of the pixel's width, so the
// box is scaled by aa_scale = 1/√N; the cells tile the pixel, so the filtered
// samples average to the pixel's box.
#ifndef MDF_MULTIPEAK_GLSL
#define MDF_MULTIPEAK_GLSL
#include "lib/common.glsl"

float sinc_half(float footprint) {
    float half_width = 0.5 * footprint;
    return half_width > 1e-4 ? sin(half_width) / half_width : 1.0 - half_width * half_width / 6.0;
}

// aa_scale: the sample's share of the pixel's width (read only under AA_ANALYTIC).
float mdf_multipeak(real2 h, float hz, real mu_f, real alpha, real beta, float aa_scale) {
    real r = sqrt(alpha * h.x * h.x + beta * h.y * h.y);
    real cycles = mu_f * r;
    float phase = TWO_PI * float(cycles - floor(cycles));
    float band = cos(phase);
#ifdef AA_ANALYTIC
    float box = TWO_PI * aa_scale;
    band *= sinc_half(box * abs(dFdx(float(cycles)))) * sinc_half(box * abs(dFdy(float(cycles))));
#endif
    return 0.5 * max(hz, 0.0) * (band + 1.0);
}

#endif
