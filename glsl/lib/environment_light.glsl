// Environment light read from its map, not from lights (docs/design.md §4.6).
// Specular: filtered importance sampling (Křivánek & Colbert, GPU Gems 3 ch. 20). Each
// pass draws ENV_SAMPLES directions from the material's own lobe (lib/lobe_sampling.glsl);
// each sample reads the map's mip level whose texel covers the solid angle the sample
// stands for, 1/(N·pdf), N the pixel's samples over all passes. Few samples then give a
// smooth, slightly widened reflection instead of noise; as N grows the level falls to 0
// and the estimate converges to the integral of the BRDF against the map. ENV_BRUTE
// reads level 0 always: the brute-force reference the benchmark converges.
// Diffuse: the map's irradiance in nine spherical harmonics (Ramamoorthi & Hanrahan
// 2001), exact for a Lambertian term to within ~3 % of the map's irradiance.
// Float64 twins: opaline/model/lobe_sampling.py, opaline/model/irradiance.py.
// The environment comes in as an Environment, filled once per fragment by the program
// (glsl/environment_params.glsl). Contract: the program declares, before this file,
//   sampler2D u_env_map;  linear radiance, equirectangular, v = 1 at the zenith
// (a sampler cannot be a member of a struct variable).
#ifndef ENVIRONMENT_LIGHT_GLSL
#define ENVIRONMENT_LIGHT_GLSL
// A grating order's read at the level whose texel spans its footprint, less this.
#define ENV_FOOTPRINT_BIAS -1.0
#include "lib/reflectance.glsl"
#include "lib/lobe_sampling.glsl"

struct Environment {
    vec2 turn;  // (cos, sin) of the angle the environment is turned about +y
    float intensity;
    vec2 size;  // the map's level 0, texels
    float max_lod;
    int pass;  // this pass's index: passes continue one sequence
    float total;  // the pixel's samples over all passes
    vec2 lobe_rotation[3];  // (cos, sin) of 0, theta1, theta2: the lobes sampled
    vec3 sh[9];  // irradiance coefficients, Â_l and Y_lm's constants folded in
#ifdef COAT
    float coat_total;  // the pixel's coat samples over all passes (lib/environment_coat.glsl)
#endif
};

// The view in the shading frame, at least ENV_MIN_NV above the shading plane. A normal
// interpolated across a silhouette's triangle can face away from the view though the
// triangle faces it: every sample of a glossy lobe then reflected under the surface, and
// the rim of a soap bubble had black pixels among neighbours reflecting the horizon.
#define ENV_MIN_NV 0.02
vec3 env_view_above(vec3 vl) {
    if (vl.z >= ENV_MIN_NV) {
        return vl;
    }
    vec2 across = dot(vl.xy, vl.xy) > 1e-12 ? normalize(vl.xy) : vec2(1.0, 0.0);
    return vec3(across * sqrt(1.0 - ENV_MIN_NV * ENV_MIN_NV), ENV_MIN_NV);
}

// Into the map's own frame (the environment turns, the object stays).
vec3 env_to_map(Environment env, vec3 d) {
    float c = env.turn.x;
    float s = env.turn.y;
    return vec3(c * d.x + s * d.z, d.y, c * d.z - s * d.x);
}

// The fragment's next draw in [0, 1) for choosing a read's level (env_level); below 0
// until the first read sets it from the pixel's hash and the pass.
float g_env_level_draw = -1.0;

// A pixel's own value in [0, 1), independent of env_pixel_shift's three (other constants).
float env_pixel_dither() {
    uvec2 p = uvec2(gl_FragCoord.xy);
    uint h = p.x * 7919u + p.y * 104729u + 15485863u;
    h = (h ^ (h >> 15)) * 0x2c1b3c6du;
    h = (h ^ (h >> 12)) * 0x297a2d39u;
    h ^= h >> 15;
    return float(h >> 8) / 16777216.0;
}

// The level a read takes, floor(lod) or the next, the upper with probability fract(lod):
// in expectation the trilinear read, at one level's bilinear cost (the map is sampled
// LINEAR_MIPMAP_NEAREST, gl/environment_maps.py). A trilinear read cost llvmpipe as much
// as the rest of a lobe sample (bench/speed_env.py). The draws step by 1/φ from the
// pixel's own start, so a pixel's reads spread over [0, 1).
float env_level(Environment env, float lod) {
    if (g_env_level_draw < 0.0) {
        g_env_level_draw = fract(env_pixel_dither() + float(env.pass) * 0.7548776662);
    }
    float level = floor(lod + g_env_level_draw);
    g_env_level_draw = fract(g_env_level_draw + 0.6180339887);
    return level;
}

vec3 env_lookup(Environment env, vec3 m, float lod) {
    float azimuth = atan(m.z, m.x);
    float elevation = asin(clamp(m.y, -1.0, 1.0));
    vec2 uv = vec2(fract(azimuth / TWO_PI), 0.5 + elevation / PI);
    return textureLod(u_env_map, uv, env_level(env, lod)).rgb * env.intensity;
}

// log2 of the side of a solid angle in level-0 texels toward m: a level-0 texel spans
// (2π/W)(π/H)·cos(elevation).
float env_texels_log2(Environment env, vec3 m, float solid_angle) {
    float texel = TWO_PI * PI / (env.size.x * env.size.y)
                  * max(sqrt(max(1.0 - m.y * m.y, 0.0)), 0.5 / env.size.y);
    return 0.5 * log2(max(solid_angle, 1e-30) / texel);
}

// The level whose texel spans a lobe sample's share 1/(N·pdf), N = total.
float env_lod_of(Environment env, vec3 m, float pdf_l, float total) {
#ifdef ENV_BRUTE
    return 0.0;
#else
    // Colbert & Křivánek add 1 (a sample's footprint is wider than its share) for ~40
    // samples; at the tiers' 2-64 a trilinear read of that level is wider than the lobe
    // itself. Measured against the brute-force reference (bench/environment_accuracy.py),
    // FLIP is least at -2 for every tier, map and lobe tried (docs/accuracy.md).
    return clamp(env_texels_log2(env, m, 1.0 / max(total * pdf_l, 1e-30)) - 2.0,
                 0.0, env.max_lod);
#endif
}

// The same for the material's own lobe samples, env.total of them.
float env_lod(Environment env, vec3 m, float pdf_l) {
    return env_lod_of(env, m, pdf_l, env.total);
}

// The level whose texel spans a read's whole footprint (a grating's order); level 0 in
// ENV_BRUTE (which only glsl/lobe_probe.glsl compiles with a grating's orders).
float env_lod_footprint(Environment env, vec3 m, float solid_angle) {
#ifdef ENV_BRUTE
    return 0.0;
#else
    return clamp(env_texels_log2(env, m, solid_angle) + ENV_FOOTPRINT_BIAS, 0.0, env.max_lod);
#endif
}

// Per pixel, a shift of the whole sequence (Cranley-Patterson) from an integer hash:
// neighbours' errors are independent grain. (Interleaved gradient noise, tried, drew
// its diagonal lines across the high-variance lobes of the presets' films.)
vec3 env_pixel_shift() {
    uvec2 p = uvec2(gl_FragCoord.xy);
    uint h = p.x * 1973u + p.y * 9277u + 26699u;
    h = (h ^ (h >> 16)) * 0x45d9f3bu;
    h = (h ^ (h >> 16)) * 0x45d9f3bu;
    h ^= h >> 16;
    return vec3(float(h & 1023u), float((h >> 10) & 1023u), float(h >> 20)) / vec3(1024.0, 1024.0, 4096.0);
}

// Sample k of the pixel: the R2 sequence (Roberts 2018) and a third dimension for the lobe.
// (k + ½)·α mod 1 in 32-bit fixed point (α = 0.7548776662, 0.5698402910, 0.6180339887
// times 2^32): in float, (k + ½)·α keeps 24 - log2(k·α) bits of its fraction, so at
// k = 4096 a point was off by 1e-4 and the brute-force reference's late samples fell
// on a coarse grid (tests/gl/test_environment_twins.py).
vec3 env_sequence(int k, vec3 shift) {
    uvec3 alpha = uvec3(3242174889u, 2447445414u, 2654435769u);
    uvec3 fraction = uint(k) * alpha + (alpha >> 1u);
    return fract(shift + vec3(fraction) * (1.0 / 4294967296.0));
}

#if !defined(MDF_MULTIPEAK) && !defined(IRIDESCENCE_GRATING) && !defined(IRIDESCENCE_THIN_FILM)
// The three channels' lobes at the rotation source's last sample: its density's terms,
// and the paper's colour there (specular_rgb_lobes), evaluated once for both.
vec3 g_env_lobes;
#endif

// A half vector from the lobe and the density of the whole mixture there.
vec4 env_sample_half(Material mat, Environment env, vec3 u) {
#if defined(MDF_MULTIPEAK) || defined(IRIDESCENCE_GRATING)
    // A grating's orders lie away from the mirror direction: its brute-force reference
    // samples the whole disc, and a render reads its orders (ENV_GRATING_ORDERS).
    return sample_projected_disc(u.xy);
#elif defined(IRIDESCENCE_THIN_FILM)
    return sample_ashikhmin(u.xy, mat.ex, mat.ey);
#else
    // Rotation colour: one of the three channels' lobes (each is eq. 1's lobe turned by
    // -θc), chosen at random, weighted by the mixture's density (one-sample MIS).
    int c = int(min(u.z * 3.0, 2.0));
    vec4 s = sample_ashikhmin(u.xy, mat.ex, mat.ey);
    vec2 cs = env.lobe_rotation[c];
    vec3 h = vec3(cs.x * s.x + cs.y * s.y, cs.x * s.y - cs.y * s.x, s.z);
    g_env_lobes = mdf_ashikhmin_three(h.xy, h.z, mat.ex, mat.ey, env.lobe_rotation[0],
                                      env.lobe_rotation[1], env.lobe_rotation[2]);
    return vec4(h, (g_env_lobes.x + g_env_lobes.y + g_env_lobes.z) / 3.0);
#endif
}

vec3 environment_irradiance(Environment env, vec3 n) {
    vec3 d = env_to_map(env, n);
    vec3 e = env.sh[0] + env.sh[1] * d.y + env.sh[2] * d.z + env.sh[3] * d.x
             + env.sh[4] * (d.x * d.y) + env.sh[5] * (d.y * d.z)
             + env.sh[6] * (3.0 * d.z * d.z - 1.0) + env.sh[7] * (d.x * d.z)
             + env.sh[8] * (d.x * d.x - d.y * d.y);
    return max(e, vec3(0.0)) * env.intensity;
}

#include "lib/environment_lobes.glsl"
#ifdef ENV_GRATING_ORDERS
#include "lib/environment_grating.glsl"
#endif

// A lobe sample's weight, f(l, v)·(n·l)/pdf(l); hl the sampled half vector and ll the
// light in the shading frame, i the sample's index in the pass (the bands' share).
vec3 env_sample_weight(Material mat, realmat3 frame, vec3 v, vec3 vl, vec3 hl, vec3 ll,
                       float pdf_l, int i, float cell, float film_nm) {
    float vh = dot(vl, hl);
#if defined(ENV_ENVELOPE)
    return specular_bands(mat, hl, vh, ll.z, vl.z, i, cell) / pdf_l;
#elif defined(ENV_RGB_LOBES)
    return specular_rgb_lobes(mat, vh, ll.z, vl.z) / pdf_l;
#elif defined(FILM_PER_PIXEL)
    // Drawn from the film's own lobe, whose density is D(h): D/pdf is 1 and the lobe is
    // not evaluated again, f·n·l/pdf_l = ks·film·n·l/max(n·l, n·v); the film comes in
    // after the samples (environment_specular).
    return vec3(mat.ks * ll.z / max(max(ll.z, vl.z), EPS_DENOM));
#elif defined(IRIDESCENCE_THIN_FILM)
    return mat.ks * film_colour(mat, vh, film_nm) * (ll.z / max(max(ll.z, vl.z), EPS_DENOM));
#else
    // The view as the sample saw it (env_view_above), back in the world.
    return specular(mat, frame, vec3(frame * real3(ll)), vec3(frame * real3(vl)), film_nm)
           * ll.z / pdf_l;
#endif
}

#if defined(ENV_QUAD_MEAN) || defined(COAT_QUAD_MEAN)
// The mean of a value over the pixel's 2×2 quad, from fine derivatives (each row's and each
// column's own difference; GL's plain dFdx may be the quad's coarse one). The few map
// samples of the rotation source and of a film evaluated once a pixel are independent from
// pixel to pixel, so the quad's four pixels pool theirs: a quarter of the variance, for a
// 2×2 blur of the reflection (the brute-force reference, the lobe probe and the
// shared-nothing tiers compile it out; gl/environment_light.py decides). Twin:
// opaline.model.lobe_sampling.quad_means.
#ifdef GL_ARB_derivative_control
#define QUAD_DX dFdxFine
#define QUAD_DY dFdyFine
#else
#define QUAD_DX dFdx
#define QUAD_DY dFdy
#endif
vec3 quad_mean(vec3 value) {
    // +1 in a quad's left column and bottom row, where the difference is to the next pixel.
    vec2 side = 1.0 - 2.0 * mod(floor(gl_FragCoord.xy), 2.0);
    vec3 row = value + 0.5 * side.x * QUAD_DX(value);
    return row + 0.5 * side.y * QUAD_DY(row);
}

// How much of the quad's mean to take: all of it where the lobe's reflection, at its
// wider width 2/√exponent (the lobe's smaller exponent), spans at least two of the mirror
// direction's steps from pixel to pixel (the pool's blur is then inside the lobe), none
// where it spans one or less (a mirror: every sample reads one direction, and pooling
// only blurs; on the mirror sphere it took FLIP from 0.017 to 0.029).
float quad_pool_weight(float exponent, vec3 n, vec3 v) {
    vec3 r = reflect(-v, n);
    float pixel_step = length(abs(QUAD_DX(r)) + abs(QUAD_DY(r)));
    float lobe_width = 2.0 * inversesqrt(max(exponent, 1.0));
    return clamp(lobe_width / max(pixel_step, 1e-6) - 1.0, 0.0, 1.0);
}
#endif
#ifdef COAT
#include "lib/environment_coat.glsl"
#endif

vec3 environment_specular(Material mat, Environment env, realmat3 frame, vec3 v, float film_nm) {
#ifdef ENV_GRATING_ORDERS
    return environment_grating(mat, env, frame, v);
#else
    vec3 vl = env_view_above(vec3(transpose(frame) * real3(v)));
    vec3 shift = env_pixel_shift();
#ifdef FILM_PER_PIXEL
    vec2 film_at = vec2(0.0);  // Σ luminance·v·h, Σ luminance of the samples' light
#endif
    // The multi-peak bands' filter: a wavelength's samples over the pixel, one a pass.
    float cell = sqrt(PI * float(ENV_SAMPLES) / max(env.total, 1.0));
    vec3 sum = vec3(0.0);
    for (int i = 0; i < ENV_SAMPLES; ++i) {
        vec3 u = env_sequence(env.pass * ENV_SAMPLES + i, shift);
#if ENV_SAMPLES % 3 == 0
        // Each of the rotation source's three lobes gets exactly a third of a pass's
        // samples (multi-sample MIS, balance heuristic: the mixture's density is still
        // the weight): no pass leaves a channel's lobe with one sample or none.
        u.z = (float(i % 3) + 0.5) / 3.0;
#endif
        vec4 s = env_sample_half(mat, env, u);
        float vh = dot(vl, s.xyz);
        vec3 ll = 2.0 * vh * s.xyz - vl;
        if (vh <= 0.0 || ll.z <= 0.0 || s.w <= 0.0) {
            continue;
        }
        // Density of l: dω_h/dω_l = 1/(4 v·h), floored as the reflectance floors it.
        float pdf_l = s.w / (4.0 * max(vh, EPS_DENOM));
        vec3 weight = env_sample_weight(mat, frame, v, vl, s.xyz, ll, pdf_l, i, cell, film_nm);
        vec3 m = env_to_map(env, vec3(frame * real3(ll)));
        vec3 light = env_lookup(env, m, env_lod(env, m, pdf_l)) * weight;
        sum += light;
#ifdef FILM_PER_PIXEL
        float luminance = dot(light, vec3(0.2126, 0.7152, 0.0722));
        film_at += vec2(luminance * vh, luminance);
#endif
    }
#ifdef FILM_PER_PIXEL
    // Once a pixel, at the v·h its light came from (the samples' mean, weighted by what
    // each brought): over a glossy lobe that is n·v, over a broad one it follows the
    // bright parts of the map. The map's bright features use this colour too.
    float vh_film = film_at.y > 0.0 ? film_at.x / film_at.y : vl.z;
    g_film_colour = film_layer_rgb(mat.film, clamp(vh_film, 0.0, 1.0),
                                   film_thickness_nm(mat.film, film_nm));
    sum *= g_film_colour;
#endif
#ifdef ENV_ENVELOPE
    // Each wavelength once a pass: the sum is the pass's estimate of the bands.
    return radiance_floor(sum + specular_envelope(mat, env, vec3(frame[2]), v));
#elif defined(ENV_QUAD_MEAN)
    vec3 own = sum / float(ENV_SAMPLES);
    return mix(own, quad_mean(own), quad_pool_weight(min(mat.ex, mat.ey), vec3(frame[2]), v));
#else
    return sum / float(ENV_SAMPLES);
#endif
#endif
}

#endif
