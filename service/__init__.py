"""Opaline: headless previews of iridescent materials (Kang, Lee, Cho 2014)."""

__version__ = "0.1.0"
