// Display encoding after exposure (resolve.glsl, a direct draw in surface.glsl): to the
// output's primaries, into its gamut, tone map, its transfer curve. Twins:
// model/color_space.py and model/display.py.
#ifndef DISPLAY_GLSL
#define DISPLAY_GLSL

uniform mat3 u_output_from_srgb;  // linear sRGB to the output's linear primaries
uniform vec3 u_output_luminance;  // each output channel's share of Y

// A colour the output cannot hold (a channel below 0: a film's cyan in sRGB) moves toward
// the grey of its own luminance until no channel is below 0, keeping luminance and hue;
// clipping the channel instead moved hue 4.3° on average on films (bench/gamut.py).
vec3 gamut_map(vec3 x) {
    float y = dot(x, u_output_luminance);
    float low = min(x.r, min(x.g, x.b));
    if (!(y > 0.0)) return vec3(0.0);
    if (low >= 0.0) return x;
    return max(vec3(y) + (x - vec3(y)) * (y / (y - low)), vec3(0.0));
}

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

// The output's transfer curve: sRGB's (sRGB, Display P3) or Rec. 709's OETF (Rec. 2020).
vec3 transfer_encode(vec3 x) {
#ifdef TRANSFER_BT709
    x = clamp(x, 0.0, 1.0);
    vec3 hi = 1.09929682680944 * pow(x, vec3(0.45)) - 0.09929682680944;
    return mix(hi, 4.5 * x, lessThan(x, vec3(0.018053968510807)));
#else
    return srgb_encode(x);
#endif
}

// Exposed linear sRGB radiance to the output's display values.
vec3 display_encode(vec3 linear_srgb) {
    return transfer_encode(tonemap(gamut_map(u_output_from_srgb * linear_srgb)));
}

#endif
