// The sum-of-sines heightfield of the wavy sheet, h(x, z) = Σ a·sin(k·(d·(x, z)) + φ),
// evaluated per fragment: its exact slope, where the mesh's interpolated vertex normals
// are only as good as the mesh is fine. Float64 twin: opaline/scene/waves.py.
#ifndef WAVES_GLSL
#define WAVES_GLSL

// Per wave, in object space: (k·dx, k·dz, amplitude, phase), k = 2π/wavelength.
uniform vec4 u_waves[WAVES];

// (∂h/∂x, ∂h/∂z) at the object-space point (x, z).
vec2 wave_slope(vec2 xz) {
    vec2 slope = vec2(0.0);
    for (int i = 0; i < WAVES; ++i) {
        vec4 wave = u_waves[i];
        slope += wave.z * cos(dot(wave.xy, xz) + wave.w) * wave.xy;
    }
    return slope;
}

#endif
