"""Every render mode starts useful (core/mode_fit.py decides the numbers).

The window (Low/High, the Transfer Function panel's) belongs to the mode
it was set in: switching modes keeps the old mode's window in
Object.voxlight.mode_windows and gives the new mode its own, kept from
the last time it was shown or, the first time, fitted to the data. So MIP
starts on the bright voxels, Average on the mixture of object and air,
ISO with its surface on the ramp's brightest colour, and going back to
Volume gives back the preset's window untouched. The ramp is shared.

The iso value is fitted at import (importer.py) and, for volumes that
never had it set (files from before), the first time ISO is picked.

Everything is a property write inside the render_mode update, so one undo
step covers the switch and scripts get the same starts as the panel."""

import bpy

from . import tf
from .core import mode_fit

_SLOT = {m: i for i, m in enumerate(mode_fit.MODES)}


def fit_iso(obj, info=None):
    """Set the iso value fitted to the data (Otsu on the histogram)."""
    obj.voxlight.iso_value = mode_fit.iso_value(tf.stats_of(obj, info))


def fitted_window(obj, mode):
    """(low, high) `mode` starts with on this volume, or None (DVR: the
    preset's placement)."""
    p = obj.voxlight
    if mode == "dvr":
        return None
    table = tf.table(p) if mode == "iso" else None
    return mode_fit.window(mode, tf.stats_of(obj), iso=p.iso_value, table=table)


def switched(props, context=None):
    """render_mode's update: store the window with the mode it was shown
    in, then give the new mode its own."""
    obj = props.id_data
    if not isinstance(obj, bpy.types.Object) or not props.is_volume:
        return
    new, old = props.render_mode, props.window_mode or "dvr"
    if new == old or new not in _SLOT or old not in _SLOT:
        props.window_mode = new if new in _SLOT else old
        return
    if new == "iso" and not props.is_property_set("iso_value"):
        fit_iso(obj)  # volumes imported before the iso value was fitted
    if new == "minip" and not props.is_property_set("minip_floor"):
        props.minip_floor = mode_fit.minip_floor(tf.stats_of(obj))
    windows = list(props.mode_windows)
    i, j = _SLOT[old], _SLOT[new]
    windows[2 * i], windows[2 * i + 1] = props.window_low, props.window_high
    known = props.mode_windows_set | (1 << i)
    if known & (1 << j):
        lo, hi = windows[2 * j], windows[2 * j + 1]
    else:
        lo_hi = fitted_window(obj, new)
        lo, hi = lo_hi if lo_hi is not None else (props.window_low, props.window_high)
    props.mode_windows = windows
    props.mode_windows_set = known
    props.window_mode = new
    props.window_low, props.window_high = lo, hi


def fit_window(obj):
    """The Fit Window button outside Volume mode: the mode's own fit."""
    lo_hi = fitted_window(obj, obj.voxlight.render_mode)
    if lo_hi is not None:
        obj.voxlight.window_low, obj.voxlight.window_high = lo_hi
    return lo_hi


def look_table(props, table):
    """The table a frame uses: a projection's ramp scaled to full opacity
    (mode_fit.projection_table), other modes' as they are."""
    if table is not None and props.render_mode in mode_fit.PROJECTIONS:
        return mode_fit.projection_table(table)
    return table
