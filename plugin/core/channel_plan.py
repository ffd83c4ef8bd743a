"""What a multi-channel volume's frame draws (no bpy, tested in plain
Python): whether its settings let the library draw the channels at all
(conflict: the same rules as the library's frame_channels.c, checked
before the frame so the panel can say why and the scalar is drawn alone,
never a failed frame), and the channel styles make_params takes (styles)
from the channels' settings: visibility, solo, colour, window, opacity
scale and opacity curve.

A channel is anything with the attributes of Object.voxlight.channels'
items (channel_props.VoxlightChannel): visible, solo, color, window_low,
window_high, opacity, ramp."""

import numpy as np

# Opacity curves of a channel over its window, t = 0 at Low, 1 at High:
# (identifier, UI name, description, f(t)). A channel's colour is its
# colour times f(t) and its opacity per voxel 0.1 f(t) times its opacity
# scale: LINEAR is exactly the library's GRAY preset (frame/transfer.c),
# which a style without a table gets, so LINEAR sends no table.
RAMPS = (
    ("LINEAR", "Linear", "Brightness and opacity grow evenly from Low to High", None),
    ("DIM", "Dim Background", "Quadratic: faint values fade, bright structures stand out",
     lambda t: t * t),
    ("BRIGHT", "Bright", "Square root: faint structures show clearly", np.sqrt),
    ("SOLID", "Solid", "A smooth step in the middle of the window: a surface-like look",
     lambda t: t * t * (3.0 - 2.0 * t)),
)
_RAMP_CURVES = {r[0]: r[3] for r in RAMPS}
GRAY_OPACITY = 0.1  # the GRAY preset's opacity at its top (frame/transfer.c)
TABLE_SIZE = 256


def ordered_window(lo, hi):
    """(low, high) with low < high: a window dragged past itself is
    flipped, an empty one widened by a hair (the library refuses both)."""
    lo, hi = sorted((float(lo), float(hi)))
    if hi <= lo:
        hi = lo + max(abs(lo), 1.0) * 1e-6
    return lo, hi


def ramp_table(ramp, n=TABLE_SIZE):
    """The (n, 4) straight-RGBA table of an opacity curve (white times the
    curve, opacity GRAY_OPACITY times it), None for LINEAR (the library's
    GRAY preset is that curve) and for an unknown name."""
    f = _RAMP_CURVES.get(ramp)
    if f is None:
        return None
    v = np.clip(f(np.linspace(0.0, 1.0, n)), 0.0, 1.0)
    return np.stack([v, v, v, GRAY_OPACITY * v], axis=1).astype(np.float32)


def conflict(render_mode="dvr", classify="post", gradient_opacity="off", shading=True,
             shading_model="phong", labels=False, overlays=False):
    """Why the library cannot draw channels with these settings ("" when it
    can), as a sentence the panel shows. The same rules as frame_channels.c
    (check_combination); every storage mode draws channels."""
    if render_mode != "dvr":
        return "channels are drawn in the DVR render mode only (MIP, MinIP, Average and ISO " \
               "project one scalar)"
    if classify != "post":
        return "channels need Post classification (Advanced)"
    if gradient_opacity != "off":
        return "channels need Edges off (Advanced)"
    if shading and shading_model != "phong":
        return "channels are lit with the Phong model only: pick Phong or turn Lighting off"
    if labels:
        return "channels are not drawn together with labels"
    if overlays:
        return "channels are not drawn together with overlays"
    return ""


def _clamped_colour(rgb):
    # Keyframes between colours can overshoot [0, 1] (Bezier), which the
    # library refuses: the colour is clamped instead.
    return tuple(float(min(max(v, 0.0), 1.0)) for v in tuple(rgb)[:3])


def styles(channels):
    """make_params' `channels`: one dict per channel, in index order, every
    channel listed (a hidden one with hidden set, so toggling visibility
    changes a flag, not the list)."""
    out = []
    for c, ch in enumerate(channels):
        # solo only on a visible channel: the library counts a hidden
        # channel's solo too, which would hide every other one
        d = dict(channel=c, hidden=not ch.visible, solo=bool(ch.solo and ch.visible),
                 color=_clamped_colour(ch.color),
                 window=ordered_window(ch.window_low, ch.window_high),
                 opacity_scale=max(float(ch.opacity), 0.0))
        table = ramp_table(ch.ramp)
        if table is not None:
            d["tf_rgba"] = table
        out.append(d)
    return out


def drawn(channels):
    """The indices of the channels a frame draws: the visible solo ones
    when any visible channel is solo, else every visible one (hidden wins
    over solo)."""
    shown = [c for c, ch in enumerate(channels) if ch.visible]
    solo = [c for c in shown if channels[c].solo]
    return solo or shown
