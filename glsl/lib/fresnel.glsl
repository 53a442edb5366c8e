// Schlick 1994: F = f0 + (1 - f0)(1 - cos θ)^5. Compiled in only when f0 < 1.
#ifndef FRESNEL_GLSL
#define FRESNEL_GLSL

uniform float u_f0;

float fresnel_schlick(float cos_theta) {
    float m = 1.0 - clamp(cos_theta, 0.0, 1.0);
    float m2 = m * m;
    return u_f0 + (1.0 - u_f0) * m2 * m2 * m;
}

#endif
