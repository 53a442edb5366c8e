// Schlick 1994: F = f0 + (1 - f0)(1 - cos θ)^5. Compiled in only when f0 < 1.
#ifndef FRESNEL_GLSL
#define FRESNEL_GLSL

float fresnel_schlick(float cos_theta, float f0) {
    float m = 1.0 - clamp(cos_theta, 0.0, 1.0);
    float m2 = m * m;
    return f0 + (1.0 - f0) * m2 * m2 * m;
}

#endif
