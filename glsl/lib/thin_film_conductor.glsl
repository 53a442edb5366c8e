// Thin film on a conductor (docs/physics.md §1.2): the substrate's index is
// complex, ñ = n + ik, so the lower interface's amplitude b is complex for each
// polarisation, and Airy's sum per polarisation is
//   R = (a² + |b|² + 2a·Re(b·e^{iφ})) / (1 + a²|b|² + 2a·Re(b·e^{iφ})),
// exact for an absorbing substrate (the film itself stays lossless, a real). The
// metal does not reflect totally; only the film's top can (never for n ≥ 1).
// Included by lib/thin_film.glsl for SUBSTRATE_CONDUCTOR; float64 twin:
// opaline/model/thinfilm.py (_conductor_interfaces, film_rgb_fast_conductor).
#ifndef THIN_FILM_CONDUCTOR_GLSL
#define THIN_FILM_CONDUCTOR_GLSL

#include "lib/complex.glsl"

// The film's top interface (s, p), as film_interfaces; false where light cannot enter,
// and exactly at grazing, where all is reflected (over a lossless ñ = 1 Airy is 0/0).
bool film_top(float nf, float cos1, out float cos2, out vec2 r12) {
    float cos2_sq = layer_cos_sq(nf, cos1);
    cos2 = sqrt(max(cos2_sq, 0.0));
    r12 = interface_amplitude(1.0, cos1, nf, cos2);
    return cos2_sq > 0.0 && cos1 > 0.0;
}

// The lower interface over ñ = nk: complex r23 for s (.xy) and p (.zw), with
// ñ·cos θ3 = √(ñ² - sin²θ1).
vec4 film_conductor_r23(float nf, float cos1, float cos2, vec2 nk) {
    vec2 n_sq = c_mul(nk, nk);
    // (ñ² - 1) + cos²θ1, in that order, as the dielectric's cos²θ3: near grazing
    // cos²θ1 - 1 rounds to -1 in float, which would turn ñ = 1 into a mirror.
    vec2 n_cos3 = c_sqrt(vec2(n_sq.x - 1.0 + cos1 * cos1, n_sq.y));
    vec2 top_s = vec2(nf * cos2, 0.0);
    vec2 top_p = n_sq * cos2;
    vec2 bottom_p = nf * n_cos3;
    return vec4(c_div(top_s - n_cos3, top_s + n_cos3), c_div(top_p - bottom_p, top_p + bottom_p));
}

// The bare metal's Fresnel reflectance from air (s and p averaged): the lower interface
// with the film's index 1. All is reflected exactly at grazing, as film_top has it.
float film_bare_conductor(float cos1, vec2 nk) {
    if (cos1 <= 0.0) {
        return 1.0;
    }
    vec4 r = film_conductor_r23(1.0, cos1, cos1, nk);
    return 0.5 * (dot(r.xy, r.xy) + dot(r.zw, r.zw));
}

#if WAVELENGTHS > 0
// u_substrate_nk: n + ik at each wavelength.
// A wavelength stands for a bin of (780 - 380)/WAVELENGTHS nm (model/spectrum.py), across
// which a micron-thick film's phase turns a cycle or more: each reads R averaged over its
// bin's phases (float64 twin: opaline/model/airy_band.py, which derives this).
#define FILM_BIN_NM (400.0 / float(WAVELENGTHS))

// One polarisation (a real, b complex) averaged about e = e^{iφ} by a Poisson kernel of
// radius rho (1: Airy's own value, 0: the incoherent sum): with q = -ab, β = (1 - a²)·b,
//   R = C0 + 2·Re(K·w/(1 - q·w)),  w = rho·e,
//   C0 = a² + |β|²/(1 - |q|²),  K = a·β + |β|²·q/(1 - |q|²).
float film_airy_band(float a, vec2 b, vec2 e, float rho) {
    vec2 beta = (1.0 - a * a) * b;
    vec2 q = -a * b;
    float beta_sq = dot(beta, beta);
    float inverse = 1.0 / max(1.0 - dot(q, q), 1e-30);
    vec2 k = a * beta + beta_sq * inverse * q;
    vec2 w = rho * e;
    vec2 term = c_div(c_mul(k, w), vec2(1.0, 0.0) - c_mul(q, w));
    return max(a * a + beta_sq * inverse + 2.0 * term.x, 0.0);
}

// The base without its film: the bare metal, integrated as the film is.
vec3 film_base_rgb(Film film, float cos1) {
    cos1 = clamp(cos1, 0.0, 1.0);
    vec3 sum = vec3(0.0);
    for (int i = 0; i < WAVELENGTHS; ++i) {
        sum += u_spectral_weight[i] * film_bare_conductor(cos1, u_substrate_nk[i]);
    }
    return radiance_floor(sum);
}

#ifndef STACK_PAIRS  // a stack's layers draw the film instead (lib/thin_film_stack.glsl)
vec3 film_rgb(Film film, float cos1, float d) {
    cos1 = clamp(cos1, 0.0, 1.0);
    float cos2;
    vec2 r12;
    if (!film_top(film.ior, cos1, cos2, r12)) {
        return vec3(1.0);
    }
    float opd = 2.0 * film.ior * d * cos2;  // nm
    vec3 sum = vec3(0.0);
    for (int i = 0; i < WAVELENGTHS; ++i) {
        vec4 r23 = film_conductor_r23(film.ior, cos1, cos2, u_substrate_nk[i]);
        // φ in cycles, reduced before the trigonometry, as the dielectric path. Its spread
        // over the bin, Δφ = φ·Δλ/λ: the terms the samples resolve (m·Δφ < π) are kept,
        // the first is removed where it would alias (model/airy_band.py).
        float cycles = opd / u_wavelength_nm[i];
        float phase = TWO_PI * fract(cycles);
        float spread = 2.0 * cycles * FILM_BIN_NM / u_wavelength_nm[i];  // Δφ/π
        float rho = exp(-(spread * spread) * (spread * spread));
        vec2 e = vec2(cos(phase), sin(phase));
        float r = 0.5 * (film_airy_band(r12.x, r23.xy, e, rho)
                         + film_airy_band(r12.y, r23.zw, e, rho));
        sum += u_spectral_weight[i] * r;
    }
    return radiance_floor(sum);
}
#endif
#else
// Fast path: the dielectric's Fourier series (lib/thin_film.glsl) per channel, with
// one n + ik per channel (its colour weight's average) and so one complex b per
// channel and polarisation: |b| in the coefficients, b's phase ψ added to every
// Gaussian's θ_k = 2π·μ_k·opd + ψ. The sign of q = -a|b| carries the π shift.
// u_substrate_nk: n + ik per channel (R, G, B).

float film_channel(int c, float nf, float cos1, float cos2, vec2 r12, float opd_um) {
    vec4 r23 = film_conductor_r23(nf, cos1, cos2, u_substrate_nk[c]);
    float value = 0.0;
    for (int pol = 0; pol < 2; ++pol) {
        vec2 b = pol == 0 ? r23.xy : r23.zw;
        float a = r12[pol];
        float b_abs = length(b);
        float psi = b_abs > 0.0 ? atan(b.y, b.x) : 0.0;
        float q = -a * b_abs;
        float one_minus = max(1.0 - q * q, 1e-30);
        float amp = -(1.0 - a * a) * (1.0 - b_abs * b_abs) / one_minus;
        value += 0.5 * (a * a + b_abs * b_abs - 2.0 * q * q) / one_minus;
        for (int k = 0; k < FILM_GAUSSIANS; ++k) {
            float c1 = cos(TWO_PI * fract(u_film_sens_centre[k][c] * opd_um) + psi);
            float c2 = 2.0 * c1 * c1 - 1.0;
            float c3 = c1 * (2.0 * c2 - 1.0);
            float c4 = 2.0 * c2 * c2 - 1.0;
            float sigma_opd = PI * u_film_sens_sigma[k][c] * opd_um;
            float d1 = exp(-2.0 * sigma_opd * sigma_opd);
            float d4 = (d1 * d1) * (d1 * d1);
            float d9 = d4 * d4 * d1;
            float d16 = d4 * d4 * d4 * d4;
            float terms = q * c1 * d1 + q * q * c2 * d4 + q * q * q * c3 * d9;
            float tail = q * q * q * q * (c4 - q * c3) / max(1.0 - 2.0 * q * c1 + q * q, 1e-12);
            value += u_film_sens_weight[k][c] * amp * (terms + d16 * tail);
        }
    }
    return value;
}

// The base without its film: the bare metal at each channel's n + ik.
vec3 film_base_rgb(Film film, float cos1) {
    cos1 = clamp(cos1, 0.0, 1.0);
    return vec3(film_bare_conductor(cos1, u_substrate_nk[0]),
                film_bare_conductor(cos1, u_substrate_nk[1]),
                film_bare_conductor(cos1, u_substrate_nk[2]));
}

#ifndef STACK_PAIRS  // a stack's layers draw the film instead (lib/thin_film_stack.glsl)
vec3 film_rgb(Film film, float cos1, float d) {
    cos1 = clamp(cos1, 0.0, 1.0);
    float cos2;
    vec2 r12;
    if (!film_top(film.ior, cos1, cos2, r12)) {
        return vec3(1.0);
    }
    float opd_um = 2e-3 * film.ior * d * cos2;
    vec3 rgb = vec3(film_channel(0, film.ior, cos1, cos2, r12, opd_um),
                    film_channel(1, film.ior, cos1, cos2, r12, opd_um),
                    film_channel(2, film.ior, cos1, cos2, r12, opd_um));
    return radiance_floor(rgb);
}
#endif
#endif

#endif
