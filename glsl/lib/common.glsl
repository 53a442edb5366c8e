// Shared constants and the `real` type.
// `real` is double in the PRECISE_PHASE variant (the MDF plot): the multi-peak
// phase mu_f·r reaches 3e4 cycles at the top of the ranges, and fp32 would lose
// it to ~1e-3 cycles. Scenes use float; trig always runs in float.
#ifndef COMMON_GLSL
#define COMMON_GLSL

#define PI 3.14159265358979323846
#define TWO_PI 6.28318530717958647692
#define EPS_DENOM 1e-4
#define EPS_HALF 1e-6

#ifdef PRECISE_PHASE
#define real double
#define real2 dvec2
#else
#define real float
#define real2 vec2
#endif

#endif
