"""Procedural scene assets in NumPy: meshes with tangent frames and normal maps."""
