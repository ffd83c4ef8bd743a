"""Minimal NIfTI-1 writer (numpy only) for test inputs: the add-on's tests
must not depend on the library to produce the files the library reads."""

import gzip
import struct

import numpy as np

_CODES = {np.dtype(np.uint8): 2, np.dtype(np.int16): 4, np.dtype(np.int32): 8,
          np.dtype(np.float32): 16, np.dtype(np.float64): 64, np.dtype(np.int8): 256,
          np.dtype(np.uint16): 512, np.dtype(np.uint32): 768}


def nifti1_bytes(data, affine=None, scl_slope=0.0, scl_inter=0.0, rgb=False):
    """data indexed [i, j, k]; affine 4x4 voxel -> mm (sform); default
    diag(1) at the origin. rgb: data is uint8 [i, j, k, 3], written as
    NIfTI's RGB24 (datatype 128, the colour of each voxel interleaved)."""
    data = np.asarray(data)
    if rgb:
        return _rgb24_bytes(np.asarray(data, np.uint8), affine)
    if data.dtype not in _CODES:
        data = data.astype(np.float32)
    data = data.astype(data.dtype.newbyteorder("<"))
    aff = np.eye(4) if affine is None else np.asarray(affine, np.float64)
    spacing = np.linalg.norm(aff[:3, :3], axis=0)
    hdr = bytearray(352)
    struct.pack_into("<i", hdr, 0, 348)
    dims = [3] + list(data.shape) + [1] * (7 - data.ndim)
    struct.pack_into("<8h", hdr, 40, *dims)
    struct.pack_into("<hh", hdr, 70, _CODES[data.dtype.newbyteorder("=")], data.dtype.itemsize * 8)
    struct.pack_into("<8f", hdr, 76, 1.0, *spacing, 1, 1, 1, 1)
    struct.pack_into("<fff", hdr, 108, 352.0, scl_slope, scl_inter)
    hdr[123] = 2  # xyzt_units: mm
    struct.pack_into("<hh", hdr, 252, 0, 1)  # qform_code 0, sform_code 1 (scanner)
    for r in range(3):
        struct.pack_into("<4f", hdr, 280 + 16 * r, *aff[r])
    hdr[344:348] = b"n+1\0"
    return bytes(hdr) + np.asfortranarray(data).tobytes(order="F")


def channels_bytes(channels, affine=None):
    """A multi-channel NIfTI-1: the 3-D arrays in `channels` (each indexed
    [i, j, k], one dtype) as dim[5], one after the other (dim = 5, X, Y, Z,
    1, C), the layout microscopy exports use and the library reads as
    channels (docs/channels.md)."""
    stack = np.stack([np.asarray(c) for c in channels], axis=3)[:, :, :, None, :]
    raw = bytearray(nifti1_bytes(stack, affine))
    struct.pack_into("<h", raw, 40, 5)  # dim[0]: five dimensions
    return bytes(raw)


def write_channels_nifti(path, channels, affine=None):
    raw = channels_bytes(channels, affine)
    with (gzip.open if str(path).endswith(".gz") else open)(path, "wb") as f:
        f.write(raw)
    return path


def _rgb24_bytes(rgb, affine):
    if rgb.ndim != 4 or rgb.shape[3] != 3:
        raise ValueError("RGB24 data is [i, j, k, 3], got %r" % (rgb.shape,))
    grey = nifti1_bytes(np.zeros(rgb.shape[:3], np.uint8), affine)
    hdr = bytearray(grey[:352])
    struct.pack_into("<hh", hdr, 70, 128, 24)  # DT_RGB24, 24 bits per voxel
    # i fastest, the three bytes of a voxel together
    return bytes(hdr) + np.ascontiguousarray(rgb.transpose(2, 1, 0, 3)).tobytes()


def write_nifti(path, data, affine=None, **kw):
    raw = nifti1_bytes(data, affine, **kw)
    if str(path).endswith(".gz"):
        with gzip.open(path, "wb") as f:
            f.write(raw)
    else:
        with open(path, "wb") as f:
            f.write(raw)
    return path


def phantom(n=32, seed=1):
    """A noisy ball: smooth enough to shade, noisy enough that every
    gradient filter and setting gives a different image."""
    g = (np.arange(n) - (n - 1) / 2.0) / (n / 2.0)
    x, y, z = np.meshgrid(g, g, g, indexing="ij")
    r = np.sqrt(x * x + y * y + z * z)
    ball = np.clip((0.8 - r) * 5.0, 0.0, 1.0)
    noise = np.random.default_rng(seed).random((n, n, n))
    return (ball * (80.0 + 40.0 * noise)).astype(np.float32)
