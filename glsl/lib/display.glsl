// Display encoding after exposure (resolve.glsl): tone map, sRGB transfer (IEC 61966-2-1).
#ifndef DISPLAY_GLSL
#define DISPLAY_GLSL

vec3 tonemap(vec3 x) {
    x = max(x, vec3(0.0));
#if defined(TONEMAP_REINHARD)
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
