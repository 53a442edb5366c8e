// One triangle that covers the viewport, from gl_VertexID alone (no buffers).
#ifndef FULLSCREEN_GLSL
#define FULLSCREEN_GLSL
#ifdef VERTEX_SHADER
void main() {
    vec2 corner = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));
    gl_Position = vec4(corner * 2.0 - 1.0, 0.0, 1.0);
}
#endif
#endif
