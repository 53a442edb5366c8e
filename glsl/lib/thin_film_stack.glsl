// A multilayer stack as the film (docs/physics.md §1.3): STACK_PAIRS periods, each a layer
// of film.ior and the film's thickness d over a spacer of film.spacer_ior, film.spacer_nm
// (scaled by d / thickness_max, so a thickness field swells the whole period), on the
// substrate: (HL)^N, a Bragg mirror or a Morpho scale's lamellae. Its amplitude is built
// from the substrate up by Rouard's recursion, one layer at a time,
//   r ← (r_top + r·e^{iφ}) / (1 + r_top·r·e^{iφ}),  φ = 4π·n·t·cos θ/λ,
// r_top the interface above the layer; exactly the characteristic matrix's reflectance
// (float64 twin: opaline/model/stack_film.py through model/multilayer.py). Layers are
// lossless with n ≥ 1, so from air every cos θ is real and no layer reflects totally; a
// conductor below makes the first r complex. Per wavelength and polarisation, averaged
// over s and p and integrated with the spectral path's colour weights; the fast path has
// no closed form for a stack and integrates STACK_BINS bins of its own.
// Included by lib/thin_film.glsl, which provides film_base_rgb, layer_cos_sq and
// interface_amplitude.
#ifndef THIN_FILM_STACK_GLSL
#define THIN_FILM_STACK_GLSL
#include "lib/complex.glsl"

#if WAVELENGTHS > 0
#define STACK_BINS WAVELENGTHS
#define stack_bin_nm(i) u_wavelength_nm[i]
#define stack_bin_weight(i) u_spectral_weight[i]
#define stack_bin_nk(i) u_substrate_nk[i]
#else
#define STACK_BINS 16
#define stack_bin_nm(i) u_stack_bin_nm[i]
#define stack_bin_weight(i) u_stack_bin_weight[i]
#define stack_bin_nk(i) u_stack_bin_nk[i]
#endif

// cos θ in a lossless layer of index n ≥ 1, lit from air at cos θ1 (never total reflection).
float stack_cos(float n, float cos1) {
    return sqrt(max(layer_cos_sq(n, cos1), 0.0));
}

// One layer laid over the amplitude r of what lies below it; e = e^{iφ} its round trip.
vec2 stack_layer(float r_top, vec2 r, vec2 e) {
    vec2 re = c_mul(r, e);
    return c_div(vec2(r_top, 0.0) + re, vec2(1.0, 0.0) + r_top * re);
}

// The stack's reflectance at one wavelength: s and p from their substrate amplitudes
// (bottom: s .xy, p .zw), the round trips eh (film layer) and el (spacer).
float stack_reflectance(vec4 bottom, vec2 r_top, vec2 r_lh, vec2 eh, vec2 el) {
    float sum = 0.0;
    for (int pol = 0; pol < 2; ++pol) {
        vec2 r = pol == 0 ? bottom.xy : bottom.zw;
        for (int k = 0; k < STACK_PAIRS; ++k) {
            r = stack_layer(-r_lh[pol], r, el);  // the spacer, under a film layer
            r = stack_layer(k == STACK_PAIRS - 1 ? r_top[pol] : r_lh[pol], r, eh);
        }
        sum += 0.5 * dot(r, r);
    }
    return sum;
}

vec3 film_rgb(Film film, float cos1, float d) {
    cos1 = clamp(cos1, 0.0, 1.0);
    if (cos1 <= 0.0) {
        return vec3(1.0);  // grazing: all is reflected, as film_interfaces has it
    }
    float nh = film.ior;
    float nl = film.spacer_ior;
    float cos_h = stack_cos(nh, cos1);
    float cos_l = stack_cos(nl, cos1);
    vec2 r_top = interface_amplitude(1.0, cos1, nh, cos_h);
    vec2 r_lh = interface_amplitude(nl, cos_l, nh, cos_h);  // a spacer above a film layer
    float spacer = film.thickness_max > 0.0 ? film.spacer_nm * d / film.thickness_max
                                            : film.spacer_nm;
    float opd_h = 2.0 * nh * d * cos_h;  // nm
    float opd_l = 2.0 * nl * spacer * cos_l;
#ifndef SUBSTRATE_CONDUCTOR
    vec2 r_sub = interface_amplitude(nl, cos_l, film.substrate_ior, stack_cos(film.substrate_ior, cos1));
    vec4 bottom = vec4(r_sub.x, 0.0, r_sub.y, 0.0);
#endif
    vec3 sum = vec3(0.0);
    for (int i = 0; i < STACK_BINS; ++i) {
#ifdef SUBSTRATE_CONDUCTOR
        vec4 bottom = film_conductor_r23(nl, cos1, cos_l, stack_bin_nk(i));
#endif
        // φ in cycles, reduced before the trigonometry, as the single film's.
        vec2 eh = c_exp_i(TWO_PI * fract(opd_h / stack_bin_nm(i)));
        vec2 el = c_exp_i(TWO_PI * fract(opd_l / stack_bin_nm(i)));
        sum += stack_bin_weight(i) * stack_reflectance(bottom, r_top, r_lh, eh, el);
    }
    return radiance_floor(sum);
}

#endif
