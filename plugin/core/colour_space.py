"""sRGB <-> scene-linear (IEC 61966-2-1) for the add-on's colours.

Blender keeps colours scene-linear (ColorRamp stops, colour properties,
float images, lights), and so does the library in the add-on's renders
(VXL_COLOR_SPACE_LINEAR). Colours from elsewhere are display-referred and
are decoded once, where they come in: the presets' tables (tf_presets), the
label tables' colours (FreeSurfer LUT, ITK-SNAP), 8-bit sRGB images. The
viewport, which draws in display colour, encodes the library's image back
(viewport.py's shader, the same formula)."""

import numpy as np


def srgb_to_linear(c):
    """sRGB-encoded values (clamped to [0, 1]) -> linear, float32."""
    c = np.clip(np.asarray(c, np.float32), 0.0, 1.0)
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4).astype(np.float32)


def linear_to_srgb(c):
    """Linear values (clamped to [0, 1]) -> sRGB-encoded, float32."""
    c = np.clip(np.asarray(c, np.float32), 0.0, 1.0)
    return np.where(c <= 0.0031308, c * 12.92, 1.055 * c ** (1 / 2.4) - 0.055).astype(np.float32)


def rgba_to_linear(rgba):
    """A colour with alpha (rgba, straight): its RGB decoded, alpha kept, as
    a tuple of floats (what a Blender colour property takes)."""
    rgb = srgb_to_linear(np.asarray(rgba[:3], np.float32))
    return tuple(float(v) for v in rgb) + tuple(float(v) for v in rgba[3:])
