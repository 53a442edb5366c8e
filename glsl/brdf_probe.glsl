//! defines: MDF_ASHIKHMIN MDF_MULTIPEAK WAVELENGTHS DIFFUSE FRESNEL PRECISE_PHASE IRIDESCENCE_THIN_FILM IRIDESCENCE_GRATING GRATING_ORDERS BESSEL_TERMS SUBSTRATE_CONDUCTOR FILM_WEIGHT STACK_PAIRS FILM_GAUSSIANS COAT
// Test harness: each pixel shades one (n, t, l, v) case read from float
// textures, through the same reflectance code the surfaces use, so the GLSL
// can be compared with the float64 reference case by case.
#include "fullscreen.glsl"

#ifdef FRAGMENT_SHADER
#include "material_params.glsl"
#include "lib/reflectance.glsl"

uniform sampler2D u_normal;
uniform sampler2D u_tangent;
uniform sampler2D u_light;
uniform sampler2D u_view;
out vec4 frag_color;

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec3 n = texelFetch(u_normal, px, 0).xyz;
    vec3 t = texelFetch(u_tangent, px, 0).xyz;
    vec3 l = texelFetch(u_light, px, 0).xyz;
    vec3 v = texelFetch(u_view, px, 0).xyz;
    frag_color = vec4(reflected_radiance(material_params(), shading_frame(real3(n), real3(t)), l, v, -1.0), 1.0);
}
#endif
