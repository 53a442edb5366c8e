"""One path for every request: ``prepare`` (scene, one resolve, limits, key, canonical URL)
and ``produce`` (render and encode), shared by HTTP, the CLI, batches, turntables,
exports and the Python API."""
