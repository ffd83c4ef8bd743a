"""Frames split into tiles: the params of a pixel rectangle of an image
(same camera, same jitter), the digest that says two frames are the same,
and the statistics of a tiled frame.

Part of the ctypes binding; plugin/core/native.py re-exports it."""

import ctypes
import hashlib

import numpy as np

from .native_abi import RenderParams, _fptr, _matrix_cm, matrix_from_cm


def _label_style_bytes(style):
    """The label style's mode, boundary and entries (colours, visibility,
    ids), not its pointer: a hidden label must change the digest, an equal
    list not. The style is a struct of its own behind a pointer, so each
    field that changes the image is packed here by hand."""
    n = style.entry_count
    stride = style.entries[0].struct_size if n and style.entries else 0
    data = ctypes.string_at(ctypes.cast(style.entries, ctypes.c_void_p), n * stride) if stride else b""
    return bytes([1]) + np.array([style.mode, n, stride, style.boundary], np.uint32).tobytes() + data


def params_digest(params, *extra):
    """A digest of everything a render depends on: every field of the
    params struct (pointers excluded) plus the contents of the arrays it
    points at (scene depth), plus `extra` (the volume's identity). Equal
    digests mean the library would be given identical inputs."""
    c = RenderParams.from_buffer_copy(params)
    c.scene_depth = None
    c.tf_rgba = None
    c.light_shapes = None  # their contents are in _keep
    c.cutaway = None  # so are the cutaway's and the MatCap's
    c.matcap = None
    c.scene_shadows = None  # its key (or arrays) are in _keep
    # the label style by contents (read before the field, which
    # shares c's memory, is cleared).
    labels = _label_style_bytes(c.labels.contents) if c.labels else b""
    c.labels = None
    c.overlays = None  # their contents are in _keep
    c.environment = None  # the World's map and numbers are in _keep
    c.channels = None  # the channel styles' contents are in _keep
    h = hashlib.blake2b(bytes(c), digest_size=16)
    h.update(labels)
    for a in getattr(params, "_keep", ()):
        a = np.ascontiguousarray(a)
        h.update(str((a.dtype.str, a.shape)).encode())
        h.update(memoryview(a).cast("B"))
    for e in extra:
        h.update(e if isinstance(e, bytes) else repr(e).encode())
    return h.hexdigest()


# The library jitters ray starts with a hash of (pixel x, pixel y, seed)
# (shaders/render/raycast.frag: x*1973 + y*9277 + seed*26699 mod 2^32). A tile's
# pixels are numbered from its own corner, so tile_params adds the tile's
# offset through the seed: the tiled image then has the very same jitter as
# the whole one. tests/python/test_native.py checks the equality; if the
# shader's hash changes, update these constants (or, better, give the library
# a tile-origin parameter, see plugin/README.md).
_JITTER_X, _JITTER_Y, _JITTER_SEED = 1973, 9277, 26699
_JITTER_SEED_INV = pow(_JITTER_SEED, -1, 1 << 32)


def tile_params(params, x0, y0, x1, y1):
    """Params that render the pixel rectangle [x0, x1) x [y0, y1) (row 0 =
    bottom) of the image `params` describes, as an image of its own: the
    projection is narrowed to the rectangle, the scene depth is cropped and
    the jitter keeps the whole image's pattern. Needs an explicit camera."""
    W, H = params.width or 512, params.height or 512
    if not params.has_camera:
        raise ValueError("tiles need an explicit camera (view and proj)")
    if not (0 <= x0 < x1 <= W and 0 <= y0 < y1 <= H):
        raise ValueError("tile %r outside the %dx%d image" % ((x0, y0, x1, y1), W, H))
    t = RenderParams.from_buffer_copy(params)
    t._keep = []
    tf = getattr(params, "_tf", None)
    if params.tf_rgba and tf is None:
        raise ValueError("params.tf_rgba was not set by make_params")
    if tf is not None:  # the copy points at the same table: keep it alive
        t._keep.append(tf)
        t._tf = tf
    shapes = getattr(params, "_shapes", None)
    if params.light_shapes and shapes is None:
        raise ValueError("params.light_shapes was not set by make_params")
    if shapes is not None:  # the same light shapes
        t._keep.append(shapes)
        t._shapes = shapes
    for name in ("_cutaway", "_matcap", "_scene_shadows", "_occluders", "_overlays", "_overlay_tables",
                 "_environment", "_env_map"):  # the copy points at the same structs (holding their arrays)
        if hasattr(params, name):
            setattr(t, name, getattr(params, name))
    t.width, t.height = x1 - x0, y1 - y0
    a, b = 2.0 * x0 / W - 1.0, 2.0 * x1 / W - 1.0
    c, d = 2.0 * y0 / H - 1.0, 2.0 * y1 / H - 1.0
    m = np.eye(4)
    m[0, 0], m[0, 3] = 2.0 / (b - a), -(a + b) / (b - a)
    m[1, 1], m[1, 3] = 2.0 / (d - c), -(c + d) / (d - c)
    t.proj = _matrix_cm(m @ matrix_from_cm(params.proj))
    off = (x0 * _JITTER_X + y0 * _JITTER_Y) * _JITTER_SEED_INV
    t.jitter_seed = (params.jitter_seed + off) & 0xFFFFFFFF
    depth = getattr(params, "_scene_depth", None)
    if params.scene_depth and depth is None:
        raise ValueError("params.scene_depth was not set by make_params")
    if depth is not None:
        sub = np.ascontiguousarray(depth.reshape(H, W)[y0:y1, x0:x1])
        t._keep.append(sub)
        t._scene_depth = sub
        t.scene_depth = _fptr(sub)
    return t


def _empty_stats():
    return {"samples": 0, "rays": 0, "max_ray_samples": 0, "sample_bound": 0,
            "effective_step": 0.0, "bricks_total": 0, "bricks_occupied": 0,
            "brick_size": 0, "calls": 0, "seconds": 0.0, "storage_name": "", "resident_bytes": 0,
            "pages_total": 0, "pages_resident": 0, "pages_constant": 0, "lod_level": 0,
            "lod_wanted_bytes": 0, "decode_ms": 0.0,
            "refine_pending": 0, "stream_level": 0, "bytes_read": 0, "load_ms": 0.0}


def _merge_stats(acc, s):
    acc["samples"] += s["samples"]
    acc["rays"] += s["rays"]
    acc["max_ray_samples"] = max(acc["max_ray_samples"], s["max_ray_samples"])
    acc["sample_bound"] = max(acc["sample_bound"], s["sample_bound"])
    for k in ("effective_step", "bricks_total", "bricks_occupied", "brick_size", "storage_name",
              "resident_bytes", "pages_total", "pages_resident", "pages_constant", "lod_level",
              "lod_wanted_bytes", "decode_ms"):
        acc[k] = s[k]
    # (streamed volumes): every band's pending bricks and reads
    # count, and the frame is as coarse as its coarsest band.
    for k in ("refine_pending", "bytes_read", "load_ms"):
        acc[k] += s.get(k, 0)
    acc["stream_level"] = max(acc["stream_level"], s.get("stream_level", 0))
    return acc
