//! defines: TWO_SIDED MDF_ASHIKHMIN MDF_MULTIPEAK WAVELENGTHS DIFFUSE FRESNEL NORMAL_MAP TANGENT_CONCENTRIC OBJECT_PROJECTION LIGHT_COUNT AA_ANALYTIC IRIDESCENCE_THIN_FILM IRIDESCENCE_GRATING GRATING_ORDERS BESSEL_TERMS THICKNESS_MAP TRANSMISSION WAVES DISPLAY TONEMAP_REINHARD TONEMAP_ACES ENVIRONMENT_MAP ENV_SAMPLES ENV_BRUTE ENV_ENVELOPE ENV_RGB_LOBES ENV_GRATING_ORDERS ENV_GRATING_READS ENV_BACKDROP FILM_PER_PIXEL TONEMAP_NEUTRAL SUBSTRATE_CONDUCTOR FILM_WEIGHT STACK_PAIRS FILM_GAUSSIANS COAT FILM_WEIGHT_MAP TRANSFER_BT709 ENV_QUAD_MEAN COAT_SAMPLES COAT_QUAD_MEAN
// A lit mesh with the iridescent material. Outputs linear radiance with alpha 1
// (coverage), accumulated over jittered samples by the renderer.

#ifdef VERTEX_SHADER
in vec3 in_position;
in vec3 in_normal;
in vec3 in_tangent;
in vec2 in_uv;

uniform mat4 u_model;
uniform mat3 u_normal_matrix;
uniform mat4 u_view_proj;
uniform vec2 u_jitter;  // sub-pixel offset in NDC units

out vec3 v_world;
out vec3 v_object;
out vec3 v_normal;
out vec3 v_tangent;
out vec2 v_uv;
#ifdef OBJECT_PROJECTION
out vec3 v_object_normal;
#endif

// Every variant compiles this code with other defines, and the all-features
// baseline is compared with the scene's own variant pixel for pixel: all of them
// must rasterise exactly the same coverage.
invariant gl_Position;

void main() {
    vec4 world = u_model * vec4(in_position, 1.0);
    v_world = world.xyz;
    v_object = in_position;
    v_normal = u_normal_matrix * in_normal;
    v_tangent = mat3(u_model) * in_tangent;
    v_uv = in_uv;
#ifdef OBJECT_PROJECTION
    v_object_normal = in_normal;
#endif
    vec4 clip = u_view_proj * world;
    clip.xy += u_jitter * clip.w;
    gl_Position = clip;
}
#endif

#ifdef FRAGMENT_SHADER
#include "material_params.glsl"
#include "lib/reflectance.glsl"
#ifdef ENVIRONMENT_MAP
#include "environment_params.glsl"
#endif

in vec3 v_world;
in vec3 v_object;
in vec3 v_normal;
in vec3 v_tangent;
in vec2 v_uv;

uniform vec3 u_eye;
uniform mat4 u_model;
#ifdef LIGHT_COUNT
// The preset's lights, or an environment's: as lights (median cut), or beside its map,
// the bright features split off it (scene/bright.py).
// xyz: position (w = 1, point light) or direction toward the light (w = 0).
uniform vec4 u_light_position[LIGHT_COUNT];
// Irradiance: at unit distance for point lights (falls off as 1/d²).
uniform vec3 u_light_irradiance[LIGHT_COUNT];
#endif
#if defined(DIFFUSE) && !defined(ENVIRONMENT_MAP)
uniform vec3 u_ambient;
#endif
#ifdef DISPLAY
// One sample straight into the 8-bit target (draft): encoded here as resolve.glsl
// would encode a single covering sample.
#include "lib/display.glsl"
uniform float u_exposure;
#endif
#ifdef NORMAL_MAP
uniform sampler2D u_normal_map;  // tangent-space unit normals, float RGB
// log2 of the sample target's scale over the image (1 when drawn at 2×): the map is
// filtered over an image pixel's footprint however finely the pixel is sampled.
uniform float u_lod_bias;
#endif
#if defined(IRIDESCENCE_THIN_FILM) && defined(THICKNESS_MAP)
uniform sampler2D u_thickness_map;  // [0, 1] → [min, max] nm, as KHR's thickness texture
#endif
#if defined(IRIDESCENCE_THIN_FILM) && defined(FILM_WEIGHT_MAP)
uniform sampler2D u_weight_map;  // [0, 1], times film_weight: KHR's iridescenceTexture
#endif
#ifdef WAVES
#include "lib/waves.glsl"
uniform mat3 u_normal_matrix;
#endif
#ifdef OBJECT_PROJECTION
// A mesh without UVs takes the maps by object-space projection (lib/triplanar.glsl).
#include "lib/triplanar.glsl"
in vec3 v_object_normal;
// xyz: the bounds' minimum corner, w: one over the longest side (one tile across it).
uniform vec4 u_projection;
#ifndef WAVES
uniform mat3 u_normal_matrix;
#endif
#endif
#if defined(IRIDESCENCE_THIN_FILM) && defined(TRANSMISSION)
uniform vec3 u_backdrop;  // linear radiance that displays as the background colour
#endif

out vec4 frag_color;

vec3 tangent_field() {
#ifdef TANGENT_CONCENTRIC
    // Along the tracks of a disc lying in the object's xz plane: perpendicular
    // to the radius, so the highlight strips curve as in the paper's Fig. 9.
    return mat3(u_model) * vec3(-v_object.z, 0.0, v_object.x);
#else
    return v_tangent;
#endif
}

void main() {
    vec3 n = v_normal;
    if (dot(n, n) < 1e-20) {
        n = vec3(0.0, 1.0, 0.0);  // zero-area triangles can interpolate to nothing
    }
    vec3 t = tangent_field();
#ifdef WAVES
    // The heightfield's own normal and tangent (dP/dx) here, as waves.py gives them at
    // the vertices: exact at any mesh density, so a thumbnail's mesh can be coarse.
    vec2 slope = wave_slope(v_object.xz);
    n = u_normal_matrix * vec3(-slope.x, 1.0, -slope.y);
#ifndef TANGENT_CONCENTRIC
    t = mat3(u_model) * vec3(1.0, slope.x, 0.0);
#endif
#endif
#ifdef OBJECT_PROJECTION
    vec3 q = (v_object - u_projection.xyz) * u_projection.w;
    vec3 object_n = safe_normalize(v_object_normal);
    vec3 w = triplanar_weights(object_n);
#endif
#if defined(NORMAL_MAP) && defined(OBJECT_PROJECTION)
    vec3 projected = triplanar_whiteout(
        texture(u_normal_map, triplanar_uv_x(q), u_lod_bias).xyz,
        texture(u_normal_map, triplanar_uv_y(q), u_lod_bias).xyz,
        texture(u_normal_map, triplanar_uv_z(q), u_lod_bias).xyz, object_n, w);
    if (dot(projected, projected) > 1e-12) {
        n = u_normal_matrix * projected;
    }
#elif defined(NORMAL_MAP)
    vec3 mapped = texture(u_normal_map, v_uv, u_lod_bias).xyz;
    // A zero normal in the map keeps the geometric one.
    if (dot(mapped, mapped) > 1e-12) {
        n = shading_frame(n, t) * normalize(mapped);
    }
#endif
#ifdef TWO_SIDED
    // Seen from behind (the side its normals do not face), a surface is shaded as its
    // front, mirrored: the back of an open sheet was black under every light. The face's
    // own normal from the position's screen derivatives faces the eye; a shading normal
    // on its other side is flipped. (A normal that only leans past the silhouette stays:
    // it is on the face's side.)
    vec3 face = cross(dFdx(v_world), dFdy(v_world));
    if (dot(face, u_eye - v_world) < 0.0) {
        face = -face;
    }
    if (dot(n, face) < 0.0) {
        n = -n;
    }
#endif
    mat3 frame = shading_frame(n, t);
    Material mat = material_params();
#ifdef ENVIRONMENT_MAP
    Environment env = environment_params();
#endif
#if defined(IRIDESCENCE_THIN_FILM) && defined(THICKNESS_MAP) && defined(OBJECT_PROJECTION)
    float film_nm = mix(mat.film.thickness_min, mat.film.thickness_max,
                        w.x * texture(u_thickness_map, triplanar_uv_x(q)).r
                        + w.y * texture(u_thickness_map, triplanar_uv_y(q)).r
                        + w.z * texture(u_thickness_map, triplanar_uv_z(q)).r);
#elif defined(IRIDESCENCE_THIN_FILM) && defined(THICKNESS_MAP)
    float film_nm = mix(mat.film.thickness_min, mat.film.thickness_max,
                        texture(u_thickness_map, v_uv).r);
#else
    float film_nm = -1.0;  // the material's maximum (thin film), else not read
#endif
#if defined(IRIDESCENCE_THIN_FILM) && defined(FILM_WEIGHT_MAP) && defined(OBJECT_PROJECTION)
    mat.film.weight *= w.x * texture(u_weight_map, triplanar_uv_x(q)).r
                       + w.y * texture(u_weight_map, triplanar_uv_y(q)).r
                       + w.z * texture(u_weight_map, triplanar_uv_z(q)).r;
#elif defined(IRIDESCENCE_THIN_FILM) && defined(FILM_WEIGHT_MAP)
    mat.film.weight *= texture(u_weight_map, v_uv).r;
#endif
    vec3 v = normalize(u_eye - v_world);

    vec3 radiance = vec3(0.0);
#ifdef ENVIRONMENT_MAP
    // The map is the whole light (with its bright features below): its irradiance
    // replaces the preset's ambient term. First: it sets the per-pixel film colour.
    radiance = environment_specular(mat, env, frame, v, film_nm);
#ifdef DIFFUSE
    radiance += environment_irradiance(env, vec3(frame[2])) * mat.kd * mat.albedo / PI;
#endif
#endif
#if defined(DIFFUSE) && !defined(ENVIRONMENT_MAP)
    radiance += u_ambient * mat.kd * mat.albedo;
#endif
#if defined(IRIDESCENCE_THIN_FILM) && defined(TRANSMISSION)
    // A free, lossless film transmits what it does not reflect: the backdrop seen
    // through both walls, each met at the view's angle to the surface (the back
    // wall's own thickness is not known: this one's is used).
    vec3 through = vec3(1.0) - film_layer_rgb(mat.film, abs(float(dot(frame[2], v))),
                                           film_thickness_nm(mat.film, film_nm));
#ifdef ENV_BACKDROP
    // The environment behind, straight through the film, where it is the background.
    vec3 behind = env_lookup(env, env_to_map(env, -v), 0.0);
#else
    vec3 behind = u_backdrop;
#endif
    radiance += behind * through * through;
#endif
#ifdef COAT
    // What the coat lets through of all the above, and its own reflection of the map;
    // the lights' reflectance below is layered the same way (lib/reflectance.glsl).
    radiance *= coat_keep(mat.coat, float(dot(frame[2], real3(v))));
#ifdef ENVIRONMENT_MAP
    radiance += environment_coat(mat, env, frame, v);
#endif
#endif
#ifdef LIGHT_COUNT
    for (int i = 0; i < LIGHT_COUNT; ++i) {
        vec4 light = u_light_position[i];
        vec3 to_light = light.xyz - light.w * v_world;
        float dist2 = max(dot(to_light, to_light), 1e-8);
        vec3 l = to_light * inversesqrt(dist2);
        float falloff = light.w > 0.5 ? 1.0 / dist2 : 1.0;
        radiance += u_light_irradiance[i] * falloff * reflected_radiance(mat, frame, l, v, film_nm);
    }
#endif
#ifdef DISPLAY
    frag_color = vec4(display_encode(radiance * u_exposure), 1.0);
#else
    frag_color = vec4(radiance, 1.0);
#endif
}
#endif
