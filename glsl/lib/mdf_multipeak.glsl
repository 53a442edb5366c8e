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

// The bands alone, cos(2π·mu_f·r), box-filtered over a square cell of side `cell` in
// the projected disc (hx, hy): the pixel's filter above with the phase's slope in h for
// its screen derivatives. Environment light draws each lobe sample from the disc, where
// it stands for an area π/N of it (N the wavelength's samples): a cell over many bands
// reads their mean, as the converged integral over a broad light does, instead of one
// band's colour; as N grows the cell shrinks to the unfiltered band. The cell is taken
// in the wavelength's turned frame (a square turned by θ(λ), taken as upright).
float multipeak_band_cell(real2 h, real mu_f, real alpha, real beta, float cell) {
    real r = sqrt(alpha * h.x * h.x + beta * h.y * h.y);
    real cycles = mu_f * r;
    vec2 slope = vec2(mu_f / max(r, real(1e-6)) * real2(alpha * h.x, beta * h.y));
    float box = TWO_PI * cell;
    return cos(TWO_PI * float(cycles - floor(cycles)))
           * sinc_half(box * abs(slope.x)) * sinc_half(box * abs(slope.y));
}

#endif
