"""How the viewport lays a volume image rendered at a reduced scale over the
full-resolution view: the maths of the compositing shader in
plugin/viewport.py (_FRAG), in numpy, so that it is tested without Blender
(tests/python/test_upsample.py) and the preview bench
(bench/preview_error.py) models exactly what the artist sees.

Inputs, all with row 0 = bottom as OpenGL reads them:
  * `color` (h, w, 4): the library's premultiplied RGBA at the frame's
    scale (h, w), the whole view at that size;
  * `hit` (h, w): the window depth (0..1) of the volume's hit, 1 where its
    ray hit nothing;
  * `stop` (h, w): the window depth of the scene the frame's rays were
    stopped by (depth.downsample of the window depth: one sample at the
    centre of each frame pixel);
  * `scene` (H, W): the window depth of the scene at full resolution;
  * `proj`, the view's projection, and (near, far), the volume box's planar
    range: depths before near or beyond far change no ray, so they compare
    equal.

Two filters:
  * "nearest" (what the add-on did before): every screen pixel takes its
    frame pixel's colour, and as depth the volume's hit clamped to the
    frame pixel's stop depth. A coarse preview is then blocks, and along a
    mesh silhouette a whole frame pixel takes the colour of rays stopped
    by (or passing) the mesh at its centre: a jagged band, dark where the
    rays were cut short.
  * "bilateral" (joint bilateral upsampling): the four frame pixels around
    the screen pixel, weighted bilinearly, but only those whose rays
    stopped where this pixel's own scene stops (|planar stop - planar
    scene| <= tol, both clamped to the box's range): a ray stopped by a
    nearer mesh lacks the volume behind it, a ray that went past this
    pixel's mesh holds volume the mesh hides. When none agrees, the ones
    stopped nearer (too little volume, never volume behind the mesh). When
    none of those either, every neighbour went past this pixel's scene: a
    feature thinner than a frame pixel, such as a wire line, that no ray of
    the coarse frame met. Their colour is used only where their nearest
    hit lies in front of this pixel's scene (the volume's surface is in
    front of the line, so it covers it, as the full frame will), otherwise
    nothing: a line in front of the volume stays whole, a line behind an
    opaque volume is not drawn through it in dashes. Smooth where the scene depth is
    smooth (a preview looks like a soft image instead of blocks), and a
    volume pixel from behind a mesh never covers that mesh. Premultiplied
    colour is what is interpolated, so edges of the volume fade without
    dark fringes. The fragment depth is the nearest hit among the pixels
    used, never behind the scene's own depth.
"""

import numpy as np

from . import depth as _depth

NEAREST = "nearest"
BILATERAL = "bilateral"
FILTERS = (NEAREST, BILATERAL)

# Below this total bilinear weight of the agreeing neighbours (a screen
# pixel on the centre line of a frame pixel that disagrees) their plain mean
# is used instead (the GLSL uses the same value).
MIN_WEIGHT = 1e-4


def clamped_planar(window, proj, near, far):
    """Window depth -> planar distance clamped to [near, far] (the cleared
    depth, 1, is far). As the shader's planar()."""
    d = _depth.window_to_planar(window, proj).astype(np.float64)
    d = np.where(np.isfinite(d), d, far)
    return np.clip(d, near, far)


def tolerance(voxel_size):
    """Depth difference (planar, scene units) under which two stop depths
    count as the same surface: two voxels, above the quantum by which the
    library's scene depth is rounded (1/8 voxel) and the depth buffer's
    resolution."""
    return 2.0 * float(voxel_size)


def _neighbours(h, w, H, W):
    """For each screen pixel: the frame-pixel indices (x0, x1, y0, y1) of
    its four neighbours and the bilinear fractions (fx, fy). Pixel centres
    map as OpenGL's texture sampling: u = (x + 0.5) / W * w - 0.5."""
    fx = (np.arange(W) + 0.5) * (w / W) - 0.5
    fy = (np.arange(H) + 0.5) * (h / H) - 0.5
    x0, y0 = np.floor(fx).astype(np.int64), np.floor(fy).astype(np.int64)
    tx, ty = fx - x0, fy - y0
    x1, y1 = np.clip(x0 + 1, 0, w - 1), np.clip(y0 + 1, 0, h - 1)
    x0, y0 = np.clip(x0, 0, w - 1), np.clip(y0, 0, h - 1)
    return x0, x1, y0, y1, tx, ty


def composite(color, hit, stop, scene, proj, near, far, tol, mode=BILATERAL):
    """(rgba (H, W, 4), fragment window depth (H, W)) that the viewport
    draws for a frame over a scene of depth `scene` (None: no scene depth,
    all cleared, at `size` given by scene's shape or color's)."""
    color = np.asarray(color, np.float64)
    hit = np.asarray(hit, np.float64)
    stop = np.asarray(stop, np.float64)
    h, w = color.shape[:2]
    scene = np.asarray(scene, np.float64)
    H, W = scene.shape
    if mode == NEAREST:
        xs = np.minimum(((np.arange(W) + 0.5) * w / W).astype(np.int64), w - 1)
        ys = np.minimum(((np.arange(H) + 0.5) * h / H).astype(np.int64), h - 1)
        c = color[ys][:, xs]
        hi, st = hit[ys][:, xs], stop[ys][:, xs]
        return c, np.where(hi < 1.0, np.minimum(hi, st), st)
    if mode != BILATERAL:
        raise ValueError("unknown filter %r" % (mode,))
    x0, x1, y0, y1, tx, ty = _neighbours(h, w, H, W)
    dp = clamped_planar(scene, proj, near, far)
    ds = clamped_planar(stop, proj, near, far)
    # per class (0: stopped at this pixel's depth, 1: stopped nearer, 2:
    # went past it): the bilinearly weighted colour, the plain mean (for a
    # pixel on a frame pixel's centre line, whose only weighted neighbour
    # may disagree), and the nearest hit
    acc = np.zeros((3, H, W, 4))
    wsum = np.zeros((3, H, W))
    accu = np.zeros((3, H, W, 4))
    cnt = np.zeros((3, H, W))
    nhit = np.ones((3, H, W))
    for yi, wy in ((y0, 1.0 - ty), (y1, ty)):
        for xi, wx in ((x0, 1.0 - tx), (x1, tx)):
            wb = np.outer(wy, wx)
            d = ds[yi][:, xi]
            c = color[yi][:, xi]
            hh = hit[yi][:, xi]
            for k, m in enumerate((np.abs(d - dp) <= tol, d < dp - tol, d > dp + tol)):
                acc[k] += np.where(m, wb, 0.0)[..., None] * c
                wsum[k] += np.where(m, wb, 0.0)
                accu[k] += m[..., None] * c
                cnt[k] += m
                nhit[k] = np.where(m, np.minimum(nhit[k], hh), nhit[k])
    out = np.zeros((H, W, 4))
    nh = np.ones((H, W))
    done = np.zeros((H, W), bool)
    for k in (0, 1, 2):
        if k == 2:  # past this pixel's scene: only a hit in front of it
            done |= nhit[2] > scene
        weighted = ~done & (wsum[k] > MIN_WEIGHT)
        plain = ~done & ~weighted & (cnt[k] > 0)
        out[weighted] = acc[k][weighted] / wsum[k][weighted][:, None]
        out[plain] = accu[k][plain] / cnt[k][plain][:, None]
        nh = np.where(weighted | plain, nhit[k], nh)
        done |= weighted | plain
    return out, np.minimum(nh, scene)


def over(rgba, background):
    """Premultiplied `rgba` over an opaque `background` (H, W, 3) or colour."""
    a = rgba[..., 3:4]
    return rgba[..., :3] + (1.0 - a) * np.asarray(background, np.float64)
