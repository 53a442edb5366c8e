//! defines: MDF_ASHIKHMIN MDF_MULTIPEAK WAVELENGTHS DIFFUSE FRESNEL AA_ANALYTIC IRIDESCENCE_THIN_FILM IRIDESCENCE_GRATING GRATING_ORDERS BESSEL_TERMS ENV_SAMPLES ENV_BRUTE ENV_ENVELOPE ENV_RGB_LOBES ENV_GRATING_ORDERS ENV_GRATING_READS FILM_WEIGHT STACK_PAIRS FILM_GAUSSIANS COAT COAT_SAMPLES
// Test harness for environment light: each pixel runs one case read from float
// textures through lib/lobe_sampling.glsl and lib/environment_light.glsl, so the
// samplers, the irradiance and the estimator can be held against their float64
// twins case by case. u_mode: 0 sample_ashikhmin(a.xy), 1 sample_projected_disc(a.xy),
// 2 env_sample_half(a.xyz): (h, pdf); 3 environment_irradiance(a); 4 one pass of
// environment_specular in the frame (n = a, t = b) toward v = c: (rgb, 1); 5 sample
// k = a.x of env_sequence shifted by b; 6 specular_envelope at n = a toward v = c (the
// ENV_ENVELOPE variant); 7 multipeak_band_cell at h = a.xy over a cell of side b.x;
// 8 one pass of environment_coat in the frame (n = a, t = b) toward v = c (COAT);
// 9 env_lookup toward a (the map's frame) at level b.x, in pass c.x.
// Mode 0 needs the A-S variant (u_ex, u_ey), 7 the multi-peak one.
#include "fullscreen.glsl"

#ifdef FRAGMENT_SHADER
#include "material_params.glsl"
#include "environment_params.glsl"

uniform sampler2D u_case_a;
uniform sampler2D u_case_b;
uniform sampler2D u_case_c;
uniform int u_mode;
out vec4 frag_color;

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec3 a = texelFetch(u_case_a, px, 0).xyz;
    vec3 b = texelFetch(u_case_b, px, 0).xyz;
    vec3 c = texelFetch(u_case_c, px, 0).xyz;
    Material mat = material_params();
    Environment env = environment_params();
    frag_color = vec4(0.0);
#ifdef MDF_ASHIKHMIN
    if (u_mode == 0) {
        frag_color = sample_ashikhmin(a.xy, mat.ex, mat.ey);
    }
#endif
    if (u_mode == 1) {
        frag_color = sample_projected_disc(a.xy);
    } else if (u_mode == 2) {
        frag_color = env_sample_half(mat, env, a);
    } else if (u_mode == 3) {
        frag_color = vec4(environment_irradiance(env, a), 1.0);
    } else if (u_mode == 4) {
        frag_color = vec4(environment_specular(mat, env, shading_frame(a, b), c, -1.0), 1.0);
    } else if (u_mode == 5) {
        frag_color = vec4(env_sequence(int(a.x), b), 1.0);
    } else if (u_mode == 9) {
        env.pass = int(c.x);
        frag_color = vec4(env_lookup(env, a, b.x), 1.0);
    }
#ifdef ENV_ENVELOPE
    if (u_mode == 6) {
        frag_color = vec4(specular_envelope(mat, env, a, c), 1.0);
    }
#endif
#ifdef COAT
    if (u_mode == 8) {
        frag_color = vec4(environment_coat(mat, env, shading_frame(a, b), c), 1.0);
    }
#endif
#ifdef MDF_MULTIPEAK
    if (u_mode == 7) {
        frag_color = vec4(multipeak_band_cell(real2(a.xy), mat.mu_f, mat.alpha, mat.beta, b.x));
    }
#endif
}
#endif
