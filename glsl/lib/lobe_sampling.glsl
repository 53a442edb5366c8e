// Directions drawn from the material's own lobe, for environment light (docs/design.md
// §4.6). Each returns a half vector in the shading frame (hx, hy, hz) and its density
// per unit solid angle of h. Float64 twin: opaline/model/lobe_sampling.py.
//  * Ashikhmin-Shirley (eq. 1): their closed-form sampler, whose density is exactly
//    eq. 1's D(h) (Ashikhmin & Shirley 2000, §3): φ from the exponents' ratio, then
//    hz = (1 - u)^(1 / (ex cos²φ + ey sin²φ + 1)).
//  * Multi-peak (eqs. 3-4): D ≤ hz, so its envelope is sampled, h uniform over the
//    projected disc (density hz/π), and the rings come in through the weight D/pdf.
#ifndef LOBE_SAMPLING_GLSL
#define LOBE_SAMPLING_GLSL
#include "lib/common.glsl"
#include "lib/mdf_ashikhmin.glsl"

// 1 - exp(t) for t ≤ 0 without cancellation near 0 (GLSL has no expm1): the A-S lobe at
// exponents ~1e6 lives at 1 - hz ~ 1e-6, where 1 - exp(t) in float keeps one digit.
float one_minus_exp(float t) {
    return t > -1e-3 ? -t * (1.0 + t * (0.5 + t / 6.0)) : 1.0 - exp(t);
}

vec4 sample_ashikhmin(vec2 u, float ex, float ey) {
    // u.x picks a quadrant and a place in it; the first quadrant's φ is mirrored into it.
    float q = min(u.x * 4.0, 3.99999);
    float quadrant = floor(q);
    float f = q - quadrant;
    // φ = atan(k·tan a), a = ½π·f, k = √((ex + 1)/(ey + 1)), as their paper writes it; its
    // cosine and sine are (cos a, k·sin a) normalised, which spares a sample atan's, tan's
    // and φ's own cosine and sine (the twin keeps the paper's form).
    float a = 0.5 * PI * f;
    vec2 cs = vec2(cos(a), sqrt((ex + 1.0) / (ey + 1.0)) * sin(a));
    cs *= inversesqrt(dot(cs, cs));
    // Into quadrant 1 as π − φ, 2 as π + φ, 3 as 2π − φ.
    float c = quadrant == 1.0 || quadrant == 2.0 ? -cs.x : cs.x;
    float s = quadrant >= 2.0 ? -cs.y : cs.y;
    float e = ex * c * c + ey * s * s;
    float t = log(max(1.0 - u.y, 1e-30)) / (e + 1.0);
    float one_minus_hz = one_minus_exp(t);
    float sin_h = sqrt(max(one_minus_hz * (2.0 - one_minus_hz), 0.0));
    vec3 h = vec3(sin_h * c, sin_h * s, 1.0 - one_minus_hz);
    // D(h) = norm·hz^e with hz = exp(t): exp(e·t), without eq. 1's logarithm again.
    return vec4(h, sqrt((ex + 1.0) * (ey + 1.0)) / TWO_PI * exp(e * t));
}

vec4 sample_projected_disc(vec2 u) {
    float r = sqrt(u.x);
    float phi = TWO_PI * u.y;
    vec2 xy = r * vec2(cos(phi), sin(phi));
    float hz = sqrt(max(1.0 - u.x, 0.0));
    return vec4(xy, hz, hz / PI);
}

#endif
