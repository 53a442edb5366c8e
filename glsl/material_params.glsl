// The material's parameters as gl/material_program.py sets them, by name, and the
// Material the library takes (lib/material.glsl), filled from them. Included by the
// programs that shade the material, and by the GLSL export (gl/export_glsl.py),
// which turns each of these declarations into a constant.
#ifndef MATERIAL_PARAMS_GLSL
#define MATERIAL_PARAMS_GLSL
#include "lib/common.glsl"
#if WAVELENGTHS > 0
uniform real2 u_spectral_rotation[WAVELENGTHS];
uniform vec3 u_spectral_weight[WAVELENGTHS];
#endif
#if WAVELENGTHS > 0 && (defined(IRIDESCENCE_THIN_FILM) || defined(IRIDESCENCE_GRATING))
uniform float u_wavelength_nm[WAVELENGTHS];
#endif
#if WAVELENGTHS == 0 && defined(IRIDESCENCE_THIN_FILM)
// The fast path's Gaussians per channel: FILM_GAUSSIANS, defined by
// gl/material_program.py from opaline/model/visible.py's SENSITIVITY_GAUSSIANS.
uniform vec3 u_film_sens_weight[FILM_GAUSSIANS];
uniform vec3 u_film_sens_centre[FILM_GAUSSIANS];
uniform vec3 u_film_sens_sigma[FILM_GAUSSIANS];
#endif
#if defined(IRIDESCENCE_THIN_FILM) && defined(SUBSTRATE_CONDUCTOR) && WAVELENGTHS > 0
uniform vec2 u_substrate_nk[WAVELENGTHS];
#elif defined(IRIDESCENCE_THIN_FILM) && defined(SUBSTRATE_CONDUCTOR)
uniform vec2 u_substrate_nk[3];
#endif
#if defined(IRIDESCENCE_THIN_FILM) && defined(STACK_PAIRS) && WAVELENGTHS == 0
// A stack has no closed form over the colour weights: the fast path evaluates it at the
// bins of lib/thin_film_stack.glsl's STACK_BINS.
uniform float u_stack_bin_nm[16];
uniform vec3 u_stack_bin_weight[16];
#ifdef SUBSTRATE_CONDUCTOR
uniform vec2 u_stack_bin_nk[16];
#endif
#endif
#if (WAVELENGTHS == 0 || defined(ENV_GRATING_ORDERS)) && defined(IRIDESCENCE_GRATING)
uniform vec3 u_visible_density[81];  // VISIBLE_TABLE of lib/grating.glsl
uniform uvec3 u_visible_cumulative[81];  // its integral from 380 nm (visible.packed_cumulative)
#endif
#include "lib/material.glsl"

#if defined(MDF_ASHIKHMIN)
uniform float u_ex;
uniform float u_ey;
#else
uniform real u_mu_f;
uniform real u_alpha;
uniform real u_beta;
#ifdef AA_ANALYTIC
uniform float u_aa_scale;
#endif
#endif
uniform float u_ks;
#ifdef DIFFUSE
uniform float u_kd;
uniform vec3 u_albedo;
#endif
#ifdef FRESNEL
uniform float u_f0;
#endif
#if WAVELENGTHS == 0
uniform real2 u_rotation[3];
#endif
#ifdef IRIDESCENCE_THIN_FILM
uniform float u_film_ior;
uniform float u_substrate_ior;
uniform float u_film_thickness_min;
uniform float u_film_thickness_max;
#ifdef FILM_WEIGHT
uniform float u_film_weight;
#endif
#ifdef STACK_PAIRS
uniform float u_stack_spacer_ior;
uniform float u_stack_spacer_nm;
#endif
#endif
#ifdef COAT
uniform float u_coat_weight;
uniform float u_coat_f0;
uniform float u_coat_exponent;
#endif
#ifdef IRIDESCENCE_GRATING
uniform float u_grating_pitch_nm;
uniform float u_grating_depth_nm;
#if WAVELENGTHS == 0 || defined(ENV_GRATING_ORDERS)
uniform vec3 u_channel_nm;
#endif
#endif

Material material_params() {
    Material mat;
#if defined(MDF_ASHIKHMIN)
    mat.ex = u_ex;
    mat.ey = u_ey;
#else
    mat.mu_f = u_mu_f;
    mat.alpha = u_alpha;
    mat.beta = u_beta;
#ifdef AA_ANALYTIC
    mat.aa_scale = u_aa_scale;
#else
    mat.aa_scale = 1.0;
#endif
#endif
    mat.ks = u_ks;
#ifdef DIFFUSE
    mat.kd = u_kd;
    mat.albedo = u_albedo;
#else
    mat.kd = 0.0;  // not read: no diffuse term is compiled in
    mat.albedo = vec3(0.0);
#endif
#ifdef FRESNEL
    mat.f0 = u_f0;
#else
    mat.f0 = 0.0;  // not read: Fresnel is off
#endif
#if WAVELENGTHS == 0
    mat.rotation = u_rotation;
#endif
#ifdef IRIDESCENCE_THIN_FILM
    mat.film.ior = u_film_ior;
    mat.film.substrate_ior = u_substrate_ior;
    mat.film.thickness_min = u_film_thickness_min;
    mat.film.thickness_max = u_film_thickness_max;
#ifdef FILM_WEIGHT
    mat.film.weight = u_film_weight;
#endif
#ifdef STACK_PAIRS
    mat.film.spacer_ior = u_stack_spacer_ior;
    mat.film.spacer_nm = u_stack_spacer_nm;
#endif
#endif
#ifdef IRIDESCENCE_GRATING
    mat.grating.pitch_nm = u_grating_pitch_nm;
    mat.grating.depth_nm = u_grating_depth_nm;
#if WAVELENGTHS == 0 || defined(ENV_GRATING_ORDERS)
    mat.grating.channel_nm = u_channel_nm;
#endif
#endif
#ifdef COAT
    mat.coat.weight = u_coat_weight;
    mat.coat.f0 = u_coat_f0;
    mat.coat.exponent = u_coat_exponent;
#endif
    return mat;
}

#endif
