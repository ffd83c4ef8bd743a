"""Conversions between window depth (what an OpenGL depth buffer holds,
0..1) and the library's depth convention: view-space planar distance along
-Z of the view, +inf where there is nothing.

Pure numpy (no bpy) so the maths is unit-tested outside Blender. Valid for
every projection Blender makes (perspective, orthographic, with lens shift):
their third and fourth rows do not depend on view x and y, so NDC z is a
function of view z alone.
"""

import numpy as np


def _rows(proj):
    p = np.asarray(proj, dtype=np.float64).reshape(4, 4)
    return p[2, 2], p[2, 3], p[3, 2], p[3, 3]


def window_to_planar(window_depth, proj):
    """Window depth in [0, 1] (1 = far plane / cleared) -> planar distance."""
    p22, p23, p32, p33 = _rows(proj)
    win = np.asarray(window_depth, dtype=np.float64)
    ndc = win * 2.0 - 1.0
    with np.errstate(divide="ignore", invalid="ignore"):
        z = (p23 - ndc * p33) / (ndc * p32 - p22)  # view-space z (negative in front)
    dist = -z
    cleared = (win >= 1.0) | ~np.isfinite(dist) | (dist < 0)
    return np.where(cleared, np.inf, dist).astype(np.float32)


def planar_to_ndc(distance, proj):
    """Planar distance -> NDC z; +inf maps beyond the far plane."""
    p22, p23, p32, p33 = _rows(proj)
    z = -np.asarray(distance, dtype=np.float64)
    with np.errstate(divide="ignore", invalid="ignore"):
        ndc = (p22 * z + p23) / (p32 * z + p33)
    return ndc


def planar_to_window(distance, proj):
    """Planar distance -> window depth in [0, 1]; +inf (no hit) -> 1."""
    d = np.asarray(distance, dtype=np.float64)
    ndc = planar_to_ndc(np.where(np.isfinite(d), d, 0.0), proj)
    win = np.clip(ndc * 0.5 + 0.5, 0.0, 1.0)
    return np.where(np.isfinite(d), win, 1.0).astype(np.float32)
