// Orthonormal shading frame (t, b, n) from a normal and a tangent field.
// The tangent is Gram-Schmidt'ed against n; where it is (nearly) parallel to n,
// as at sphere poles or under a steep normal map, any perpendicular is used.
#ifndef FRAME_GLSL
#define FRAME_GLSL

mat3 shading_frame(vec3 n, vec3 t) {
    n = normalize(n);
    t = t - n * dot(n, t);
    float len = length(t);
    if (len > 1e-6) {
        t /= len;
    } else {
        vec3 axis = abs(n.x) < 0.9 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 1.0, 0.0);
        t = normalize(cross(n, axis));
    }
    return mat3(t, cross(n, t), n);
}

#endif
