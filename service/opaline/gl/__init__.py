"""The GL renderer: headless contexts (EGL, OSMesa), shader composition and
variants, uniforms, the camera, the framebuffers and scenes kept on the GPU, and
the renderer that owns one context (with its MDF plot and BRDF probe)."""
