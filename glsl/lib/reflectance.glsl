// Ashikhmin-Shirley reflectance around the paper's MDF (docs/design.md §1.5):
//   f_c = kd·albedo_c/π + ks·D_c(h)·F(v·h) / (4·(v·h)·max(n·l, n·v))
// under a clear coat where one is compiled in (lib/coat.glsl),
// returned already multiplied by max(n·l, 0), i.e. radiance per unit irradiance.
#ifndef REFLECTANCE_GLSL
#define REFLECTANCE_GLSL
#include "lib/common.glsl"
#include "lib/frame.glsl"
#include "lib/material.glsl"
#if defined(IRIDESCENCE_THIN_FILM)
#include "lib/thin_film.glsl"
#elif defined(IRIDESCENCE_GRATING)
#include "lib/grating.glsl"
#endif

#ifdef IRIDESCENCE_THIN_FILM
#ifdef FILM_PER_PIXEL
// Environment light evaluates the film once per pixel (lib/environment_light.glsl).
vec3 g_film_colour;
vec3 film_colour(Material mat, float vh, float film_nm) {
    return g_film_colour;
}
#else
vec3 film_colour(Material mat, float vh, float film_nm) {
    return film_layer_rgb(mat.film, vh, film_thickness_nm(mat.film, film_nm));
}
#endif
#endif

// film_nm: the thin film's thickness here (negative: the material's maximum, as KHR's
// without a thickness texture); not read by the other sources.
vec3 specular(Material mat, realmat3 frame, vec3 l, vec3 v, float film_nm) {
#ifdef IRIDESCENCE_GRATING
    return mat.ks * grating_specular(mat, frame, l, v);
#else
    real3 sum_lv = real3(l) + real3(v);
    real len = length(sum_lv);
    // l = -v: no half vector, no specular.
    if (len <= EPS_HALF) {
        return vec3(0.0);
    }
    real3 h = sum_lv / len;
    real3 hl = transpose(frame) * h;  // (h·t, h·b, h·n)
    float vh = float(dot(real3(v), h));
#ifdef IRIDESCENCE_THIN_FILM
    // The unrotated lobe, coloured by the film instead of by rotation (Fresnel off).
    vec3 d = mdf_ashikhmin(hl.xy, float(hl.z), mat.ex, mat.ey) * film_colour(mat, vh, film_nm);
#else
    vec3 d = mdf_color(mat, hl.xy, float(hl.z));
#endif
    float nl = float(dot(frame[2], real3(l)));
    float nv = float(dot(frame[2], real3(v)));
    return mat.ks * d * microfacet_factor(mat, vh, nl, nv);
#endif
}

vec3 reflected_radiance(Material mat, realmat3 frame, vec3 l, vec3 v, float film_nm) {
    vec3 f = specular(mat, frame, l, v, film_nm);
#ifdef DIFFUSE
    f += mat.kd * mat.albedo / PI;
#endif
#ifdef COAT
    f = f * coat_keep(mat.coat, float(dot(frame[2], real3(v)))) + coat_specular(mat.coat, frame, l, v);
#endif
    return f * max(float(dot(frame[2], real3(l))), 0.0);
}

#endif
