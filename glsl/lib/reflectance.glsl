// Ashikhmin-Shirley reflectance around the paper's MDF (DESIGN §1):
//   f_c = kd·albedo_c/π + ks·D_c(h)·F(v·h) / (4·(v·h)·max(n·l, n·v))
// returned already multiplied by max(n·l, 0), i.e. radiance per unit irradiance.
#ifndef REFLECTANCE_GLSL
#define REFLECTANCE_GLSL
#include "lib/common.glsl"
#include "lib/frame.glsl"
#include "lib/material.glsl"
#ifdef FRESNEL
#include "lib/fresnel.glsl"
#endif

uniform float u_ks;
#ifdef DIFFUSE
uniform float u_kd;
uniform vec3 u_albedo;
#endif

vec3 specular(mat3 frame, vec3 l, vec3 v) {
    vec3 sum_lv = l + v;
    float len = length(sum_lv);
    // l = -v: no half vector, no specular.
    if (len <= EPS_HALF) {
        return vec3(0.0);
    }
    vec3 h = sum_lv / len;
    vec3 hl = transpose(frame) * h;  // (h·t, h·b, h·n)
    vec3 d = mdf_color(real2(hl.xy), hl.z);
    float vh = dot(v, h);
    float nl = dot(frame[2], l);
    float nv = dot(frame[2], v);
#ifdef FRESNEL
    float f = fresnel_schlick(vh);
#else
    float f = 1.0;
#endif
    float denom = 4.0 * max(vh, EPS_DENOM) * max(max(nl, nv), EPS_DENOM);
    return u_ks * d * (f / denom);
}

vec3 reflected_radiance(mat3 frame, vec3 l, vec3 v) {
    vec3 f = specular(frame, l, v);
#ifdef DIFFUSE
    f += u_kd * u_albedo / PI;
#endif
    return f * max(dot(frame[2], l), 0.0);
}

#endif
