"""The optional render inputs as ctypes structs: the cutaway (clip
planes, crop box, cutter meshes, caps), the MatCap and a slice plane's
params, built from plain Python data (numbers, numpy arrays) so the
add-on's Blender side stays free of ctypes.

Each builder returns the struct and the numpy arrays that describe its
contents: make_params keeps both alive as long as the params, and the
arrays go into params._keep, which params_digest hashes instead of the
pointers (two frames with equal contents are the same frame).

Part of the ctypes binding; plugin/core/native.py re-exports it."""

import ctypes

import numpy as np

from .native_abi import (MAX_CLIP_PLANES, MAX_CUTTERS, Cutaway, Cutter, Matcap, SliceParams, _fptr,
                         _matrix_cm, _sized)

MAX_MATCAP_SIDE = 4096


def _u32ptr(arr):
    return arr.ctypes.data_as(ctypes.POINTER(ctypes.c_uint32))


def cutaway_struct(cutaway):
    """A Cutaway from a dict (every key optional):
        clip_planes: [((a, b, c, d), thickness), ...]  world plane, keeps
                     a x + b y + c z + d >= 0; thickness 0 = the half-space
        crop_box:    4x4 math matrix (box -> world; the box is [-1, 1]^3) or None
        cutters:     [(vertices (n, 3), triangles (m, 3), remove_outside), ...]
                     world-space closed meshes
        caps:        True (default) shades the cut faces with the cut's normal
    Returns (struct, arrays): the arrays are the cutters' buffers the struct
    points at plus one array of every number in it, for the digest."""
    planes = list(cutaway.get("clip_planes", ()))
    cutters = list(cutaway.get("cutters", ()))
    if len(planes) > MAX_CLIP_PLANES:
        raise ValueError("at most %d clip planes (got %d)" % (MAX_CLIP_PLANES, len(planes)))
    if len(cutters) > MAX_CUTTERS:
        raise ValueError("at most %d cutters (got %d)" % (MAX_CUTTERS, len(cutters)))
    c = _sized(Cutaway)
    numbers = []
    c.clip_plane_count = len(planes)
    for dst, (plane, thickness) in zip(c.clip_planes, planes):
        dst.plane[:] = [float(v) for v in plane]
        dst.thickness = float(thickness)
        numbers += list(dst.plane) + [dst.thickness]
    box = cutaway.get("crop_box")
    if box is not None:
        c.has_crop = 1
        c.crop_box = _matrix_cm(box)
        numbers += list(c.crop_box)
    c.caps_off = 0 if cutaway.get("caps", True) else 1
    numbers += [c.clip_plane_count, c.has_crop, c.caps_off, len(cutters)]
    arrays = []
    if cutters:
        arr = (Cutter * len(cutters))()
        for dst, (verts, tris, remove_outside) in zip(arr, cutters):
            v = np.ascontiguousarray(verts, dtype=np.float32).reshape(-1, 3)
            t = np.ascontiguousarray(tris, dtype=np.uint32).reshape(-1, 3)
            dst.struct_size = ctypes.sizeof(Cutter)
            dst.remove_outside = 1 if remove_outside else 0
            dst.vertices, dst.indices = _fptr(v), _u32ptr(t)
            dst.vertex_count, dst.triangle_count = len(v), len(t)
            numbers.append(dst.remove_outside)
            arrays += [v, t]
        c.cutter_count = len(cutters)
        c.cutters = ctypes.cast(arr, ctypes.POINTER(Cutter))
        c._cutters = arr  # the array the pointer points at lives with the struct
    c._arrays = arrays
    return c, arrays + [np.array(numbers, np.float64)]


def matcap_struct(image, key=0):
    """A Matcap from an image (height, width, 3 or 4) of linear floats, row
    0 = bottom (Blender's Image.pixels order). key: the caller's name for
    the image (nonzero: not uploaded again while it stays the same).
    Returns (struct, arrays) as cutaway_struct."""
    img = np.asarray(image, dtype=np.float32)
    if img.ndim != 3 or img.shape[2] not in (3, 4):
        raise ValueError("a MatCap is an (height, width, 3 or 4) image, got shape %r" % (img.shape,))
    h, w = img.shape[:2]
    if not (1 <= w <= MAX_MATCAP_SIDE and 1 <= h <= MAX_MATCAP_SIDE):
        raise ValueError("a MatCap is 1 to %d pixels per side, got %dx%d" % (MAX_MATCAP_SIDE, w, h))
    if img.shape[2] == 3:
        img = np.concatenate([img, np.ones((h, w, 1), np.float32)], axis=2)
    rgba = np.ascontiguousarray(img)
    m = _sized(Matcap)
    m.width, m.height = w, h
    m.rgba = _fptr(rgba)
    m.key = int(key) & 0xFFFFFFFFFFFFFFFF
    m._rgba = rgba
    return m, [rgba, np.array([w, h, m.key], np.uint64)]


def slice_struct(plane_to_world, interpolation):
    """SliceParams: plane_to_world a 4x4 math matrix (the slice is its
    square [-1, 1]^2 at z = 0), interpolation a VXL_INTERP_* number."""
    s = _sized(SliceParams)
    s.interpolation = int(interpolation)
    s.plane_to_world = _matrix_cm(plane_to_world)
    return s
