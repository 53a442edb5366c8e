// Grating colour (docs/physics.md §2): a 1-D reflection grating with grooves along
// the tangent t and grating vector along the bitangent b. Order m at wavelength λ
// is the A-S lobe at h_m = k_m/|k_m|, k_m = l + v - (m·λ/d)·b, weighted by
//   η_m(λ)·F(v·h_m)·(v·h_m) / (|k_m|²·max(n·l, n·v))
// (dω_h/dω_v = (v·h_m)/|k_m|²; for m = 0 this is the usual 1/(4 v·h)), with
// η_m = J_m(a)², a = π·depth·(n·(l+v))/λ, a sinusoidal phase grating's efficiency.
// Float64 twin: opaline/model/grating.py. The grating's parameters come in the
// Material (mat.grating). Contract: the program declares, before this file,
//   float u_wavelength_nm[WAVELENGTHS];         with WAVELENGTHS > 0
//   vec3 u_visible_density[VISIBLE_TABLE];      with WAVELENGTHS = 0: ŵ(λ) per nm,
//                                               380 … 780 nm by 5 nm
#ifndef GRATING_GLSL
#define GRATING_GLSL
#include "lib/common.glsl"
#include "lib/material.glsl"

// GRATING_ORDERS (1-8) is a compile-time define: the orders are written out below,
// and with a literal m the Bessel series' divisors are constants.
#ifndef GRATING_ORDERS
#error "define GRATING_ORDERS"
#elif GRATING_ORDERS > 8
#error "GRATING_ORDERS is at most 8"
#endif
// BESSEL_TERMS (2-16), the series' length the grooves' depth needs (grating.bessel_terms).
#ifndef BESSEL_TERMS
#error "define BESSEL_TERMS"
#elif BESSEL_TERMS > 16
#error "BESSEL_TERMS is at most 16"
#endif
#define EPS_K2 1e-12
#define VISIBLE_TABLE 81  // glsl/material_params.glsl declares the table at this size
// visible.PACKED_VALUE and PACKED_STEP: the ranges the packed table's 16 bits span.
#define VISIBLE_VALUE_LOW -0.5
#define VISIBLE_VALUE_SCALE (2.0 / 65535.0)
#define VISIBLE_STEP_LOW -0.125
#define VISIBLE_STEP_SCALE (0.25 / 65535.0)

// J_m(x) by its power series (x/2)^m/m! · Σ_k (-x²/4)^k·m!/(k!(k+m)!), summed by
// Horner from the last term: a fixed count, no early exit, so it unrolls into
// multiply-adds. Truncation < 1e-9 absolute at the depth's largest x (16 terms reach
// x ≤ 7: depth ≤ 400 nm, λ ≥ 380 nm); fp32 cancellation among the terms loses < 1e-5
// absolute there.
float bessel_j(int m, float x) {
    float half_x = 0.5 * x;
    float lead = 1.0;
    for (int j = 1; j <= m; ++j) {
        lead *= half_x / float(j);
    }
    float y = -half_x * half_x;
    float series = 1.0;
    for (int k = BESSEL_TERMS - 1; k >= 1; --k) {
        series = 1.0 + y * series / float(k * (k + m));
    }
    return lead * series;
}

float grating_efficiency(int m, float lam, float kn, float depth_nm) {
    float j = bessel_j(abs(m), PI * depth_nm * max(kn, 0.0) / lam);
    return j * j;
}

// One order's lobe without η: k = (l+v) in the frame with its b component kb.
float order_lobe(Material mat, vec3 k, vec3 vl, float cos_max) {
    float k2 = max(dot(k, k), EPS_K2);
    float k_len = sqrt(k2);
    vec3 h = k / k_len;
    float vh = dot(vl, h);
    return material_fresnel(mat, vh) * mdf_ashikhmin(h.xy, h.z, mat.ex, mat.ey) * max(vh, 0.0) / (k2 * cos_max);
}

// Whether any order's lobe can be above 0, k = l + v in the frame. Every order's h is k
// shifted along b, normalised: its n component is at most h0, k's with k_b = 0, and eq. 1's
// exponent (ex·hx² + ey·hy²)/(hx² + hy²) is a mean of ex and ey, so each lobe is at most
// its norm times hz^min(ex, ey). mdf_ashikhmin takes hz² as 1 - (hx² + hy²), which its
// rounding may leave up to ~1e-6 above h0² where hz is tiny: the bound uses h0² + 1e-6.
// Under 2^-160 of the norm (11 binades below float's least value) every lobe's exp is 0.
// Where |k| without its b part is under order_lobe's floor, h is not a unit vector and
// the bound does not hold.
bool grating_lobes_reach(Material mat, vec3 k) {
    float across = k.x * k.x + k.z * k.z;
    if (!(across >= EPS_K2)) {
        return true;
    }
    float h0 = k.z * inversesqrt(across);
    return h0 > 0.0 && min(mat.ex, mat.ey) * log2(h0 * h0 + 1e-6) > -320.0;
}

#if WAVELENGTHS > 0
// Orders ±m at one wavelength: J_{-m}² = J_m², so one series serves both signs.
float order_pair(Material mat, int m, float lam, float step_b, vec3 k, vec3 vl, float cos_max) {
    float shift = float(m) * step_b;
    float lobes = order_lobe(mat, vec3(k.x, k.y - shift, k.z), vl, cos_max)
                + order_lobe(mat, vec3(k.x, k.y + shift, k.z), vl, cos_max);
    return grating_efficiency(m, lam, k.z, mat.grating.depth_nm) * lobes;
}

// Σ_i w_i Σ_{|m| ≤ M} η_m(λ_i)·lobe_m(λ_i). The orders are written out, not looped:
// with m a literal the Bessel series' divisors are constants (a loop over m this
// large is not unrolled by Mesa, and its divisions cost a quarter of the draw).
vec3 grating_color_spectral(Material mat, vec3 k, vec3 vl, float cos_max) {
    vec3 sum = vec3(0.0);
    // Off the streak every order's lobe is exactly 0 at every wavelength
    // (grating_lobes_reach): the loop is skipped there, which changes no value, and
    // llvmpipe, which only masks an if, leaves the loop after one pass where no pixel of
    // its block is in it.
    if (grating_lobes_reach(mat, k)) {
        float zero = order_lobe(mat, k, vl, cos_max);  // the mirror order: the same at every λ
        for (int i = 0; i < WAVELENGTHS; ++i) {
            float lam = u_wavelength_nm[i];
            float step_b = lam / mat.grating.pitch_nm;
            float s = grating_efficiency(0, lam, k.z, mat.grating.depth_nm) * zero;
            s += order_pair(mat, 1, lam, step_b, k, vl, cos_max);
#if GRATING_ORDERS >= 2
            s += order_pair(mat, 2, lam, step_b, k, vl, cos_max);
#endif
#if GRATING_ORDERS >= 3
            s += order_pair(mat, 3, lam, step_b, k, vl, cos_max);
#endif
#if GRATING_ORDERS >= 4
            s += order_pair(mat, 4, lam, step_b, k, vl, cos_max);
#endif
#if GRATING_ORDERS >= 5
            s += order_pair(mat, 5, lam, step_b, k, vl, cos_max);
#endif
#if GRATING_ORDERS >= 6
            s += order_pair(mat, 6, lam, step_b, k, vl, cos_max);
#endif
#if GRATING_ORDERS >= 7
            s += order_pair(mat, 7, lam, step_b, k, vl, cos_max);
#endif
#if GRATING_ORDERS >= 8
            s += order_pair(mat, 8, lam, step_b, k, vl, cos_max);
#endif
            sum += u_spectral_weight[i] * s;
        }
    }
    return radiance_floor(sum);
}
#endif

#if WAVELENGTHS == 0 || defined(ENV_GRATING_ORDERS)
// Fast path (and every grating under an environment read from its map, whose
// orders are read in closed form over the spectrum too: lib/environment_grating.glsl):
// each order straight at its wavelength λ_m = d·(l+v)·b/m (Stam 1999),
// the lobe's extent in λ integrated under a Gaussian approximation across the
// grooves: ∫ D dλ ≈ D(h at k_b = 0)·(d/|m|)·|k_0|·√(2π/ey), the colour weight averaged
// over the box of the same variance (Float64 twin: grating.grating_fast).
vec3 visible_density(float lam) {
    float x = (lam - 380.0) / 5.0;
    if (!(x >= 0.0 && x <= float(VISIBLE_TABLE - 1))) {
        return vec3(0.0);
    }
    int i = min(int(floor(x)), VISIBLE_TABLE - 2);
    return mix(u_visible_density[i], u_visible_density[i + 1], x - float(i));
}

// ∫ ŵ(λ) dλ from 380 nm to lam: the cumulative table, linear between its 5 nm points,
// each point packed with its step to the next (visible.packed_cumulative): a read is one
// gather from the uniform array, not two, and on llvmpipe the gathers are most of what a
// grating's orders cost under an environment (docs/speed.md).
vec3 visible_cumulative(float lam) {
    float x = clamp((lam - 380.0) / 5.0, 0.0, float(VISIBLE_TABLE - 1));
    int i = min(int(floor(x)), VISIBLE_TABLE - 2);
    uvec3 point = u_visible_cumulative[i];
    vec3 value = vec3(point >> 16u) * VISIBLE_VALUE_SCALE + VISIBLE_VALUE_LOW;
    vec3 step = vec3(point & 0xffffu) * VISIBLE_STEP_SCALE + VISIBLE_STEP_LOW;
    return value + (x - float(i)) * step;
}

// ŵ averaged over lam ± half (a lobe's extent in λ); the density itself under half a step.
vec3 visible_filtered(float lam, float half_nm) {
    if (half_nm < 2.5) {
        return visible_density(lam);
    }
    return (visible_cumulative(lam + half_nm) - visible_cumulative(lam - half_nm)) / (2.0 * half_nm);
}

vec3 grating_color_visible(Material mat, vec3 k, vec3 vl, float cos_max) {
    vec3 k0 = vec3(k.x, 0.0, k.z);
    float base = order_lobe(mat, k0, vl, cos_max);
    float k0_len = sqrt(max(dot(k0, k0), EPS_K2));
    float width = sqrt(TWO_PI / max(mat.ey, 1.0));
    vec3 sum = vec3(0.0);
    // Off the streak the lobe's power underflows to 0, and every order's term with it:
    // the orders are skipped there, which changes no value, and llvmpipe, which only
    // masks an if, leaves their loop after one pass where no pixel of its block is in it.
    if (base > 0.0) {
        for (int m = 1; m <= GRATING_ORDERS; ++m) {
            float spread = mat.grating.pitch_nm / float(m) * k0_len * width;
            // The colour over the lobe's extent in λ: the box of the Gaussian's variance.
            float half_nm = sqrt(3.0) * mat.grating.pitch_nm / float(m) * k0_len
                            / sqrt(max(mat.ey, 1.0));
            for (int sign = -1; sign <= 1; sign += 2) {
                float lam = float(sign) * mat.grating.pitch_nm * k.y / float(m);
                if (lam + half_nm <= 380.0 || lam - half_nm >= 780.0) {
                    continue;  // outside the visible range (and its lobe's reach): no colour
                }
                vec3 density = visible_filtered(lam, half_nm);
                // η held in the visible range (a tiny λ would overflow the Bessel series).
                float eta = grating_efficiency(m, clamp(lam, 380.0, 780.0), k.z,
                                               mat.grating.depth_nm);
                sum += density * (spread * eta * base);
            }
        }
    }
    float zero = order_lobe(mat, k, vl, cos_max);
    float depth = mat.grating.depth_nm;
    vec3 eta0 = vec3(grating_efficiency(0, mat.grating.channel_nm.r, k.z, depth),
                     grating_efficiency(0, mat.grating.channel_nm.g, k.z, depth),
                     grating_efficiency(0, mat.grating.channel_nm.b, k.z, depth));
    return radiance_floor(sum + zero * eta0);
}
#endif

vec3 grating_specular(Material mat, realmat3 frame, vec3 l, vec3 v) {
    vec3 k = vec3(transpose(frame) * (real3(l) + real3(v)));  // (·t, ·b, ·n)
    vec3 vl = vec3(transpose(frame) * real3(v));
    float nl = float(dot(frame[2], real3(l)));
    float cos_max = max(max(nl, vl.z), EPS_DENOM);
#if WAVELENGTHS == 0 || defined(ENV_GRATING_ORDERS)
    return grating_color_visible(mat, k, vl, cos_max);
#else
    return grating_color_spectral(mat, k, vl, cos_max);
#endif
}

#endif
