// The material's MDF per colour channel: the one MDF the variant was compiled
// with, evaluated at the half vector rotated per channel (eq. 2), or per
// wavelength and integrated to linear sRGB when WAVELENGTHS > 0 (docs/design.md §4.1).
// The material comes in as a Material, filled once per fragment by the program
// (glsl/material_params.glsl). Contract: with WAVELENGTHS > 0 the program declares,
// before this file, the per-wavelength tables (copied into a struct they would cost
// a copy per call):
//   real2 u_spectral_rotation[WAVELENGTHS];  (cos θ(λ), sin θ(λ))
//   vec3 u_spectral_weight[WAVELENGTHS];     its weight into linear sRGB
// The iridescence sources' own tables are named at the top of their files.
#ifndef MATERIAL_GLSL
#define MATERIAL_GLSL
#include "lib/common.glsl"
#include "lib/rotation.glsl"

#if defined(MDF_ASHIKHMIN)
#include "lib/mdf_ashikhmin.glsl"
#elif defined(MDF_MULTIPEAK)
#include "lib/mdf_multipeak.glsl"
#else
#error "define MDF_ASHIKHMIN or MDF_MULTIPEAK"
#endif
#ifdef FRESNEL
#include "lib/fresnel.glsl"
#endif
#ifdef COAT
#include "lib/coat.glsl"
#endif

#ifdef IRIDESCENCE_THIN_FILM
struct Film {  // lib/thin_film.glsl
    float ior;
    float substrate_ior;  // not read over a conductor: its n + ik is a table
    float thickness_min;  // nm: a thickness map's 0
    float thickness_max;  // nm: its 1, and the thickness without a map
#ifdef FILM_WEIGHT
    float weight;  // KHR iridescenceFactor: mix(bare substrate, film, weight); 1 without
#endif
#ifdef STACK_PAIRS
    float spacer_ior;  // a stack's second layer (lib/thin_film_stack.glsl)
    float spacer_nm;  // its thickness where the film's is thickness_max
#endif
};
#endif
#ifdef IRIDESCENCE_GRATING
struct Grating {  // lib/grating.glsl
    float pitch_nm;
    float depth_nm;
#if WAVELENGTHS == 0 || defined(ENV_GRATING_ORDERS)
    vec3 channel_nm;  // where η_0 is taken per channel
#endif
};
#endif

struct Material {
#if defined(MDF_ASHIKHMIN)
    float ex;
    float ey;
#else
    real mu_f;
    real alpha;
    real beta;
    float aa_scale;  // 1 where no filter is compiled in (AA_ANALYTIC off)
#endif
    float ks;
    float kd;
    vec3 albedo;
    float f0;
#if WAVELENGTHS == 0
    real2 rotation[3];  // (cos θ, sin θ) for R, G, B: θ = 0, theta1, theta2
#endif
#ifdef IRIDESCENCE_THIN_FILM
    Film film;
#endif
#ifdef IRIDESCENCE_GRATING
    Grating grating;
#endif
#ifdef COAT
    Coat coat;
#endif
};

#if defined(MDF_ASHIKHMIN)
float mdf(Material mat, real2 h, float hz) {
    return mdf_ashikhmin(h, hz, mat.ex, mat.ey);
}
#else
float mdf(Material mat, real2 h, float hz) {
    return mdf_multipeak(h, hz, mat.mu_f, mat.alpha, mat.beta, mat.aa_scale);
}
#endif

#if WAVELENGTHS > 0 && defined(MDF_ASHIKHMIN)
// CIE 1931 CMFs × XYZ→sRGB, white balanced so equal D gives equal RGB; eq. 1's logarithm
// once for every wavelength (a turn keeps |h|), its exp at each.
vec3 mdf_color(Material mat, real2 h, float hz) {
    float log_scale = ashikhmin_log_scale(h);
    vec3 sum = vec3(0.0);
    for (int i = 0; i < WAVELENGTHS; ++i) {
        sum += u_spectral_weight[i] * ashikhmin_turned(h, u_spectral_rotation[i], log_scale,
                                                       mat.ex, mat.ey);
    }
    // A channel below 0 (a colour outside sRGB) is kept to the display's gamut map.
    return hz > 0.0 ? radiance_floor(ashikhmin_norm(mat.ex, mat.ey) * sum) : vec3(0.0);
}
#elif WAVELENGTHS > 0
vec3 mdf_color(Material mat, real2 h, float hz) {
    vec3 sum = vec3(0.0);
    for (int i = 0; i < WAVELENGTHS; ++i) {
        sum += u_spectral_weight[i] * mdf(mat, rotate_half(h, u_spectral_rotation[i]), hz);
    }
    return radiance_floor(sum);
}
#elif defined(MDF_ASHIKHMIN)
vec3 mdf_color(Material mat, real2 h, float hz) {
    return mdf_ashikhmin_three(h, hz, mat.ex, mat.ey, mat.rotation[0], mat.rotation[1],
                               mat.rotation[2]);
}
#else
vec3 mdf_color(Material mat, real2 h, float hz) {
    return vec3(
        mdf(mat, rotate_half(h, mat.rotation[0]), hz),
        mdf(mat, rotate_half(h, mat.rotation[1]), hz),
        mdf(mat, rotate_half(h, mat.rotation[2]), hz));
}
#endif

// Schlick's F where the material has it (FRESNEL), else 1.
float material_fresnel(Material mat, float cos_theta) {
#ifdef FRESNEL
    return fresnel_schlick(cos_theta, mat.f0);
#else
    return 1.0;
#endif
}

// F(v·h)/(4·(v·h)·max(n·l, n·v)): the microfacet reflectance of §1.5 without D and ks.
float microfacet_factor(Material mat, float vh, float nl, float nv) {
    return material_fresnel(mat, vh) / (4.0 * max(vh, EPS_DENOM) * max(max(nl, nv), EPS_DENOM));
}

#endif
