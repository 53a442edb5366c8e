// Shared constants and the `real` type.
// `real` is double in the PRECISE_PHASE variant (the MDF plot and the BRDF
// probe): the multi-peak phase mu_f·r reaches 3e4 cycles at the top of the
// ranges, where fp32 loses ~1e-3 cycles in the phase and ~0.07 cycles in the
// frame and half vector. Scenes use float (their pixel footprint there spans
// many cycles); trig always runs in float.
#ifndef COMMON_GLSL
#define COMMON_GLSL

#define PI 3.14159265358979323846
#define TWO_PI 6.28318530717958647692
#define EPS_DENOM 1e-4

// A colour of luminance at or below 0 is no radiance (a fast path's fit ringing, an
// estimator's negative pass): black. A channel below 0 under a luminance above 0 is a
// colour outside sRGB, kept for the display's gamut map. Twin: model/color_space.py.
vec3 radiance_floor(vec3 c) {
    return dot(c, vec3(0.2126, 0.7152, 0.0722)) > 0.0 ? c : vec3(0.0);
}
#define EPS_HALF 1e-6

#ifdef PRECISE_PHASE
#define real double
#define real2 dvec2
#define real3 dvec3
#define realmat3 dmat3
#else
#define real float
#define real2 vec2
#define real3 vec3
#define realmat3 mat3
#endif

#endif
