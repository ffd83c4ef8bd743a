"""The `path` shading model's samples across viewport redraws, without bpy.

A path frame is the mean of Monte Carlo samples; each sample depends only
on (seed, pixel, sample index), so the viewport renders sample 0 when the
view settles, then samples 1, 2, ... one call each while nothing changes,
and shows the running mean, which equals one call of that many samples
(vxl_path_accumulate in the library; the same formula here, in numpy, on
the worker's result). Any change of the frame (its key) starts again at 0.
F12 renders `path_samples` in one call."""

import numpy as np


def accumulate(mean, img, offset, samples=1):
    """The mean of samples 0 .. offset + samples - 1, from `mean` (of samples
    0 .. offset - 1; ignored when offset is 0) and `img`, the mean of the
    call's samples offset .. offset + samples - 1. Alpha and depth are the
    same in every call, so averaging keeps them."""
    img = np.asarray(img, np.float32)
    if offset <= 0 or mean is None:
        return img.copy()
    w = np.float32(samples / float(offset + samples))
    return (np.asarray(mean, np.float32) + (img - mean) * w).astype(np.float32)


def next_offset(done, target):
    """The sample index the next viewport pass renders, or None when the
    image holds `target` samples (at least 1) already."""
    return done if done < max(1, int(target)) else None
