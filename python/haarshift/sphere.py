"""Lat-long (equirectangular) maps rotated, integrated and multiplied through their Haar
coefficients: `rotate`, `integrate`, `product`.

A map is (H, 2H) or (H, 2H, C), H a power of two; row i is the elevation from +Y (up),
column j the azimuth. See `haarshift sphere rotate --help` for the conventions in full.
"""
from ._native import sphere as _sphere

rotate = _sphere.rotate
integrate = _sphere.integrate
product = _sphere.product

__all__ = ["integrate", "product", "rotate"]
