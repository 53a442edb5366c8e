// Thin-film colour (docs/physics.md §1): Airy reflectance of a film of index
// film.ior and thickness d (nm) on a substrate of index film.substrate_ior, under
// air, at cos θ1 = v·h. Real indices make the Fresnel amplitudes a = r12 and
// b = r23 real and signed (the sign is the interface's 0 or π phase shift):
//   R(φ) = (a² + b² + 2ab·cos φ) / (1 + a²b² + 2ab·cos φ),  φ = 4π·n·d·cos θ2/λ,
// averaged over s and p; total internal reflection gives 1. Under a conductor
// (SUBSTRATE_CONDUCTOR) the index below is complex, n + ik, and so is b: the same
// sum is exact with b·cos φ replaced by Re(b·e^{iφ}) (b's phase adds to the film's).
// Float64 twin: opaline/model/thinfilm.py. The film comes in as a Film (mat.film,
// lib/material.glsl). Contract: the program declares, before this file, the tables
//   float u_wavelength_nm[WAVELENGTHS];           with WAVELENGTHS > 0
//   vec3 u_film_sens_weight[FILM_GAUSSIANS], u_film_sens_centre[…], u_film_sens_sigma[…];
//                                                 with WAVELENGTHS = 0 (see film_rgb)
//   vec2 u_substrate_nk[WAVELENGTHS, or 3 for R, G, B];  with SUBSTRATE_CONDUCTOR
// With STACK_PAIRS the film is a stack of that many periods, each a layer of film.ior over
// a spacer (lib/thin_film_stack.glsl). What the surface reflects is film_layer_rgb: the
// film over its base, by film.weight
// (KHR iridescenceFactor) where FILM_WEIGHT is compiled in (a weight below 1), else the
// film alone, as before the weight existed.
#ifndef THIN_FILM_GLSL
#define THIN_FILM_GLSL
#include "lib/common.glsl"
#include "lib/material.glsl"

// A fragment's thickness in nm from what its caller knows: its thickness field's value,
// or negative (the probe, a surface without a field) for the maximum, as in KHR.
float film_thickness_nm(Film film, float film_nm) {
    return film_nm >= 0.0 ? film_nm : film.thickness_max;
}

float film_ratio(float num, float den) {
    return num / (abs(den) > 1e-30 ? den : 1e-30);
}

// cos²θ in a layer of index n lit from air at cos θ1 (Snell): 1 - sin²θ1/n² as
// (n² - 1 + cos²θ1)/n², since near grazing 1 - cos²θ1 rounds to 1 in float, which would
// turn a film of index 1 into total reflection. Below 0: no light gets through.
float layer_cos_sq(float n, float cos1) {
    return (n * n - 1.0 + cos1 * cos1) / (n * n);
}

// The Fresnel amplitude at the interface from a medium (na, cos_a) above into (nb, cos_b)
// below, for s (.x) and p (.y).
vec2 interface_amplitude(float na, float cos_a, float nb, float cos_b) {
    return vec2(film_ratio(na * cos_a - nb * cos_b, na * cos_a + nb * cos_b),
                film_ratio(nb * cos_a - na * cos_b, nb * cos_a + na * cos_b));
}

// Both interfaces for s (.x) and p (.y); false where light cannot get through.
bool film_interfaces(Film film, float cos1, out float cos2, out vec2 r12, out vec2 r23) {
    cos1 = clamp(cos1, 0.0, 1.0);
    float nf = film.ior;
    float ns = film.substrate_ior;
    float cos2_sq = layer_cos_sq(nf, cos1);
    float cos3_sq = layer_cos_sq(ns, cos1);
    cos2 = sqrt(max(cos2_sq, 0.0));
    float cos3 = sqrt(max(cos3_sq, 0.0));
    r12 = interface_amplitude(1.0, cos1, nf, cos2);
    r23 = interface_amplitude(nf, cos2, ns, cos3);
    return cos2_sq > 0.0 && cos3_sq > 0.0;
}

#ifdef SUBSTRATE_CONDUCTOR
#include "lib/thin_film_conductor.glsl"
#else
// The base without its film: the bare substrate's Fresnel reflectance from air, s and p
// averaged, white (the colour weights of both paths sum to 1 per channel). All is
// reflected exactly at grazing, as film_interfaces has it.
vec3 film_base_rgb(Film film, float cos1) {
    cos1 = clamp(cos1, 0.0, 1.0);
    float ns = film.substrate_ior;
    float cos3_sq = layer_cos_sq(ns, cos1);
    vec2 r = interface_amplitude(1.0, cos1, ns, sqrt(max(cos3_sq, 0.0)));
    return vec3(cos1 > 0.0 && cos3_sq > 0.0 ? 0.5 * dot(r, r) : 1.0);
}

#if defined(STACK_PAIRS)
// A stack's layers draw the film (lib/thin_film_stack.glsl, included below).
#elif WAVELENGTHS > 0
float film_airy(float a, float b, float c) {
    float ab = a * b;
    // The numerator cancels to ~0 where a = -b (no interface): rounding may not go negative.
    return max(a * a + b * b + 2.0 * ab * c, 0.0) / max(1.0 + ab * ab + 2.0 * ab * c, 1e-30);
}

// Σ_i w_i·R(λ_i), with the CIE weights of the spectral path (material.glsl).
vec3 film_rgb(Film film, float cos1, float d) {
    float cos2;
    vec2 r12, r23;
    if (!film_interfaces(film, cos1, cos2, r12, r23)) {
        return vec3(1.0);
    }
    float opd = 2.0 * film.ior * d * cos2;  // nm
    vec3 sum = vec3(0.0);
    for (int i = 0; i < WAVELENGTHS; ++i) {
        // φ in cycles, reduced before the cosine: float trig never sees a big argument.
        float cycles = opd / u_wavelength_nm[i];
        float c = cos(TWO_PI * fract(cycles));
        float r = 0.5 * (film_airy(r12.x, r23.x, c) + film_airy(r12.y, r23.y, c));
        sum += u_spectral_weight[i] * r;
    }
    return radiance_floor(sum);  // a channel below 0 is kept to the display's gamut map
}
#else
// Fast path (Belcour & Barla 2017): R(φ) = c0 + 2·Σ_m c_m cos(mφ) with
// c0 = (a² + b² - 2x²)/(1 - x²), c_m = A·q^m, A = -(1-a²)(1-b²)/(1-x²), q = -x,
// x = ab; each cos(mφ) integrated against the colour weights in closed form from
// four Gaussians per channel (FILM_GAUSSIANS) over wavenumber (opaline/model/visible.py):
//   ∫ ŵ cos(2π·m·opd·ν) dν = Σ_k w_k cos(m·θ_k) d_k^(m²),  θ_k = 2π·μ_k·opd,
//   d_k = exp(-2(π·σ_k·opd)²).
// The three terms are evaluated from one cosine and one exponential per Gaussian
// (Chebyshev for cos mθ, powers for d^(m²)), shared by s and p; the terms m > 3,
// which matter near grazing where |q| nears 1, are summed as the geometric series
// Re(z⁴/(1 - z)), z = q·e^{iθ}, damped as the term m = 4. The float64 twin
// (model/thinfilm.py) evaluates the same sums term by term. The tables, per
// Gaussian k and channel: u_film_sens_weight its integral, u_film_sens_centre μ_k
// and u_film_sens_sigma σ_k in µm⁻¹.

vec3 film_rgb(Film film, float cos1, float d) {
    float cos2;
    vec2 r12, r23;
    if (!film_interfaces(film, cos1, cos2, r12, r23)) {
        return vec3(1.0);
    }
    float opd_um = 2e-3 * film.ior * d * cos2;
    vec2 x = r12 * r23;  // (s, p)
    vec2 one_minus = max(1.0 - x * x, 1e-30);
    vec2 c0 = (r12 * r12 + r23 * r23 - 2.0 * x * x) / one_minus;
    vec2 amp = -(1.0 - r12 * r12) * (1.0 - r23 * r23) / one_minus;
    vec2 q = -x;
    vec2 q2 = q * q;
    // Both polarisations averaged: ½·(c0 + 2·Σ A·q^m ...) summed over s and p.
    float w1 = dot(amp, q);
    float w2 = dot(amp, q2);
    float w3 = dot(amp, q2 * q);
    vec2 tail4 = amp * q2 * q2;  // A·q⁴ per polarisation
    vec3 rgb = vec3(0.5 * (c0.x + c0.y));
    for (int k = 0; k < FILM_GAUSSIANS; ++k) {
        vec3 c1 = cos(TWO_PI * fract(u_film_sens_centre[k] * opd_um));
        vec3 c2 = 2.0 * c1 * c1 - 1.0;
        vec3 c3 = c1 * (2.0 * c2 - 1.0);
        vec3 c4 = 2.0 * c2 * c2 - 1.0;
        vec3 sigma_opd = PI * u_film_sens_sigma[k] * opd_um;
        vec3 d1 = exp(-2.0 * sigma_opd * sigma_opd);
        vec3 d4 = (d1 * d1) * (d1 * d1);
        vec3 d9 = d4 * d4 * d1;
        vec3 d16 = d4 * d4 * d4 * d4;
        vec3 terms = w1 * c1 * d1 + w2 * c2 * d4 + w3 * c3 * d9;
        vec3 tail = vec3(0.0);
        for (int pol = 0; pol < 2; ++pol) {
            float qp = q[pol];
            vec3 den = max(1.0 - 2.0 * qp * c1 + qp * qp, 1e-12);
            tail += tail4[pol] * (c4 - qp * c3) / den;
        }
        rgb += u_film_sens_weight[k] * (terms + d16 * tail);
    }
    return radiance_floor(rgb);
}
#endif  // WAVELENGTHS
#endif  // SUBSTRATE_CONDUCTOR
#ifdef STACK_PAIRS
#include "lib/thin_film_stack.glsl"
#endif

// KHR_materials_iridescence's layering: the film's reflectance mixed with its base's by
// the weight (the Sample Viewer mixes the two Fresnel terms by iridescenceFactor). Without
// FILM_WEIGHT (weight 1) the base is not compiled in: a whole film costs what it did.
vec3 film_layer_rgb(Film film, float cos1, float d) {
#ifdef FILM_WEIGHT
    return mix(film_base_rgb(film, cos1), film_rgb(film, cos1, d), film.weight);
#else
    return film_rgb(film, cos1, d);
#endif
}

#endif
