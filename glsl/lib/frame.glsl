// Orthonormal shading frame (t, b, n) from a normal and a tangent field.
// The tangent is Gram-Schmidt'ed against n; where it is (nearly) parallel to n,
// as at sphere poles or under a steep normal map, any perpendicular is used.
// A zero normal (degenerate geometry) stays zero instead of becoming NaN: the
// frame then has no n, so nothing is reflected, as in the reference.
#ifndef FRAME_GLSL
#define FRAME_GLSL
#include "lib/common.glsl"

real3 safe_normalize(real3 x) {
    real d = dot(x, x);
    return d > 1e-30 ? x * inversesqrt(d) : real3(0.0);
}

realmat3 shading_frame(real3 n, real3 t) {
    n = safe_normalize(n);
    t = t - n * dot(n, t);
    real len = length(t);
    if (len > 1e-6) {
        t /= len;
    } else {
        real3 axis = abs(n.x) < 0.9 ? real3(1.0, 0.0, 0.0) : real3(0.0, 1.0, 0.0);
        t = safe_normalize(cross(n, axis));
    }
    // A short remainder (t nearly along n) is mostly cancellation error: a second
    // projection makes it perpendicular to working precision ("twice is enough").
    t = safe_normalize(t - n * dot(n, t));
    return realmat3(t, cross(n, t), n);
}

#endif
