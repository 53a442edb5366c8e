// The material's MDF per colour channel: the one MDF the variant was compiled
// with, evaluated at the half vector rotated per channel (eq. 2), or per
// wavelength and integrated to linear sRGB when WAVELENGTHS > 0 (docs/design.md §4.1).
#ifndef MATERIAL_GLSL
#define MATERIAL_GLSL
#include "lib/common.glsl"
#include "lib/rotation.glsl"

// The material's scalar parameters are read here, once for the library: the MDFs
// and Schlick's term (lib/mdf_*.glsl, lib/fresnel.glsl) take theirs as arguments.
#if defined(MDF_ASHIKHMIN)
#include "lib/mdf_ashikhmin.glsl"
uniform float u_ex;
uniform float u_ey;

float mdf(real2 h, float hz) {
    return mdf_ashikhmin(h, hz, u_ex, u_ey);
}
#elif defined(MDF_MULTIPEAK)
#include "lib/mdf_multipeak.glsl"
uniform real u_mu_f;
uniform real u_alpha;
uniform real u_beta;
#ifdef AA_ANALYTIC
uniform float u_aa_scale;
#define MDF_AA_SCALE u_aa_scale
#else
#define MDF_AA_SCALE 1.0  // not read: no filter is compiled in
#endif

float mdf(real2 h, float hz) {
    return mdf_multipeak(h, hz, u_mu_f, u_alpha, u_beta, MDF_AA_SCALE);
}
#else
#error "define MDF_ASHIKHMIN or MDF_MULTIPEAK"
#endif
#ifdef FRESNEL
#include "lib/fresnel.glsl"
uniform float u_f0;
#endif

#if WAVELENGTHS > 0
// Per wavelength: (cos θ(λ), sin θ(λ)) and its weight into linear sRGB
// (CIE 1931 CMFs × XYZ→sRGB, white balanced so equal D gives equal RGB).
uniform real2 u_spectral_rotation[WAVELENGTHS];
uniform vec3 u_spectral_weight[WAVELENGTHS];

vec3 mdf_color(real2 h, float hz) {
    vec3 sum = vec3(0.0);
    for (int i = 0; i < WAVELENGTHS; ++i) {
        sum += u_spectral_weight[i] * mdf(rotate_half(h, u_spectral_rotation[i]), hz);
    }
    // Colour matching weights go negative outside the sRGB gamut; radiance may not.
    return max(sum, vec3(0.0));
}
#else
// (cos θ, sin θ) for R, G, B: θ = 0, theta1, theta2.
uniform real2 u_rotation[3];

vec3 mdf_color(real2 h, float hz) {
    return vec3(
        mdf(rotate_half(h, u_rotation[0]), hz),
        mdf(rotate_half(h, u_rotation[1]), hz),
        mdf(rotate_half(h, u_rotation[2]), hz));
}
#endif

#endif
