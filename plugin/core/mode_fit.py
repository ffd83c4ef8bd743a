"""Where each render mode starts, fitted to the data (no bpy, tested in
plain Python): the iso value, and the window each projection and the
iso-surface get the first time the user switches to them. Like the presets
(tf_fit), everything is read from the histogram (tf_fit.DataStats), so the
same rules work on 0..130 MR, Hounsfield CT and 0..4000 microscopy.

Why these choices:
  * ISO: Otsu's threshold, the value that best separates the histogram into
    two classes. On a scan in air that is the boundary between air (or the
    zeros around a skull-stripped brain) and tissue, so the surface is the
    object's outside (skin on a head, the body on CT), the first thing a
    person expects to see. A fixed quantile would land inside the tissue
    on one scan and in the noise on the next.
  * ISO's window: the library colours the surface with the transfer
    function at the iso value, so a window that puts the iso value on the
    ramp's transparent foot draws a black surface. The window keeps the
    foreground's width and is slid so the iso value lands on the ramp's
    brightest entry.
  * MIP: a ray's maximum through the object lies among the bright voxels,
    so the window spans the upper half of the foreground, from its median
    to the data's maximum: a window ending at a quantile below the maximum
    turns every ray that meets a voxel above it white (on ch2better, 0.999
    is 121 of 130, and MIP was a white silhouette), while the maximum
    keeps the brightest structures apart.
  * Average: a ray's mean mixes the object with the air around it, so it
    lies between the data's low end and the foreground's median.
  * MinIP: the darkest value along the ray. On a scan surrounded by air
    every ray's minimum is air, so MinIP of an uncropped head would be air
    everywhere. The library's MinIP floor skips samples below a level: it
    starts at Otsu's threshold (the same split between air and tissue as
    the iso value), so each ray's minimum is the darkest tissue it crosses
    (ventricles, sulci), as a viewer's MinIP of a slab shows. Rays that
    cross the object's boundary also pass interpolated samples just above
    the floor, so the window starts at the data's low end, not at the
    floor (there the whole head maps to the ramp's transparent foot), and
    ends at the foreground's median.
"""

import numpy as np

from .tf_fit import never_empty

MODES = ("dvr", "mip", "minip", "average", "iso")
PROJECTIONS = ("mip", "minip", "average")


def otsu(stats):
    """Otsu's threshold of the histogram, in data units: the bin edge that
    maximises the between-class variance. Falls back to the middle of the
    range on a flat or empty histogram."""
    c = np.asarray(stats.counts, np.float64)
    total = c.sum()
    if len(c) < 2 or total <= 0:
        return 0.5 * (stats.lo + stats.hi)
    centres = stats.lo + (np.arange(len(c)) + 0.5) * stats.bin_width
    w0 = np.cumsum(c)[:-1]                 # class 0: bins 0..k
    m0 = np.cumsum(c * centres)[:-1]
    w1 = total - w0
    m1 = (c * centres).sum() - m0
    valid = (w0 > 0) & (w1 > 0)
    if not valid.any():
        return 0.5 * (stats.lo + stats.hi)
    between = np.zeros_like(w0)
    between[valid] = w0[valid] * w1[valid] * (m0[valid] / w0[valid] - m1[valid] / w1[valid]) ** 2
    k = int(np.argmax(between))
    # Empty bins between the classes give them all the same variance: the
    # threshold goes to the middle of that gap (data with nothing between 0
    # and 51 gets 25.5, not 0.1), where the trilinear surface is smoothest.
    end = k
    while end + 1 < len(between) and between[end + 1] >= between[k] * (1.0 - 1e-9):
        end += 1
    return float(stats.lo + (0.5 * (k + end) + 1) * stats.bin_width)


def iso_value(stats):
    """The iso value an import starts with: Otsu's threshold, kept strictly
    inside the data range so the surface exists."""
    v = otsu(stats)
    span = stats.hi - stats.lo
    return float(min(max(v, stats.lo + 1e-3 * span), stats.hi - 1e-3 * span))


def minip_floor(stats):
    """MinIP's floor: the background's level, below which samples are not
    candidates for a ray's minimum (Otsu's threshold, as iso_value)."""
    return iso_value(stats)


def brightest_position(table):
    """Position 0..1 of the table's brightest visible entry (largest
    luminance among entries with some opacity; the brightest of all when
    none is visible). `table`: (n, 4) straight RGBA."""
    t = np.asarray(table, np.float64)
    lum = t[:, :3] @ np.array([0.2126, 0.7152, 0.0722])
    visible = t[:, 3] > 0
    if visible.any():
        lum = np.where(visible, lum, -1.0)
    return float(np.argmax(lum)) / max(len(t) - 1, 1)


def window(mode, stats, iso=None, table=None):
    """(low, high), the window `mode` starts with on data described by
    `stats` (tf_fit.DataStats). iso: the iso value (ISO); table: the
    ramp sampled to (n, 4) (ISO: where its brightest colour is). None for
    DVR, whose window is the preset's (tf_fit.place)."""
    if mode == "mip":
        return never_empty(stats.level(0.5), stats.hi)
    if mode in ("minip", "average"):
        return never_empty(stats.lo, stats.level(0.5))
    if mode == "iso":
        iso = iso_value(stats) if iso is None else float(iso)
        width = stats.level(0.995) - stats.level(0.0)
        if not width > 0:
            width = max(stats.hi - stats.lo, 1e-6)
        t = 0.75 if table is None else brightest_position(table)
        lo = iso - t * width
        return never_empty(lo, lo + width)
    return None


def projection_table(table):
    """A projection draws one sample per ray, but a ramp made for volume
    rendering holds opacity per unit of path (its most opaque entry is often
    a quarter), which leaves MIP a faint veil. Scaled so the most opaque
    entry is opaque, the ramp keeps its colours and the shape of its
    opacity. `table`: (n, 4) straight RGBA; returns a new float32 array."""
    t = np.array(table, np.float32, copy=True)
    top = float(t[:, 3].max()) if len(t) else 0.0
    if top > 0:
        t[:, 3] = np.minimum(t[:, 3] / top, 1.0)
    return t
