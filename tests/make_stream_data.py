"""The data benchmark streams (bench/stream_study.c,
docs/streaming.md "Benchmark"), generated with numpy and nothing
downloaded; every file is the same on every run (fixed seeds).

  make_stream_data.py sparse PATH.nii [--dims 4096,4096,1600]
      An uncompressed 8-bit NIfTI larger than the machine's memory (25.2 GiB
      of voxels by default) made as a sparse file: the header is written,
      the file is extended with ftruncate, and a few hundred small balls and
      tubes are written into it, so most of it stays holes (about 0.2 GiB on
      disk).
  make_stream_data.py gzip PATH.nii.gz [--dims 2600,1500,400]
      The issue's 2600 x 1500 x 400 8-bit .nii.gz (1.56 GB of voxels): a
      smooth body-like structure (a soft-edged ellipsoid with slow
      variations inside, bright vessels and balls), computed and gzip-
      compressed slab by slab (zlib's gzip stream), never whole in memory.
  make_stream_data.py zarr PATH.zarr [--dims 2048,2048,512] [--codec zstd|blosc|gzip]
      An OME-Zarr v2 (NGFF 0.4) pyramid of 4 levels of uint16 (each level
      every second voxel of the one before, as tests/zarr_write.py's
      pyramid), chunks of 64^3, cells (Gaussian balls) in a tissue slab;
      chunks holding only zeros are not written (fill_value 0). Each level
      is computed from the analytic field at its own voxels, a chunk row at
      a time.

  make_stream_data.py tiff PATH.tif [--dims 2600,1500,400]
      The gzip kind's body as an uncompressed multi-page 8-bit TIFF (one
      page per z slice, one strip per page, rows top first as images store
      them): what TIFF streaming reads by offset.

--dims X,Y,Z makes smaller versions (the smoke test uses them)."""
import argparse
import gzip
import json
import os
import struct
import sys
import zlib
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from zarr_write import encode  # noqa: E402


def nifti1_header(dims, dtype_code=2, bitpix=8, vox_offset=352, spacing=(1.0, 1.0, 1.0)):
    """A NIfTI-1 header (348 bytes) plus the 4-byte extension flag: dims x,
    y, z, uint8 by default, an sform of the spacing."""
    h = bytearray(348)
    struct.pack_into("<i", h, 0, 348)
    struct.pack_into("<8h", h, 40, 3, dims[0], dims[1], dims[2], 1, 1, 1, 1)
    struct.pack_into("<hh", h, 70, dtype_code, bitpix)
    struct.pack_into("<8f", h, 76, 1.0, *spacing, 1.0, 1.0, 1.0, 1.0)
    struct.pack_into("<f", h, 108, float(vox_offset))
    struct.pack_into("<ff", h, 112, 1.0, 0.0)  # scl_slope, scl_inter
    struct.pack_into("<B", h, 123, 10)  # xyzt_units: mm, s
    struct.pack_into("<hh", h, 252, 0, 1)  # qform_code, sform_code
    struct.pack_into("<4f", h, 280, spacing[0], 0, 0, 0)
    struct.pack_into("<4f", h, 296, 0, spacing[1], 0, 0)
    struct.pack_into("<4f", h, 312, 0, 0, spacing[2], 0)
    h[344:348] = b"n+1\0"
    return bytes(h) + b"\0\0\0\0"


# ------------------------------------------------------------------ sparse


def _ball(r):
    """A Gaussian-profiled ball of radius r: uint8, 0 outside."""
    g = np.arange(-r, r + 1, dtype=np.float32)
    d2 = g[:, None, None] ** 2 + g[None, :, None] ** 2 + g[None, None, :] ** 2
    v = 250 * np.exp(-d2 / (2 * (r / 2.2) ** 2))
    return np.where(d2 <= r * r, np.maximum(v, 1), 0).astype(np.uint8)


def write_sparse(path, dims, balls=300, tubes=24, seed=21):
    nx, ny, nz = dims
    rng = np.random.default_rng(seed)
    with open(path, "w+b") as f:  # read too: overlapping balls keep the max
        f.write(nifti1_header(dims))
        f.truncate(352 + nx * ny * nz)
        f.flush()
        fd = f.fileno()

        def put(block, x0, y0, z0):
            """Writes block (z, y, x) at voxel (x0, y0, z0), one row at a time,
            keeping what is there (the max), so overlaps stay smooth."""
            bz, by, bx = block.shape
            for k in range(bz):
                for j in range(by):
                    row = block[k, j]
                    nzr = np.nonzero(row)[0]
                    if not len(nzr):
                        continue
                    a, b = nzr[0], nzr[-1] + 1
                    off = 352 + ((z0 + k) * ny + (y0 + j)) * nx + x0 + a
                    old = np.frombuffer(os.pread(fd, b - a, off), np.uint8)
                    os.pwrite(fd, np.maximum(old, row[a:b]).tobytes(), off)

        for _ in range(balls):
            r = int(rng.integers(4, 12))
            r = min(r, (min(dims) - 1) // 2)
            c = [int(rng.integers(r, d - r)) for d in dims]
            put(_ball(r), c[0] - r, c[1] - r, c[2] - r)
        # tubes: balls of radius 3 along straight segments
        small = _ball(3)
        for _ in range(tubes):
            a = np.array([rng.uniform(4, d - 4) for d in dims])
            b = np.array([rng.uniform(4, d - 4) for d in dims])
            n = int(np.linalg.norm(b - a) / 3) + 1
            n = min(n, 200)
            for t in np.linspace(0, 1, n):
                c = np.round(a + t * (b - a)).astype(int)
                put(small, c[0] - 3, c[1] - 3, c[2] - 3)


# -------------------------------------------------------------------- gzip


def body_slab(dims, z0, z1, rng_balls):
    """Voxels z0..z1-1 of the smooth body: float32 (z, y, x) in 0..255."""
    nx, ny, nz = dims
    z = ((np.arange(z0, z1, dtype=np.float32) + 0.5) / nz * 2 - 1)[:, None, None]
    y = ((np.arange(ny, dtype=np.float32) + 0.5) / ny * 2 - 1)[None, :, None]
    x = ((np.arange(nx, dtype=np.float32) + 0.5) / nx * 2 - 1)[None, None, :]
    r2 = (x / 0.85) ** 2 + (y / 0.7) ** 2 + (z / 0.95) ** 2
    body = np.clip((1 - r2) * 12, 0, 1)  # soft edge
    inside = 70 + 25 * np.sin(5 * x) * np.cos(4 * y) + 15 * np.sin(3 * z + 2 * x)
    vessels = 120 * np.exp(-((np.sin(9 * x + 3 * z) * 0.5 + y * 0.8) ** 2) / 0.002)
    v = body * (inside + vessels * (r2 < 0.8))
    for (cx, cy, cz, rad) in rng_balls:
        d2 = (x - cx) ** 2 + (y - cy) ** 2 + (z - cz) ** 2
        v = v + 150 * np.exp(-d2 / (2 * rad * rad)) * body
    return np.clip(v, 0, 255)


def write_gzip(path, dims, slab=4, level=1):
    rng = np.random.default_rng(7)
    balls = [(rng.uniform(-0.6, 0.6), rng.uniform(-0.5, 0.5), rng.uniform(-0.8, 0.8), rng.uniform(0.02, 0.06))
             for _ in range(12)]
    nx, ny, nz = dims
    comp = zlib.compressobj(level, zlib.DEFLATED, 31)  # 31: a gzip stream
    with open(path, "wb") as f:
        f.write(comp.compress(nifti1_header(dims)))
        for z0 in range(0, nz, slab):
            v = body_slab(dims, z0, min(nz, z0 + slab), balls)
            f.write(comp.compress(v.astype(np.uint8).tobytes()))
        f.write(comp.flush())


def write_tiff(path, dims, slab=4):
    """Classic little-endian TIFF, each page's data then its directory."""
    rng = np.random.default_rng(7)  # the gzip kind's balls: the same body
    balls = [(rng.uniform(-0.6, 0.6), rng.uniform(-0.5, 0.5), rng.uniform(-0.8, 0.8), rng.uniform(0.02, 0.06))
             for _ in range(12)]
    nx, ny, nz = dims
    if nx * ny * nz + nz * 256 >= 1 << 32:
        sys.exit("make_stream_data: %dx%dx%d does not fit a classic TIFF" % dims)
    with open(path, "wb") as f:
        f.write(b"II*\x00" + struct.pack("<I", 0))
        link = 4  # where the previous directory's next-directory offset lies
        for z0 in range(0, nz, slab):
            v = body_slab(dims, z0, min(nz, z0 + slab), balls).astype(np.uint8)
            for page in v.reshape(-1, ny, nx):
                data = f.tell()
                f.write(np.ascontiguousarray(page[::-1]).tobytes())  # top row first
                if f.tell() % 2:
                    f.write(b"\0")
                ifd = f.tell()
                tags = [(256, 4, nx), (257, 4, ny), (258, 3, 8), (259, 3, 1), (262, 3, 1), (273, 4, data),
                        (277, 3, 1), (278, 4, ny), (279, 4, nx * ny)]
                f.write(struct.pack("<H", len(tags)))
                for tag, typ, val in tags:
                    f.write(struct.pack("<HHI", tag, typ, 1) +
                            (struct.pack("<HH", val, 0) if typ == 3 else struct.pack("<I", val)))
                f.write(struct.pack("<I", 0))
                end = f.tell()
                f.seek(link)
                f.write(struct.pack("<I", ifd))
                f.seek(end)
                link = ifd + 2 + 12 * len(tags)


# -------------------------------------------------------------------- zarr


def cells(dims, count, seed=5):
    """count cells (x, y, z, sigma, brightness) in level-0 voxels, in a
    tissue slab through the middle of z."""
    rng = np.random.default_rng(seed)
    nx, ny, nz = dims
    return np.array([(rng.uniform(0, nx), rng.uniform(0, ny), rng.uniform(nz * 0.25, nz * 0.75), rng.uniform(2.5, 6),
                      rng.uniform(8000, 40000)) for _ in range(count)])


def zarr_block(dims, cell_list, step, lo, shape):
    """The field at level voxels lo .. lo+shape (x, y, z) of a level of
    `step` level-0 voxels per voxel: uint16 (z, y, x)."""
    nx, ny, nz = dims
    xs = (lo[0] + np.arange(shape[0])) * step
    ys = (lo[1] + np.arange(shape[1])) * step
    zs = (lo[2] + np.arange(shape[2])) * step
    zt = np.abs(zs / nz - 0.5)[:, None, None]
    tissue = np.clip((0.3 - zt) * 40, 0, 1)  # the slab, soft-edged
    bg = tissue * (300 + 200 * np.sin(xs / 97.0)[None, None, :] * np.cos(ys / 61.0)[None, :, None])
    v = np.broadcast_to(bg, (shape[2], shape[1], shape[0])).astype(np.float32)
    # only the cells within 3 sigma of the block (a chunk meets a few of thousands)
    near = np.ones(len(cell_list), bool)
    for axis, coords in enumerate((xs, ys, zs)):
        c = cell_list[:, axis]
        near &= (c + 3 * cell_list[:, 3] >= coords[0]) & (c - 3 * cell_list[:, 3] <= coords[-1])
    for (cx, cy, cz, s, b) in cell_list[near]:
        r = 3 * s
        ix = np.nonzero(np.abs(xs - cx) <= r)[0]
        iy = np.nonzero(np.abs(ys - cy) <= r)[0]
        iz = np.nonzero(np.abs(zs - cz) <= r)[0]
        if not (len(ix) and len(iy) and len(iz)):
            continue
        sx, sy, sz = slice(ix[0], ix[-1] + 1), slice(iy[0], iy[-1] + 1), slice(iz[0], iz[-1] + 1)
        d2 = ((xs[sx] - cx) ** 2)[None, None, :] + ((ys[sy] - cy) ** 2)[None, :, None] + \
             ((zs[sz] - cz) ** 2)[:, None, None]
        v[sz, sy, sx] += (b * np.exp(-d2 / (2 * s * s))).astype(np.float32)
    return np.clip(v, 0, 65535).astype(np.uint16)


def write_zarr(path, dims, levels=4, chunk=64, codec="zstd"):
    root = Path(path)
    root.mkdir(parents=True, exist_ok=True)
    nx, ny, nz = dims
    cell_list = cells(dims, max(50, nx * ny * nz // 400000))
    datasets = []
    for l in range(levels):
        step = 2 ** l
        shape = [(d + step - 1) // step for d in dims]  # x, y, z: every second voxel
        folder = root / str(l)
        folder.mkdir(exist_ok=True)
        ch = [min(chunk, s) for s in shape[::-1]]  # z, y, x
        comp = None if codec == "raw" else (
            {"id": "blosc", "cname": "lz4", "clevel": 5, "shuffle": 2, "blocksize": 0} if codec == "blosc"
            else {"id": codec, "level": 1})
        meta = {"zarr_format": 2, "shape": shape[::-1], "chunks": ch, "dtype": "<u2", "compressor": comp,
                "fill_value": 0, "order": "C", "filters": None, "dimension_separator": "/"}
        (folder / ".zarray").write_text(json.dumps(meta))
        for cz in range(0, shape[2], ch[0]):
            for cy in range(0, shape[1], ch[1]):
                for cx in range(0, shape[0], ch[2]):
                    ext = [min(ch[2], shape[0] - cx), min(ch[1], shape[1] - cy), min(ch[0], shape[2] - cz)]
                    block = zarr_block(dims, cell_list, step, (cx, cy, cz), ext)
                    if not block.any():
                        continue  # fill_value
                    full = np.zeros(ch, np.uint16)
                    full[:ext[2], :ext[1], :ext[0]] = block
                    p = folder / str(cz // ch[0]) / str(cy // ch[1]) / str(cx // ch[2])
                    p.parent.mkdir(parents=True, exist_ok=True)
                    p.write_bytes(encode(codec, full.tobytes(), 2) if codec != "gzip"
                                  else gzip.compress(full.tobytes(), 1))
        datasets.append({"path": str(l), "coordinateTransformations": [
            {"type": "scale", "scale": [0.5 * step, 0.2 * step, 0.2 * step]}]})
    axes = [{"name": a, "type": "space", "unit": "micrometer"} for a in "zyx"]
    (root / ".zgroup").write_text(json.dumps({"zarr_format": 2}))
    (root / ".zattrs").write_text(json.dumps({"multiscales": [
        {"version": "0.4", "name": root.name, "axes": axes, "datasets": datasets}]}))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("kind", choices=["sparse", "gzip", "tiff", "zarr"])
    ap.add_argument("path")
    ap.add_argument("--dims", help="X,Y,Z")
    ap.add_argument("--codec", default="zstd", choices=["zstd", "blosc", "gzip", "raw"])
    a = ap.parse_args(argv)
    default = {"sparse": (4096, 4096, 1600), "gzip": (2600, 1500, 400), "tiff": (2600, 1500, 400),
               "zarr": (2048, 2048, 512)}[a.kind]
    dims = tuple(int(v) for v in a.dims.split(",")) if a.dims else default
    if len(dims) != 3 or min(dims) < 8:
        ap.error("--dims needs three sizes of at least 8")
    if a.kind == "sparse":
        write_sparse(a.path, dims)
    elif a.kind == "gzip":
        write_gzip(a.path, dims)
    elif a.kind == "tiff":
        write_tiff(a.path, dims)
    else:
        write_zarr(a.path, dims, codec=a.codec)


if __name__ == "__main__":
    main()
