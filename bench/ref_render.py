"""ref_render.py - double-precision CPU reference for a sampled volume.

The ray caster's equations as csrc/reference.c states them for the phantoms
(camera, box, classification, opacity correction, Phong headlight with
two-sided normals, front-to-back compositing), in float64 with numpy, but
on the voxels of a real scan instead of an analytic field:

  * value: trilinear interpolation of the voxels (clamped to the edge), the
    field both Voxlight and VTK sample;
  * gradient: central differences one voxel apart of that field, what both
    renderers' "central" gradient estimates;
  * a fine step (default 1/8 voxel), no jitter, and compositing until the
    transmittance left is below 1e-6 (no early termination at 0.99).

Neither renderer's shortcuts (empty-space skipping, early termination,
8-bit tables or framebuffers, jitter) are in it, so both are measured
against the same image of the same field. Light: the headlight of
csrc/frame.c, a directional light along the view axis; VTK's positional
headlight differs from it (docs/benchmark.md says by how much).
"""

import numpy as np

TERMINATE = 1.0 - 1e-6


class Field:
    """Trilinear field of a volume given x-fastest (NIfTI order)."""

    def __init__(self, data, dims):
        self.dims = np.array(dims, dtype=np.int64)
        self.v = np.ascontiguousarray(np.asarray(data, dtype=np.float32).ravel())
        self.stride = np.array([1, dims[0], dims[0] * dims[1]], dtype=np.int64)

    def sample(self, p):
        """Values at voxel-space points p (n, 3), float64."""
        hi = self.dims - 1
        q = np.clip(p, 0, hi)
        i0 = np.minimum(np.floor(q).astype(np.int64), np.maximum(hi - 1, 0))
        w = q - i0
        base = i0 @ self.stride
        out = np.zeros(len(p))
        for dz in (0, 1):
            wz = w[:, 2] if dz else 1 - w[:, 2]
            for dy in (0, 1):
                wy = w[:, 1] if dy else 1 - w[:, 1]
                for dx in (0, 1):
                    wx = w[:, 0] if dx else 1 - w[:, 0]
                    off = dx * self.stride[0] + dy * self.stride[1] + dz * self.stride[2]
                    out += wx * wy * wz * self.v[base + off]
        return out

    def gradient(self, p):
        g = np.empty_like(p)
        for a in range(3):
            e = np.zeros(3)
            e[a] = 1.0
            g[:, a] = 0.5 * (self.sample(p + e) - self.sample(p - e))
        return g


def classify(table, window, v):
    """GL_LINEAR lookup of the table at the window-mapped value."""
    lo, hi = window
    x = np.clip((v - lo) / (hi - lo), 0, 1)
    u = x * (len(table) - 1)
    i0 = np.minimum(np.floor(u).astype(np.int64), len(table) - 1)
    i1 = np.minimum(i0 + 1, len(table) - 1)
    w = (u - i0)[:, None]
    return table[i0] * (1 - w) + table[i1] * w


def camera_rays(dims, model, view, proj, width, height):
    """Per pixel (row 0 = bottom, x fastest): voxel-space origin o and unit
    direction d, and the entry and exit t0, t1 of the box [-0.5, dims-0.5]
    (t0 >= t1: the ray misses), as raycast.frag builds them."""
    mv = view @ model
    inv_mvp = np.linalg.inv(proj @ mv)
    ys, xs = np.mgrid[0:height, 0:width]
    ndc_x = ((xs.ravel() + 0.5) / width * 2 - 1)
    ndc_y = ((ys.ravel() + 0.5) / height * 2 - 1)
    ones = np.ones_like(ndc_x)
    hn = np.stack([ndc_x, ndc_y, -ones, ones], 1) @ inv_mvp.T
    hf = np.stack([ndc_x, ndc_y, ones, ones], 1) @ inv_mvp.T
    o = hn[:, :3] / hn[:, 3:]
    d = hf[:, :3] * hn[:, 3:] - hn[:, :3] * hf[:, 3:]  # as raycast.frag: no divide by the far w
    length = np.linalg.norm(d, axis=1)
    d /= length[:, None]
    t0 = np.zeros(len(o))
    t1 = length / (hn[:, 3] * hf[:, 3])
    for k in range(3):
        lo, hi = -0.5, dims[k] - 0.5
        with np.errstate(divide="ignore", invalid="ignore"):
            ta, tb = (lo - o[:, k]) / d[:, k], (hi - o[:, k]) / d[:, k]
        flat = np.abs(d[:, k]) < 1e-12
        inside = (o[:, k] >= lo) & (o[:, k] <= hi)
        t0 = np.where(flat, np.where(inside, t0, np.inf), np.maximum(t0, np.minimum(ta, tb)))
        t1 = np.where(flat, t1, np.minimum(t1, np.maximum(ta, tb)))
    return o, d, t0, t1


def march_samples(data, dims, model, view, proj, width, height, table, window, step, stop):
    """Samples per ray of a ray caster without empty-space skipping that
    stops at opacity `stop` (VTK: 1 - 1/255): the work such a caster does
    on this frame; and of those, the samples with opacity > 0, the least
    any caster must shade. Opacity only; two (height, width) int arrays."""
    table = np.asarray(table, dtype=np.float64).reshape(-1, 4)
    field = Field(data, dims)
    o, d, t0, t1 = camera_rays(dims, model, view, proj, width, height)
    count = np.zeros(len(o), dtype=np.int64)
    visible = np.zeros(len(o), dtype=np.int64)
    idx = np.nonzero(t0 < t1)[0]
    t, a_acc = t0[idx].copy(), np.zeros(len(idx))
    while len(idx):
        a = classify(table, window, field.sample(o[idx] + t[:, None] * d[idx]))[:, 3]
        a_acc += (1 - a_acc) * (1 - np.power(np.clip(1 - a, 0, 1), step))
        count[idx] += 1
        visible[idx] += a > 0
        t += step
        keep = (t < t1[idx]) & (a_acc < stop)
        idx, t, a_acc = idx[keep], t[keep], a_acc[keep]
    return count.reshape(height, width), visible.reshape(height, width)


def render(data, dims, model, view, proj, width, height, table, window, material=(0.3, 0.7, 0.3, 24.0),
           step=0.125, shading=True, chunk=1 << 18):
    """Premultiplied RGBA (height, width, 4) float64, row 0 = bottom, and the
    (height, width) mask of pixels whose ray meets the volume's box."""
    table = np.asarray(table, dtype=np.float64).reshape(-1, 4)
    field = Field(data, dims)
    mv = view @ model
    normal = np.linalg.inv(mv[:3, :3]).T
    o, d, t0, t1 = camera_rays(dims, model, view, proj, width, height)
    hit = t0 < t1
    view_dir = -(d @ mv[:3, :3].T)
    view_dir /= np.linalg.norm(view_dir, axis=1)[:, None]
    light = np.array([0.0, 0.0, 1.0])
    amb, dif, spe, shin = material
    acc = np.zeros((len(o), 4))
    for start in range(0, len(o), chunk):
        idx = np.arange(start, min(start + chunk, len(o)))
        idx = idx[hit[idx]]
        t = t0[idx].copy()
        while len(idx):
            p = o[idx] + t[:, None] * d[idx]
            col = classify(table, window, field.sample(p))
            a = col[:, 3]
            vis = a > 0
            if vis.any():
                iv = np.nonzero(vis)[0]
                c = col[iv, :3]
                av = 1 - np.power(np.clip(1 - a[iv], 0, 1), step)
                if shading:
                    n = field.gradient(p[iv]) @ normal.T
                    nl = np.linalg.norm(n, axis=1)
                    lit = nl > 1e-20
                    n = n / np.where(lit, nl, 1)[:, None]
                    v = view_dir[idx[iv]]
                    n = np.where((np.sum(n * v, 1) < 0)[:, None], -n, n)
                    ndl = n @ light
                    h = light + v
                    h /= np.maximum(np.linalg.norm(h, axis=1), 1e-300)[:, None]
                    spec = np.power(np.maximum(np.sum(n * h, 1), 0), shin)
                    on = (ndl > 0)[:, None]
                    shaded = amb * c + np.where(on, dif * ndl[:, None] * c + spe * spec[:, None], 0)
                    c = np.where(lit[:, None], np.clip(shaded, 0, 1), c)
                rows = idx[iv]
                wgt = (1 - acc[rows, 3]) * av
                acc[rows, :3] += wgt[:, None] * c
                acc[rows, 3] += wgt
            t += step
            keep = (t < t1[idx]) & (acc[idx, 3] < TERMINATE)
            idx, t = idx[keep], t[keep]
    img = np.clip(acc, 0, 1).reshape(height, width, 4)
    return img, hit.reshape(height, width)
