// Eq. 2 of Kang et al. 2014: rotate the projected half vector counter-clockwise.
// `cs` is (cos θ, sin θ), computed once per channel on the CPU in float64.
#ifndef ROTATION_GLSL
#define ROTATION_GLSL
#include "lib/common.glsl"

real2 rotate_half(real2 h, real2 cs) {
    return real2(cs.x * h.x - cs.y * h.y, cs.y * h.x + cs.x * h.y);
}

#endif
