"""Procedural scene assets in NumPy: meshes with tangent frames (mesh, geometry,
waves) and normal maps, named in presets through one argument checker (generators)."""
