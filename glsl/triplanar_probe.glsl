//! defines:
// Test harness: each pixel projects one (object position, normal) case through
// lib/triplanar.glsl, reading one map whose rgb is a tangent-space normal map and
// alpha a scalar field: rgb out the blended object-space normal, alpha the blended
// scalar, to hold against opaline.model.projection.sample.
#include "fullscreen.glsl"

#ifdef FRAGMENT_SHADER
#include "lib/frame.glsl"
#include "lib/triplanar.glsl"

uniform sampler2D u_position;
uniform sampler2D u_normal;
uniform sampler2D u_map;
out vec4 frag_color;

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec3 q = texelFetch(u_position, px, 0).xyz;
    vec3 n = safe_normalize(texelFetch(u_normal, px, 0).xyz);
    vec3 w = triplanar_weights(n);
    // Level 0: neighbouring cases are unrelated, so implicit derivatives mean nothing.
    vec4 x = textureLod(u_map, triplanar_uv_x(q), 0.0);
    vec4 y = textureLod(u_map, triplanar_uv_y(q), 0.0);
    vec4 z = textureLod(u_map, triplanar_uv_z(q), 0.0);
    frag_color = vec4(triplanar_whiteout(x.xyz, y.xyz, z.xyz, n, w),
                      w.x * x.a + w.y * y.a + w.z * z.a);
}
#endif
