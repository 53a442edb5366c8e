//! defines:
// The environment behind the object: each pixel looks up the equirectangular
// map (scene/mediancut.py's convention) along its view ray, turned and scaled
// as the lights are, so reflections and background agree.
#include "fullscreen.glsl"

#ifdef FRAGMENT_SHADER
#include "lib/common.glsl"

uniform sampler2D u_environment;  // linear radiance; v = 0 at the nadir, 1 at the zenith
uniform mat4 u_inv_view_proj;
uniform vec2 u_size;
uniform vec2 u_jitter;  // the surface pass's sub-pixel offset, in NDC units
uniform float u_rotation;  // radians the environment is turned about +y
uniform float u_intensity;
uniform float u_lod;  // the mip level environment_blur asks for; 0 is the sharp map

out vec4 frag_color;

void main() {
    // The surface pass shifts the image by the jitter: undo it to find this pixel's ray.
    vec2 ndc = gl_FragCoord.xy / u_size * 2.0 - 1.0 - u_jitter;
    vec4 far = u_inv_view_proj * vec4(ndc, 1.0, 1.0);
    vec4 near = u_inv_view_proj * vec4(ndc, -1.0, 1.0);
    vec3 d = normalize(far.xyz / far.w - near.xyz / near.w);
    float azimuth = atan(d.z, d.x) - u_rotation;
    float elevation = asin(clamp(d.y, -1.0, 1.0));
    vec2 uv = vec2(fract(azimuth / TWO_PI), 0.5 + elevation / PI);
    // Explicit LOD: the azimuth's wrap would otherwise pick a tiny mip along the seam.
    // The map is sampled one level at a time (LINEAR_MIPMAP_NEAREST, for the surface's
    // lobe reads): the blur between two levels is mixed here, as trilinear would.
    float level = floor(u_lod);
    vec3 below = textureLod(u_environment, uv, level).rgb;
    vec3 above = textureLod(u_environment, uv, level + 1.0).rgb;
    frag_color = vec4(mix(below, above, u_lod - level) * u_intensity, 1.0);
}
#endif
