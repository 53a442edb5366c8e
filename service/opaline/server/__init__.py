"""The HTTP service: routes, errors, query models, the render queue and workers,
the image cache, metrics and the tuning page."""
