//! defines: TONEMAP_REINHARD TONEMAP_ACES TONEMAP_NEUTRAL TRANSFER_BT709 TRANSPARENT DOWNSAMPLE_2X
// Averages the accumulated samples and encodes for display: exposure, the output's
// primaries and gamut, tone map, transfer curve; composited over the background unless the output keeps its alpha.
// Rows are written top row first (the reverse of GL's order), so the readback
// is already in image order; an 8-bit target quantises in GL, rounding to nearest.
#include "fullscreen.glsl"

#ifdef FRAGMENT_SHADER
#include "lib/display.glsl"

uniform sampler2D u_accum;
uniform float u_inv_samples;
uniform float u_exposure;
uniform vec3 u_background;  // display-referred, in the output's colour space
uniform int u_height;  // of the target, for the row flip

out vec4 frag_color;

void main() {
    ivec2 texel = ivec2(gl_FragCoord.x, u_height - 1 - int(gl_FragCoord.y));
#ifdef DOWNSAMPLE_2X
    // The samples were drawn at twice the size: this pixel's are a 2×2 block.
    texel *= 2;
    vec4 acc = (texelFetch(u_accum, texel, 0) + texelFetch(u_accum, texel + ivec2(1, 0), 0)
                + texelFetch(u_accum, texel + ivec2(0, 1), 0)
                + texelFetch(u_accum, texel + ivec2(1, 1), 0)) * u_inv_samples;
#else
    vec4 acc = texelFetch(u_accum, texel, 0) * u_inv_samples;
#endif
    float coverage = clamp(acc.a, 0.0, 1.0);
    vec3 straight = coverage > 0.0 ? acc.rgb / coverage : vec3(0.0);
    vec3 display = display_encode(straight * u_exposure);
#ifdef TRANSPARENT
    frag_color = vec4(display, coverage);
#else
    frag_color = vec4(mix(u_background, display, coverage), 1.0);
#endif
}
#endif
