"""A multi-channel volume's per-channel defaults in the add-on (no bpy,
tested in plain Python): each channel's name, colour, dye and window, from
the volume's information.

Names and colours come from the file's metadata when the information
carries them (`channel_names`, `channel_colors`: read with getattr / get,
so an information object without them, as the library gives today, works
unchanged); otherwise a channel is "Channel N" (N = the library's channel
index, the one `--channel N` and `obj.voxlight.channels[N]` use) in the
library's default colour of its index. A name that names a known dye
("DAPI", "GFP", "Alexa 647", ...) takes that dye's colour when the metadata
gives none. Colours are scene-linear RGB in [0, 1], as every colour of the
add-on (core/colour_space.py).
"""

from . import colour_space, native_abi

# The library's default colour of channel index c (frame_channels.c,
# vxl_channel_default_color): red, green, blue, magenta, cyan, yellow,
# orange, white. The same table here so a channel's swatch shows what the
# library draws when the style gives no colour.
LIBRARY_COLORS = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0), (1.0, 0.0, 1.0),
                  (0.0, 1.0, 1.0), (1.0, 1.0, 0.0), (1.0, 0.5, 0.0), (1.0, 1.0, 1.0))

# Dye presets: (identifier, UI name, colour, the words that name the dye in
# a channel name, lower case). Pure display colours as napari, Imaris and
# Fiji give them: a fluorophore's emission is drawn as the primary or
# secondary nearest to it, so channels stay apart when added.
DYES = (
    ("DAPI", "DAPI / Hoechst (blue)", (0.0, 0.0, 1.0), ("dapi", "hoechst", "405")),
    ("GFP", "GFP / FITC / Alexa 488 (green)", (0.0, 1.0, 0.0),
     ("gfp", "fitc", "488", "egfp", "alexa488")),
    ("YFP", "YFP / Venus (yellow)", (1.0, 1.0, 0.0), ("yfp", "venus", "514")),
    ("CY3", "Cy3 / TRITC / Alexa 555 (orange)", (1.0, 0.5, 0.0),
     ("cy3", "tritc", "555", "546", "561")),
    ("MCHERRY", "mCherry / Texas Red / Alexa 594 (red)", (1.0, 0.0, 0.0),
     ("mcherry", "texas", "594", "rfp", "tdtomato")),
    ("CY5", "Cy5 / Alexa 647 / far-red (magenta)", (1.0, 0.0, 1.0),
     ("cy5", "647", "far-red", "farred", "640")),
    ("CFP", "CFP (cyan)", (0.0, 1.0, 1.0), ("cfp", "cerulean")),
    ("GRAY", "Brightfield / Grey (white)", (1.0, 1.0, 1.0),
     ("brightfield", "bright field", "transmitted", "dic", "phase")),
)
DYE_COLORS = {d[0]: d[2] for d in DYES}


def dye_of_color(rgb, tol=1e-3):
    """The dye preset whose colour `rgb` is, or "" (a colour of its own)."""
    for ident, _ui, colour, _words in DYES:
        if all(abs(float(a) - b) <= tol for a, b in zip(tuple(rgb)[:3], colour)):
            return ident
    return ""


def default_name(c):
    return "Channel %d" % c


def dye_of_name(name):
    """The dye a channel's name names ("DAPI", "anti-GFP 488", ...), or ""."""
    text = (name or "").lower().replace(" ", "")
    for ident, _ui, _rgb, words in DYES:
        if any(w.replace(" ", "") in text for w in words):
            return ident
    return ""


def _field(info, key):
    """info[key] of an information dict, or its attribute (None: absent)."""
    if isinstance(info, dict):
        return info.get(key)
    return getattr(info, key, None)


def _listed(values, c):
    """values[c] when values lists one for channel c (else None); bytes decoded."""
    if values is None:
        return None
    try:
        v = values[c]
    except (IndexError, KeyError, TypeError):
        return None
    if isinstance(v, bytes):
        v = v.decode("utf-8", "replace")
    return v


def _colour(value):
    """A scene-linear (r, g, b) from a metadata colour, or None when it is
    not one. Metadata colours are display colours (OME writes the sRGB
    colour a viewer shows), so they are decoded to linear as a lookup
    file's label colours are."""
    try:
        rgb = tuple(float(x) for x in value)[:3]
    except (TypeError, ValueError):
        return None
    if len(rgb) != 3 or not all(0.0 <= x <= 1.0 for x in rgb):
        return None
    return tuple(float(v) for v in colour_space.srgb_to_linear(rgb))


def channel_count(info):
    n = int(_field(info, "channel_count") or 0)
    return n if 2 <= n <= native_abi.MAX_CHANNELS else 0


def channel_defaults(info):
    """[{name, color, dye, window: (lo, hi), range: (lo, hi), visible,
    decided}, ...] per channel of a multi-channel volume's information (a
    dict as Volume.info, or the library's info struct), [] for a
    one-channel volume. `decided` says where the colour came from
    ("metadata", "dye named", "default of its index"), for the panel and
    the notes. The file's display window (`channel_windows`, a (lo, hi) or
    None per channel) and visibility (`channel_active`) are taken when it
    gives them; else the window is the channel's range and it is shown."""
    n = channel_count(info)
    lows, highs = _field(info, "channel_min"), _field(info, "channel_max")
    names, colours = _field(info, "channel_names"), _field(info, "channel_colors")
    windows, active = _field(info, "channel_windows"), _field(info, "channel_active")
    out = []
    for c in range(n):
        name = _listed(names, c)
        name = name.strip() if isinstance(name, str) and name.strip() else default_name(c)
        lo = float(_listed(lows, c) or 0.0)
        hi = float(_listed(highs, c) or 0.0)
        if not hi > lo:
            hi = lo + 1.0
        dye = dye_of_name(name) if name != default_name(c) else ""
        colour = _colour(_listed(colours, c))
        if colour is not None:
            decided = "metadata"
        elif dye:
            colour, decided = DYE_COLORS[dye], "dye named"
        else:
            colour, decided = LIBRARY_COLORS[c % len(LIBRARY_COLORS)], "default of its index"
        window = _listed(windows, c)
        try:
            wlo, whi = (float(window[0]), float(window[1])) if window is not None else (lo, hi)
        except (TypeError, ValueError, IndexError):
            wlo, whi = lo, hi
        if not whi > wlo:
            wlo, whi = lo, hi
        shown = _listed(active, c)
        out.append(dict(name=name, color=colour, dye=dye, window=(wlo, whi), range=(lo, hi),
                        visible=True if shown is None else bool(shown), decided=decided))
    return out
