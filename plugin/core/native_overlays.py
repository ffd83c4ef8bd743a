"""Overlays as ctypes structs: params.overlays built from plain
Python data, so the add-on's Blender side stays free of ctypes.

An overlay is a dict (every key but `slot` optional) or a ready
OverlayStyle:
    slot           the slot Renderer.set_overlay filled (< MAX_OVERLAYS)
    blend          "over" (default), "add", "max" or VXL_BLEND_*
    interpolation  "nearest", "linear", "cubic", VXL_INTERP_* or None (linear)
    preset         a preset's name or VXL_PRESET_* (used without tf_rgba)
    tf_rgba        (n, 4) straight RGBA, opacity per voxel of the base's path
    window         (low, high) in the overlay's data units, or None
    opacity_scale  multiplies its opacity (1 = as the table says)
    shading        False: emission only
    model          4x4 math matrix voxel -> world, or None for its own affine

overlay_array returns the struct array plus the numpy arrays that describe
its contents (the tables, and every field but the pointers): make_params
keeps both as long as the params, and params_digest hashes the arrays
instead of the pointers (equal contents, the same frame).

Part of the ctypes binding; plugin/core/native.py re-exports it."""

import ctypes

import numpy as np

from .native_abi import MAX_OVERLAYS, OverlayStyle, _fptr, _matrix_cm, style_digest, style_table


def _enum(lib, kind, value):
    return int(value) if isinstance(value, (int, np.integer)) else lib.index(kind, value)


def _from_dict(dst, d, lib):
    """Fills dst (a zeroed OverlayStyle) from dict d; returns its table or None."""
    unknown = set(d) - {"slot", "blend", "interpolation", "preset", "tf_rgba", "window",
                        "opacity_scale", "shading", "model"}
    if unknown:
        raise ValueError("unknown overlay keys: %s" % ", ".join(sorted(unknown)))
    dst.slot = int(d["slot"])
    dst.blend = _enum(lib, "blend", d.get("blend", "over"))
    if d.get("interpolation") is not None:
        dst.interpolation = _enum(lib, "interpolation", d["interpolation"])
        dst.interpolation_set = 1
    dst.preset = _enum(lib, "preset", d.get("preset", "auto"))
    window = d.get("window")
    if window is not None:
        dst.has_window = 1
        dst.window_low, dst.window_high = float(window[0]), float(window[1])
    dst.opacity_scale = float(d.get("opacity_scale", 1.0))
    dst.shading_off = 0 if d.get("shading", True) else 1
    if d.get("model") is not None:
        dst.has_model = 1
        dst.model = _matrix_cm(d["model"])
    return style_table(dst, d.get("tf_rgba"), "an overlay")


def overlay_array(overlays, lib):
    """(OverlayStyle array, tables, digest arrays) of a sequence of dicts or
    OverlayStyles (copied, their tables too)."""
    overlays = list(overlays)
    if len(overlays) > MAX_OVERLAYS:
        raise ValueError("at most %d overlays (got %d)" % (MAX_OVERLAYS, len(overlays)))
    arr = (OverlayStyle * max(1, len(overlays)))()
    tables, digest = [], []
    for dst, o in zip(arr, overlays):
        if isinstance(o, OverlayStyle):
            ctypes.memmove(ctypes.addressof(dst), ctypes.addressof(o), ctypes.sizeof(OverlayStyle))
            tf = np.ctypeslib.as_array(o.tf_rgba, (o.tf_size, 4)).copy() if o.tf_rgba and o.tf_size else None
            if tf is not None:  # our own copy, kept with the params
                dst.tf_rgba = _fptr(tf)
        else:
            tf = _from_dict(dst, o, lib)
        dst.struct_size = ctypes.sizeof(OverlayStyle)
        if tf is not None:
            tables.append(tf)
            digest.append(tf)
        digest.append(style_digest(dst))
    return arr, tables, digest
