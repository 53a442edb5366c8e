"""The GL renderer: headless contexts (EGL, OSMesa), shader composition and
variants, uniforms, the camera, and the renderer that owns one context."""
