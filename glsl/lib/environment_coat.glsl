// The clear coat's reflection of the environment map (lib/coat.glsl's lobe), by the same
// filtered importance sampling as the material's own (lib/environment_light.glsl):
// COAT_SAMPLES directions a pass drawn from the coat's isotropic A-S lobe, each read at
// the level whose texel spans its share 1/(N·pdf), N = env.coat_total over the pixel's
// passes. A sharp coat, whose one read a pass is already level 0, reads once; a rough one
// as often as the material's own lobe, pooled over the quad below 48 reads a pixel as
// the material's are (COAT_QUAD_MEAN; gl/environment_light.py decides both). The
// brute-force reference draws ENV_SAMPLES at level 0.
// Contract: included by lib/environment_light.glsl where COAT is defined, after the
// quad's mean.
#ifndef ENVIRONMENT_COAT_GLSL
#define ENVIRONMENT_COAT_GLSL
#include "lib/coat.glsl"

#ifndef COAT_SAMPLES
#define COAT_SAMPLES 1
#endif

vec3 environment_coat(Material mat, Environment env, realmat3 frame, vec3 v) {
    vec3 vl = env_view_above(vec3(transpose(frame) * real3(v)));
    // Its own shift of the sequence: drawn with the material's, the coat's directions
    // would follow the base's sample for sample.
    vec3 shift = env_pixel_shift().zxy;
    float exponent = mat.coat.exponent;
    vec3 sum = vec3(0.0);
    for (int i = 0; i < COAT_SAMPLES; ++i) {
        vec4 s = sample_ashikhmin(env_sequence(env.pass * COAT_SAMPLES + i, shift).xy,
                                  exponent, exponent);
        float vh = dot(vl, s.xyz);
        vec3 ll = 2.0 * vh * s.xyz - vl;
        if (vh <= 0.0 || ll.z <= 0.0 || s.w <= 0.0) {
            continue;
        }
        // Drawn from D itself: f·(n·l)/pdf_l = w·F_c(v·h)·(n·l)/max(n·l, n·v).
        float weight = mat.coat.weight * fresnel_schlick(vh, mat.coat.f0)
                       * ll.z / max(max(ll.z, vl.z), EPS_DENOM);
        float pdf_l = s.w / (4.0 * max(vh, EPS_DENOM));
        vec3 m = env_to_map(env, vec3(frame * real3(ll)));
        sum += env_lookup(env, m, env_lod_of(env, m, pdf_l, env.coat_total)) * weight;
    }
    vec3 own = sum / float(COAT_SAMPLES);
#ifdef COAT_QUAD_MEAN
    return mix(own, quad_mean(own), quad_pool_weight(exponent, vec3(frame[2]), v));
#else
    return own;
#endif
}

#endif
