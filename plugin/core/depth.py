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


def downsample(img, w, h):
    """Nearest sample at the centre of each (w, h) pixel of a (H, W) image."""
    H, W = img.shape[:2]
    if (W, H) == (w, h):
        return img
    ys = np.minimum(((np.arange(h) + 0.5) * H / h).astype(np.int64), H - 1)
    xs = np.minimum(((np.arange(w) + 0.5) * W / w).astype(np.int64), W - 1)
    return np.ascontiguousarray(img[ys][:, xs])


def for_library(planar, near, far, quantum, rect=None):
    """The scene depth as the library is given it, reduced to what can
    change the image, so that the frame key (a hash of it) changes only
    when the image would:
      * depth at or beyond `far` (the box's farthest planar distance) stops
        no ray inside the box: +inf;
      * depth at or before `near` (the box's nearest, when > 0) stops every
        ray before it enters: 0;
      * outside `rect` (x0, y0, x1, y1), the box's screen footprint, no ray
        meets the box: +inf;
      * the rest is rounded down to a multiple of `quantum` (a fraction of
        a voxel), so a ray stops at most that much earlier and sub-quantum
        wobble of the depth buffer does not re-render.
    The first three are exact; the rounding is not (by < quantum)."""
    d = np.array(planar, dtype=np.float64)
    finite = np.isfinite(d)
    if quantum > 0:
        d[finite] = np.floor(d[finite] / quantum) * quantum
    d[finite & (d >= far)] = np.inf
    if near > 0:
        d[np.isfinite(d) & (d <= near)] = 0.0
    if rect is not None:
        x0, y0, x1, y1 = rect
        mask = np.ones(d.shape, bool)
        mask[y0:y1, x0:x1] = False
        d[mask] = np.inf
    return d.astype(np.float32)
