// Object-space (triplanar) projection of a preset's maps onto a mesh without UVs:
// three planar lookups along the object axes, blended by the normal. The float64
// twin and the reasons (plane layout, sharpness, scale, the whiteout blend after
// Barré-Brisebois and Hill 2012 in Golus's 2017 triplanar form) are in
// service/opaline/model/projection.py.
#ifndef TRIPLANAR_GLSL
#define TRIPLANAR_GLSL

// |n|^4, normalised: a fixed sharpness. A zero normal gets equal thirds.
vec3 triplanar_weights(vec3 n) {
    vec3 w = n * n;
    w *= w;
    float total = w.x + w.y + w.z;
    return total > 1e-30 ? w / total : vec3(1.0 / 3.0);
}

// Along x the plane (z, y), along y (x, z), along z (x, y): the side planes keep v up.
vec2 triplanar_uv_x(vec3 q) { return q.zy; }
vec2 triplanar_uv_y(vec3 q) { return q.xz; }
vec2 triplanar_uv_z(vec3 q) { return q.xy; }

// Each plane's tangent-space normal (tx, ty, tz) whiteout-blended with the object-space
// normal n, then weighted: a unit object-space normal (zero if the blend cancels).
vec3 triplanar_whiteout(vec3 tx, vec3 ty, vec3 tz, vec3 n, vec3 w) {
    tx = vec3(tx.xy + n.zy, abs(tx.z) * n.x);
    ty = vec3(ty.xy + n.xz, abs(ty.z) * n.y);
    tz = vec3(tz.xy + n.xy, abs(tz.z) * n.z);
    vec3 blended = tx.zyx * w.x + ty.xzy * w.y + tz * w.z;
    float d = dot(blended, blended);
    return d > 1e-30 ? blended * inversesqrt(d) : vec3(0.0);
}

#endif
