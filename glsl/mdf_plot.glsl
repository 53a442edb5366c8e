//! defines: MDF_ASHIKHMIN MDF_MULTIPEAK WAVELENGTHS PRECISE_PHASE AA_ANALYTIC
// The paper's Figs. 2, 3, 6, 7: D over the projected half-vector disc.
// Pixel centres are hx, hy in (-1, 1), +hy up; R, G, B use rotations 0, θ1, θ2
// (or the spectral sum); zero outside the unit disc. Linear float output.
#include "fullscreen.glsl"

#ifdef FRAGMENT_SHADER
#include "material_params.glsl"

uniform int u_size;
out vec4 frag_color;

void main() {
    real2 h = (real2(ivec2(gl_FragCoord.xy)) + 0.5) / real(u_size) * 2.0 - 1.0;
    real s2 = h.x * h.x + h.y * h.y;
    if (s2 >= 1.0) {
        frag_color = vec4(0.0, 0.0, 0.0, 1.0);
        return;
    }
    float hz = float(sqrt(1.0 - s2));
    frag_color = vec4(mdf_color(material_params(), h, hz), 1.0);
}
#endif
