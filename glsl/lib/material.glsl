// The material's MDF per colour channel: the one MDF the variant was compiled
// with, evaluated at the half vector rotated per channel (eq. 2), or per
// wavelength and integrated to linear sRGB when WAVELENGTHS > 0 (docs/design.md §4.1).
#ifndef MATERIAL_GLSL
#define MATERIAL_GLSL
#include "lib/common.glsl"
#include "lib/rotation.glsl"

#if defined(MDF_ASHIKHMIN)
#include "lib/mdf_ashikhmin.glsl"
#define mdf mdf_ashikhmin
#elif defined(MDF_MULTIPEAK)
#include "lib/mdf_multipeak.glsl"
#define mdf mdf_multipeak
#else
#error "define MDF_ASHIKHMIN or MDF_MULTIPEAK"
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
