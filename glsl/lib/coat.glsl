// A clear coat over the whole material, KHR_materials_clearcoat's layering
// (docs/physics.md §1.5):
//   f = f_base·(1 - w·F_c(n·v)) + w·D_c(h)·F_c(v·h)/(4·(v·h)·max(n·l, n·v)),
// D_c an isotropic Ashikhmin-Shirley lobe. Float64 twin: opaline/model/coat.py.
#ifndef COAT_GLSL
#define COAT_GLSL
#include "lib/common.glsl"
#include "lib/fresnel.glsl"
#include "lib/mdf_ashikhmin.glsl"

struct Coat {
    float weight;  // KHR clearcoatFactor; a coat of 0 is not compiled in
    float f0;  // ((ior - 1)/(ior + 1))²
    float exponent;  // the A-S exponent of its roughness (model/coat.py)
};

// What of the base the coat lets through toward v.
float coat_keep(Coat coat, float nv) {
    return 1.0 - coat.weight * fresnel_schlick(nv, coat.f0);
}

// The coat's own lobe, without the n·l the caller applies; hl the half vector in the
// shading frame.
float coat_lobe(Coat coat, vec3 hl, float vh, float nl, float nv) {
    float d = mdf_ashikhmin(real2(hl.xy), hl.z, coat.exponent, coat.exponent);
    return coat.weight * d * fresnel_schlick(vh, coat.f0)
           / (4.0 * max(vh, EPS_DENOM) * max(max(nl, nv), EPS_DENOM));
}

float coat_specular(Coat coat, realmat3 frame, vec3 l, vec3 v) {
    real3 sum_lv = real3(l) + real3(v);
    real len = length(sum_lv);
    if (len <= EPS_HALF) {
        return 0.0;
    }
    real3 h = sum_lv / len;
    vec3 hl = vec3(transpose(frame) * h);
    return coat_lobe(coat, hl, float(dot(real3(v), h)), float(dot(frame[2], real3(l))),
                     float(dot(frame[2], real3(v))));
}

#endif
