//! defines:
// Adds one sample's image into the accumulation buffer (blending ONE, ONE).
#include "fullscreen.glsl"

#ifdef FRAGMENT_SHADER
uniform sampler2D u_sample;
out vec4 frag_color;

void main() {
    frag_color = texelFetch(u_sample, ivec2(gl_FragCoord.xy), 0);
}
#endif
