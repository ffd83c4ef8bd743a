"""The panel's histogram picture (no bpy, tested in plain Python).

Two parts, one image, row 0 = bottom (Blender's pixel order):
  * top: the histogram over the window only, on a log scale, so its x axis
    is the ColorRamp's drawn right above it (position 0 = window low,
    1 = window high); bars take the ramp's colour there, and the ramp's
    opacity is drawn over them as a white curve;
  * bottom strip: the whole data range (log scale), the window's span lit
    and its low and high ends marked with yellow lines.
"""

import numpy as np

BACKGROUND = (0.16, 0.16, 0.16, 1.0)
OUTSIDE = (0.10, 0.10, 0.10, 1.0)    # window parts beyond the data range
BAR = (0.62, 0.62, 0.62)
MARK = (1.0, 0.85, 0.2, 1.0)         # window low / high in the overview strip
CURVE = (1.0, 1.0, 1.0, 1.0)


def _cumulative(counts, lo, hi):
    """x -> voxels below x, linear within the histogram's bins."""
    c = np.asarray(counts, np.float64).ravel()
    edges = np.linspace(lo, hi, len(c) + 1)
    cum = np.concatenate([[0.0], np.cumsum(c)])
    return lambda x: np.interp(x, edges, cum)


def rebin(counts, lo, hi, a, b, n):
    """Voxel counts of `counts` (equal bins over [lo, hi]) in n equal bins
    over [a, b], assuming voxels spread evenly within a bin."""
    cum = _cumulative(counts, lo, hi)
    return np.diff(cum(np.linspace(a, b, n + 1)))


def value_step(counts, lo, hi):
    """The spacing of the values the data takes (integer data in fine bins
    fills only every k-th bin), 0 when bins are filled densely; bars
    narrower than this would alternate with empty ones."""
    occupied = np.nonzero(np.asarray(counts).ravel() > 0)[0]
    if len(occupied) < 3:
        return 0.0
    gap = float(np.median(np.diff(occupied)))
    return gap * (hi - lo) / len(np.asarray(counts).ravel()) if gap > 1 else 0.0


def _bars(counts, lo, hi, a, b, width):
    """Counts per image column over [a, b], in bars no narrower than the
    data's value step."""
    step = value_step(counts, lo, hi)
    n = width if step <= 0 else int(np.clip((b - a) / step, 8, width))
    per_bar = rebin(counts, lo, hi, a, b, n)
    return per_bar[(np.arange(width) * n) // width]


def _log_heights(v, rows):
    v = np.log1p(np.maximum(v, 0.0))
    top = v.max()
    return np.zeros(len(v)) if top <= 0 else v / top * rows


def render(counts, lo, hi, window_low, window_high, table=None, width=256, height=224,
           strip=40):
    """(height, width, 4) float32 RGBA. `table` is the ramp sampled (n, 4)
    over the window (colours of the bars, opacity curve), or None."""
    img = np.empty((height, width, 4), np.float32)
    img[:] = BACKGROUND
    wl, wh = sorted((float(window_low), float(window_high)))
    if not wh > wl:
        wh = wl + max(abs(wl), 1.0) * 1e-6
    main_rows = height - strip - 2
    base = strip + 2
    x_centres = wl + (np.arange(width) + 0.5) / width * (wh - wl)

    # top: the window, aligned with the ramp
    outside = (x_centres < lo) | (x_centres > hi)
    img[base:, outside] = OUTSIDE
    hts = _log_heights(_bars(counts, lo, hi, wl, wh, width), main_rows)
    if table is not None:
        t = np.asarray(table, np.float64)
        pos = np.linspace(0.0, 1.0, len(t))
        u = (np.arange(width) + 0.5) / width
        rgb = np.stack([np.interp(u, pos, t[:, c]) for c in range(3)], axis=1)
        alpha = np.interp(u, pos, t[:, 3])
        bar = 0.35 * np.asarray(BAR) + 0.65 * rgb  # dark ramp colours stay visible
    else:
        alpha = None
        bar = np.tile(BAR, (width, 1))
    rows = np.arange(main_rows)[:, None]
    filled = rows < np.round(hts)[None, :]
    region = img[base:]
    region[filled] = np.concatenate([np.broadcast_to(bar, (main_rows, width, 3))[filled],
                                     np.ones((int(filled.sum()), 1))], axis=1)
    if alpha is not None and alpha.max() > 0:
        y = np.clip(np.round(alpha / alpha.max() * (main_rows - 1)), 0, main_rows - 1).astype(int)
        for dy in (0, 1):  # two pixels thick
            region[np.clip(y + dy, 0, main_rows - 1), np.arange(width)] = CURVE

    # bottom: the whole data range, the window lit and its ends marked
    span_lo, span_hi = min(lo, wl), max(hi, wh)
    if not span_hi > span_lo:
        span_hi = span_lo + 1.0
    full = _log_heights(_bars(counts, lo, hi, span_lo, span_hi, width), strip)
    xs = span_lo + (np.arange(width) + 0.5) / width * (span_hi - span_lo)
    lit = (xs >= wl) & (xs <= wh)
    srows = np.arange(strip)[:, None]
    sfilled = srows < np.round(full)[None, :]
    shade = np.where(lit, 0.85, 0.45)[None, :]
    strip_img = img[:strip]
    strip_img[:] = OUTSIDE
    strip_img[..., :3] = np.where(sfilled[..., None], shade[..., None] * np.ones(3), strip_img[..., :3])
    for col in mark_columns(lo, hi, wl, wh, width):
        img[:strip, col] = MARK
    return img


def mark_columns(lo, hi, window_low, window_high, width=256):
    """The overview strip's columns of window low and high (for tests)."""
    wl, wh = sorted((float(window_low), float(window_high)))
    span_lo, span_hi = min(lo, wl), max(hi, wh)
    if not span_hi > span_lo:
        span_hi = span_lo + 1.0
    return [int(np.clip(np.floor((v - span_lo) / (span_hi - span_lo) * width), 0, width - 1))
            for v in (wl, wh)]
