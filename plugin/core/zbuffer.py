"""A numpy z-buffer: rasterises world-space triangles into the library's
depth convention (view-space planar distance, +inf = empty, row 0 = bottom).

Used for F12 / background renders, where Blender gives Python no access to
the render's depth: the volume's rays stop at this depth, so meshes in front
of or inside the volume hide what lies behind them. No bpy here, so it is
tested in plain Python.

One sample per pixel at the pixel centre, no anti-aliasing; triangles are
clipped against the near plane so large ground planes that pass behind the
camera still rasterise correctly.
"""

import numpy as np

from . import depth as _depth

# Candidate pixels processed per chunk: bounds memory to a few hundred MB.
_CHUNK_PIXELS = 1 << 22


def _clip_near(clip, src):
    """Clip triangles (n, 3, 4) in clip space against the near plane
    (z > -w). Returns the surviving and newly cut triangles (m, 3, 4) and
    the index in `src` of the triangle each came from."""
    dist = clip[:, :, 2] + clip[:, :, 3]
    inside = dist > 0.0
    count = inside.sum(axis=1)
    out = [clip[count == 3]]
    origin = [src[count == 3]]

    def lerp(a, b, da, db):
        t = (da / (da - db))[:, None]
        return a + (b - a) * t

    # One vertex inside: the triangle shrinks to one triangle.
    sel = count == 1
    if sel.any():
        c, d, ins = clip[sel], dist[sel], inside[sel]
        i0 = np.argmax(ins, axis=1)  # the inside vertex
        i1, i2 = (i0 + 1) % 3, (i0 + 2) % 3
        r = np.arange(len(c))
        a, b, e = c[r, i0], c[r, i1], c[r, i2]
        da, db, de = d[r, i0], d[r, i1], d[r, i2]
        out.append(np.stack([a, lerp(a, b, da, db), lerp(a, e, da, de)], axis=1))
        origin.append(src[sel])
    # Two vertices inside: a quad, split into two triangles.
    sel = count == 2
    if sel.any():
        c, d, ins = clip[sel], dist[sel], inside[sel]
        o = np.argmin(ins, axis=1)  # the outside vertex
        i1, i2 = (o + 1) % 3, (o + 2) % 3
        r = np.arange(len(c))
        ov, a, b = c[r, o], c[r, i1], c[r, i2]
        do, da, db = d[r, o], d[r, i1], d[r, i2]
        pa = lerp(a, ov, da, do)  # on edge a-o
        pb = lerp(b, ov, db, do)  # on edge b-o
        out.append(np.stack([a, b, pb], axis=1))
        out.append(np.stack([a, pb, pa], axis=1))
        origin += [src[sel], src[sel]]
    return np.concatenate(out, axis=0), np.concatenate(origin)


def rasterize(triangles, view, proj, width, height, zbuf=None, ids=None):
    """triangles: (n, 3, 3) world-space vertices. view, proj: 4x4 math
    matrices. Returns (height, width) float32 planar distances (min-merged
    into zbuf when given). ids, a (height, width) int64 array: where a
    triangle is nearest, set to its index in `triangles` (the scene shadow
    needs the visible surface's normal)."""
    width, height = int(width), int(height)
    if zbuf is None:
        zbuf = np.full((height, width), np.inf, np.float32)
    tris = np.asarray(triangles, dtype=np.float64).reshape(-1, 3, 3)
    if len(tris) == 0:
        return zbuf
    mvp = np.asarray(proj, np.float64) @ np.asarray(view, np.float64)
    hom = np.concatenate([tris, np.ones(tris.shape[:2] + (1,))], axis=2)
    clip = hom @ mvp.T
    clip, src = _clip_near(clip, np.arange(len(clip)))
    if len(clip) == 0:
        return zbuf
    w = clip[:, :, 3]
    ndc = clip[:, :, :3] / w[:, :, None]
    sx = (ndc[:, :, 0] * 0.5 + 0.5) * width
    sy = (ndc[:, :, 1] * 0.5 + 0.5) * height
    sz = ndc[:, :, 2]

    # Pixel-centre bounding boxes; triangles off screen or degenerate go.
    x0 = np.clip(np.ceil(sx.min(axis=1) - 0.5), 0, width).astype(np.int64)
    x1 = np.clip(np.floor(sx.max(axis=1) - 0.5), -1, width - 1).astype(np.int64)
    y0 = np.clip(np.ceil(sy.min(axis=1) - 0.5), 0, height).astype(np.int64)
    y1 = np.clip(np.floor(sy.max(axis=1) - 0.5), -1, height - 1).astype(np.int64)
    area = ((sx[:, 1] - sx[:, 0]) * (sy[:, 2] - sy[:, 0])
            - (sx[:, 2] - sx[:, 0]) * (sy[:, 1] - sy[:, 0]))
    keep = (x1 >= x0) & (y1 >= y0) & (np.abs(area) > 1e-12) & (sz.min(axis=1) <= 1.0)
    if not keep.any():
        return zbuf
    sx, sy, sz, area, src = sx[keep], sy[keep], sz[keep], area[keep], src[keep]
    x0, x1, y0, y1 = x0[keep], x1[keep], y0[keep], y1[keep]
    bw = x1 - x0 + 1
    npix = bw * (y1 - y0 + 1)

    flat = zbuf.reshape(-1)
    flat_ids = None if ids is None else ids.reshape(-1)
    start = 0
    n = len(npix)
    cum = np.cumsum(npix)
    while start < n:
        # Take triangles until the chunk holds about _CHUNK_PIXELS candidates.
        base = cum[start - 1] if start else 0
        stop = int(np.searchsorted(cum, base + _CHUNK_PIXELS, side="right"))
        stop = max(stop, start + 1)
        idx = np.arange(start, stop)
        counts = npix[idx]
        tri = np.repeat(idx, counts)
        offs = np.arange(counts.sum()) - np.repeat(np.cumsum(counts) - counts, counts)
        px = x0[tri] + offs % bw[tri]
        py = y0[tri] + offs // bw[tri]
        cx, cy = px + 0.5, py + 0.5
        ax, ay = sx[tri, 0], sy[tri, 0]
        bx, by = sx[tri, 1], sy[tri, 1]
        qx, qy = sx[tri, 2], sy[tri, 2]
        # Barycentric weights from edge functions, normalised by the area.
        w0 = ((bx - cx) * (qy - cy) - (qx - cx) * (by - cy)) / area[tri]
        w1 = ((qx - cx) * (ay - cy) - (ax - cx) * (qy - cy)) / area[tri]
        w2 = 1.0 - w0 - w1
        inside = (w0 >= -1e-9) & (w1 >= -1e-9) & (w2 >= -1e-9)
        z = w0 * sz[tri, 0] + w1 * sz[tri, 1] + w2 * sz[tri, 2]  # NDC z is affine on screen
        inside &= (z >= -1.0) & (z <= 1.0)
        pix = (py * width + px)[inside]
        z = z[inside]
        tri = tri[inside]
        if len(z):
            # Nearest sample per pixel: sort by (pixel, z), keep each pixel's first.
            order = np.lexsort((z, pix))
            pix, z, tri = pix[order], z[order], tri[order]
            first = np.ones(len(pix), bool)
            first[1:] = pix[1:] != pix[:-1]
            pix, z, tri = pix[first], z[first], tri[first]
            dist = _depth.window_to_planar(z * 0.5 + 0.5, proj)
            nearer = dist < flat[pix]
            flat[pix[nearer]] = dist[nearer]
            if flat_ids is not None:
                flat_ids[pix[nearer]] = src[tri[nearer]]
        start = stop
    return zbuf
