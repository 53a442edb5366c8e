"""Encoding images (PNG 8/16-bit, linear .npy) and writing files atomically."""
