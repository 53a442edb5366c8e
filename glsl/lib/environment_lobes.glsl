// The colour terms environment light weighs its lobe samples by, where they are not the
// ordinary reflectance of lib/reflectance.glsl (docs/design.md §4.5): the rotation
// source's paper channels, the multi-peak lobe's envelope and bands. Included by
// lib/environment_light.glsl after its Environment, g_env_lobes and
// environment_irradiance.
#ifndef ENVIRONMENT_LOBES_GLSL
#define ENVIRONMENT_LOBES_GLSL

#ifdef ENV_RGB_LOBES
// The rotation source's map samples in the paper's own colour (eq. 2): one lobe for each
// channel, turned by 0, θ1, θ2, the very lobes the mixture draws from (their values at
// the sample, g_env_lobes, are its density's terms), so a sample's weight D_c/pdf stays
// under 3. Set below 48 samples a pixel (gl/environment_light.py): there the
// 16-wavelength colour cost 3× as much a sample and measured no closer to the spectral
// brute-force reference (FLIP 0.106 either way at 6 samples), while the spectral lobe
// is still what lights (the preset's, a map's bright features) evaluate.
vec3 specular_rgb_lobes(Material mat, float vh, float nl, float nv) {
    vec3 d = g_env_lobes;
    return mat.ks * d * microfacet_factor(mat, vh, nl, nv) * nl;
}
#endif

#ifdef ENV_ENVELOPE
// The multi-peak lobe under an environment, D(λ, h) = ½·hz + ½·hz·band(λ, h). Float64
// twin: opaline/model/envelope.py, which says why and what it measured.
// * The envelope ½·hz, the same at every wavelength and as wide as the hemisphere: its
//   albedo A(n·v) times the map's mean radiance about d = n + ½·r (normalised, r the
//   mirror direction), the irradiance E(d)/π of the diffuse term's nine coefficients.
// * The bands, which carry the colour: lobe samples, their spectrum shared among a
//   pass's samples (sample i carries wavelengths i, i + ENV_SAMPLES, …: a pass costs one
//   spectral evaluation, as one light does), each band box-filtered over the share of
//   the disc its wavelength's samples stand for. None are drawn (ENV_SAMPLES 0) when
//   that filter leaves them under 5 % of the envelope anywhere on the lobe.
// * The bands' mean over the disc moves to the envelope (½·hz·(1 + mean)), the samples
//   carry band − mean: near mu_f = 0 the band is a constant 1 that few samples a
//   wavelength drew as colour noise over a smooth lobe.
uniform float u_env_band_mean;

vec3 specular_bands(Material mat, vec3 hl, float vh, float nl, float nv, int first,
                    float cell) {
    vec3 d = vec3(0.0);
    for (int i = first; i < WAVELENGTHS; i += max(ENV_SAMPLES, 1)) {
        d += u_spectral_weight[i] * (multipeak_band_cell(
            rotate_half(real2(hl.xy), u_spectral_rotation[i]), mat.mu_f, mat.alpha, mat.beta, cell)
            - u_env_band_mean);
    }
    return mat.ks * (0.5 * hl.z) * d * microfacet_factor(mat, vh, nl, nv) * nl;
}

// ∫ ½·hz·F/(4·v·h·max(n·l, n·v))·n·l dω: (π/8)·(2 − n·v), and with Schlick's F a fit to
// its (1 − v·h)⁵ part (envelope.SCHLICK_FIT).
float envelope_albedo(Material mat, float nv) {
    float plain = PI / 8.0 * (2.0 - nv);
#ifdef FRESNEL
    float x = 1.0 - nv;
    float schlick = ((((((1.42818824 * x - 3.31018136) * x + 3.11136970) * x - 1.31620555)
                      * x + 0.267333428) * x - 0.0174354895) * x + 0.000192833728);
    return mat.f0 * plain + (1.0 - mat.f0) * schlick;
#else
    return plain;
#endif
}

vec3 specular_envelope(Material mat, Environment env, vec3 n, vec3 v) {
    float nv = clamp(dot(n, v), 0.0, 1.0);
    vec3 d = normalize(n + 0.5 * (2.0 * dot(n, v) * n - v));
    return mat.ks * envelope_albedo(mat, nv) * (1.0 + u_env_band_mean)
           * environment_irradiance(env, d) / PI;
}
#endif

#endif
