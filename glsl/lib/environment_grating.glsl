// A grating's orders read from the map (docs/design.md §4.5). Order m at wavelength λ is
// a lobe about the light l whose shifted sum k_m = l + v − (mλ/d)·b lies along n: in the
// frame (t, b, n), l = (−v_t, q − v_b, √(1 − v_t² − (q − v_b)²)) with q = mλ/d. Every
// order at every wavelength leaves along one curve, l_t = −v_t, l_b = b ∈ (−r, r),
// r = √(1 − v_t²); at b it is order m's at λ = d·|b + v_b|/m. Over a lobe narrower than
// the map's features an order reflects the map's radiance there times its albedo
//   ∫ η_m·F·D(h_m)·(v·h_m)/(|k_m|²·max(n·l, n·v))·(n·l) dω_l ≈ η_m(λ)·F(n·v)·(n·v)/max(n·l, n·v)
// (dω_l = |k_m|²/(l·h_m)·dω_h and ∫ D dω_h ≈ 1 about h_m = n), so the map is read at
// ENV_GRATING_READS pieces of the curve, each at its middle and over its stretch Δb,
// and each read lights every order that falls there with the spectrum's weight over the
// wavelengths of that stretch, λ ∈ d·(|b + v_b| ± Δb/2)/m, from the visible density's
// integral: the same closed form over the spectrum as the fast path's lights
// (lib/grating.glsl), and a cost that does not grow with the tier's wavelengths. The
// mirror order is one read. Each pixel and pass cuts the curve at its own offset (fixed
// cuts drew the pieces' colours as rings), and once more where its two halves join.
// Float64 twin: opaline/model/grating_environment.py. Included by
// lib/environment_light.glsl (ENV_GRATING_ORDERS) after env_lookup and env_lod_footprint.
#ifndef ENVIRONMENT_GRATING_GLSL
#define ENVIRONMENT_GRATING_GLSL

// The map's radiance toward l (shading frame) over what its read stands for: the lobe's
// solid angle in l, lobe_h·|k|²/(n·l) (k = (n·l + n·v)·n at the peak), widened by a
// strip `gap` long along b.
vec3 grating_read(Environment env, realmat3 frame, vec3 l, float nv, float lobe_h, float gap) {
    float k = l.z + nv;
    float lobe_l = lobe_h * k * k / max(l.z, EPS_DENOM);
    vec3 m = env_to_map(env, vec3(frame * real3(l)));
    return env_lookup(env, m, env_lod_footprint(env, m, lobe_l + gap * sqrt(lobe_l)));
}

// Order m's weight at a stretch of the curve |b + v_b| ∈ q ± half: over each half of its
// wavelengths, the spectrum's weight times η_m at that half's middle (η changes across a
// stretch: at one point a stretch, 8 reads cut at offset 0 were 11 % off under a constant
// map, at two 3 %).
vec3 grating_stretch(Material mat, int m, float q, float half_q, float kn) {
    float per_nm = mat.grating.pitch_nm / float(m);
    float lo = per_nm * (q - half_q);
    float mid = per_nm * q;
    float hi = per_nm * (q + half_q);
    if (hi <= 380.0 || lo >= 780.0) {
        return vec3(0.0);  // no visible wavelength (and no Bessel series at a tiny λ)
    }
    vec3 at_mid = visible_cumulative(mid);
    float depth = mat.grating.depth_nm;
    // η's wavelengths held in the visible range, where the weights are (a half outside it
    // weighs 0, and a tiny λ would overflow the series).
    vec2 lam = clamp(0.5 * vec2(lo + mid, mid + hi), 380.0, 780.0);
    return (at_mid - visible_cumulative(lo)) * grating_efficiency(m, lam.x, kn, depth)
           + (visible_cumulative(hi) - at_mid) * grating_efficiency(m, lam.y, kn, depth);
}

// Every order's weight at a stretch q ± half of the curve.
vec3 grating_orders_at(Material mat, float q, float half_q, float kn) {
    vec3 w = grating_stretch(mat, 1, q, half_q, kn);
#if GRATING_ORDERS >= 2
    w += grating_stretch(mat, 2, q, half_q, kn);
#endif
#if GRATING_ORDERS >= 3
    w += grating_stretch(mat, 3, q, half_q, kn);
#endif
#if GRATING_ORDERS >= 4
    w += grating_stretch(mat, 4, q, half_q, kn);
#endif
#if GRATING_ORDERS >= 5
    w += grating_stretch(mat, 5, q, half_q, kn);
#endif
#if GRATING_ORDERS >= 6
    w += grating_stretch(mat, 6, q, half_q, kn);
#endif
#if GRATING_ORDERS >= 7
    w += grating_stretch(mat, 7, q, half_q, kn);
#endif
#if GRATING_ORDERS >= 8
    w += grating_stretch(mat, 8, q, half_q, kn);
#endif
    return w;
}

// The lobe's half-width along b in l (the box of its Gaussian's variance, √3·|k|/√ey):
// a wavelength's light comes from that far either side of its order's direction.
float grating_widen(Material mat, float kn) {
    return sqrt(3.0) * kn / sqrt(mat.ey + 1.0);
}

// Boundary i of the pieces, along the two stretches laid end to end: the cuts at
// (k − offset)·step before the join, the join (the end of the first stretch), the rest.
float grating_cut(int i, int join, float len_plus, float len_all, float step_b, float offset) {
    if (i == join) {
        return len_plus;
    }
    float k = float(i < join ? i : i - 1) - offset;
    return clamp(k * step_b, 0.0, len_all);
}

vec3 environment_grating(Material mat, Environment env, realmat3 frame, vec3 v) {
    vec3 vl = vec3(transpose(frame) * real3(v));
    if (vl.z <= 0.0) {
        return vec3(0.0);
    }
    float lobe_h = TWO_PI / sqrt((mat.ex + 1.0) * (mat.ey + 1.0));  // 1/D at the peak
    float depth = mat.grating.depth_nm;
    vec3 eta0 = vec3(grating_efficiency(0, mat.grating.channel_nm.r, 2.0 * vl.z, depth),
                     grating_efficiency(0, mat.grating.channel_nm.g, 2.0 * vl.z, depth),
                     grating_efficiency(0, mat.grating.channel_nm.b, 2.0 * vl.z, depth));
    vec3 sum = eta0 / max(vl.z, EPS_DENOM) * grating_read(env, frame, vec3(-vl.xy, vl.z), vl.z, lobe_h, 0.0);
    // Where on the curve an order is seen, b + v_b ∈ ±[380/d, M·780/d] and a lobe's reach
    // about it, within the horizon |b| < r: two stretches (q = ±(b + v_b) on each), laid
    // end to end and cut every `step` from an offset, and once more where the first ends:
    // ENV_GRATING_READS + 2 pieces cover both, none across the join, and the reads move
    // with v, never jumping from one stretch to the other.
    float r = sqrt(max(1.0 - vl.x * vl.x, 0.0));
    float reach = grating_widen(mat, 1.0 + vl.z);
    vec2 q_range = vec2(380.0, float(GRATING_ORDERS) * 780.0) / mat.grating.pitch_nm
                   + vec2(-reach, reach);
    vec2 plus = clamp(q_range - vl.y, -r, r);
    vec2 minus = clamp(-q_range.yx - vl.y, -r, r);
    float len_plus = plus.y - plus.x;
    float len_all = len_plus + minus.y - minus.x;
    float step_b = max(len_all, 1e-6) / float(ENV_GRATING_READS);
    // Each pixel and pass cuts them at its own offset (a pass steps it by 1/φ): where
    // they met in one place for every pixel, the pieces' colours drew rings.
    float offset = fract(env_pixel_shift().x + float(env.pass) * 0.6180339887);
    int join = int(floor(len_plus / step_b + offset)) + 1;  // the cuts up to the join
    for (int j = 0; j < ENV_GRATING_READS + 2; ++j) {
        vec2 piece = vec2(grating_cut(j, join, len_plus, len_all, step_b, offset),
                          grating_cut(j + 1, join, len_plus, len_all, step_b, offset));
        float half_b = 0.5 * (piece.y - piece.x);
        if (half_b <= 0.0) {
            continue;  // the first or last piece, or a stretch, empty
        }
        bool on_plus = piece.x < len_plus;
        float b = on_plus ? plus.x + piece.x + half_b : minus.x + piece.x - len_plus + half_b;
        vec3 l = vec3(-vl.x, b, sqrt(max(r * r - b * b, 0.0)));
        float kn = l.z + vl.z;
        // The read lights the wavelengths whose lobes reach its piece, each by the share
        // of its lobe there: a trapezoid, taken as the piece where the lobe is the
        // narrower (the presets'), as the lobe's box scaled to the piece's share where it
        // is the wider.
        float half_q = max(half_b, grating_widen(mat, kn));
        vec3 w = grating_orders_at(mat, on_plus ? b + vl.y : -(b + vl.y), half_q, kn)
                 * (half_b / half_q);
        if (w != vec3(0.0) && l.z > 0.0) {
            sum += w / max(l.z, vl.z) * grating_read(env, frame, l, vl.z, lobe_h, 2.0 * half_b);
        }
    }
    return radiance_floor(mat.ks * material_fresnel(mat, vl.z) * vl.z * sum);
}

#endif
