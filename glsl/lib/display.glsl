// Display encoding after exposure (resolve.glsl): tone map, sRGB transfer (IEC 61966-2-1).
#ifndef DISPLAY_GLSL
#define DISPLAY_GLSL

#if defined(TONEMAP_NEUTRAL)
// Khronos PBR Neutral (KhronosGroup/ToneMapping, PBR_Neutral): an offset of F90, the
// Fresnel of an IoR 1.5 dielectric, makes a white-lit base colour in 0.08 … 0.8 come out
// exactly; a peak above KS is compressed toward 1 and mixed toward white, in the plane of
// the colour and the grey axis, so its hue about that axis is kept.
const float NEUTRAL_F90 = 0.04;
const float NEUTRAL_KS = 0.8 - NEUTRAL_F90;
const float NEUTRAL_KD = 0.15;

vec3 tonemap_neutral(vec3 x) {
    float low = min(x.r, min(x.g, x.b));
    x -= low <= 2.0 * NEUTRAL_F90 ? low - low * low / (4.0 * NEUTRAL_F90) : NEUTRAL_F90;
    float peak = max(x.r, max(x.g, x.b));
    if (peak <= NEUTRAL_KS) return x;
    float d = 1.0 - NEUTRAL_KS;
    float new_peak = 1.0 - d * d / (peak + d - NEUTRAL_KS);
    float g = 1.0 / (NEUTRAL_KD * (peak - new_peak) + 1.0);
    return mix(vec3(new_peak), x * (new_peak / peak), g);
}
#endif

vec3 tonemap(vec3 x) {
    x = max(x, vec3(0.0));
#if defined(TONEMAP_NEUTRAL)
    return tonemap_neutral(x);
#elif defined(TONEMAP_REINHARD)
    return x / (1.0 + x);
#elif defined(TONEMAP_ACES)
    // Narkowicz 2015 fit of the ACES filmic curve.
    return clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
#else
    return clamp(x, 0.0, 1.0);
#endif
}

vec3 srgb_encode(vec3 x) {
    x = clamp(x, 0.0, 1.0);
    vec3 lo = 12.92 * x;
    vec3 hi = 1.055 * pow(x, vec3(1.0 / 2.4)) - 0.055;
    return mix(hi, lo, lessThanEqual(x, vec3(0.0031308)));
}

#endif
