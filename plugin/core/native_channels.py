"""Channel styles as ctypes structs: params.channels built from plain
Python data, so the add-on's Blender side stays free of ctypes.

A channel style is a dict (every key but `channel` optional):
    channel        the channel's index in the volume (< its channel_count)
    hidden, solo   booleans (vxl_channel_style's hidden and solo)
    color          (r, g, b) in [0, 1], or None for the library's default
    window         (low, high) in the channel's data units, or None
    preset         a preset's name or VXL_PRESET_* (used without tf_rgba)
    tf_rgba        (n, 4) straight RGBA over the window
    opacity_scale  multiplies its opacity (1 = as the table says)

channel_array returns the struct array plus the numpy arrays that describe
its contents, as native_overlays.overlay_array does: make_params keeps both
as long as the params, and params_digest hashes the arrays.

Part of the ctypes binding; plugin/core/native.py re-exports it."""

import ctypes

import numpy as np

from .native_abi import MAX_CHANNELS, ChannelStyle, style_digest, style_table

_KEYS = {"channel", "hidden", "solo", "color", "window", "preset", "tf_rgba", "opacity_scale"}


def _from_dict(dst, d, lib):
    """Fills dst (a zeroed ChannelStyle) from dict d; returns its table or None."""
    unknown = set(d) - _KEYS
    if unknown:
        raise ValueError("unknown channel keys: %s" % ", ".join(sorted(unknown)))
    dst.channel = int(d["channel"])
    dst.hidden = 1 if d.get("hidden") else 0
    dst.solo = 1 if d.get("solo") else 0
    if d.get("color") is not None:
        dst.has_color = 1
        dst.color[:] = [float(v) for v in tuple(d["color"])[:3]]
    if d.get("window") is not None:
        dst.has_window = 1
        dst.window_low, dst.window_high = float(d["window"][0]), float(d["window"][1])
    preset = d.get("preset", 0)
    dst.preset = int(preset) if isinstance(preset, (int, np.integer)) else lib.preset_index(preset)
    dst.opacity_scale = float(d.get("opacity_scale", 1.0))
    return style_table(dst, d.get("tf_rgba"), "a channel")


def channel_array(channels, lib):
    """(ChannelStyle array, tables, digest arrays) of a sequence of dicts."""
    channels = list(channels)
    if len(channels) > MAX_CHANNELS:
        raise ValueError("at most %d channels (got %d)" % (MAX_CHANNELS, len(channels)))
    arr = (ChannelStyle * max(1, len(channels)))()
    tables, digest = [], []
    for dst, d in zip(arr, channels):
        tf = _from_dict(dst, d, lib)
        dst.struct_size = ctypes.sizeof(ChannelStyle)
        if tf is not None:
            tables.append(tf)
        digest.extend(([] if tf is None else [tf]) + [style_digest(dst)])
    return arr, tables, digest
