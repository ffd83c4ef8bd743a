"""The channels of a multi-channel volume (docs/channels.md, "In Blender"):
Object.voxlight.channels holds one VoxlightChannel per channel of the file,
in the library's channel order (channels[N] is channel N), each with its
name, colour, visibility, solo, window (data units of that channel),
opacity scale and opacity curve, and its histogram; Object.voxlight's
channel_blend says how they combine (Add or Max) and use_channels whether
they are drawn at all (off: the scalar, channel 0, with the volume's own
transfer function, as a one-channel file).

Everything that changes the look is animatable (colour, visibility, solo,
window, opacity), and the viewport and F12 pass them as params.channels
(look_kwargs, called by params.look_kwargs). When the volume's other
settings cannot go with channels (core/channel_plan.conflict), look_kwargs
draws the scalar alone and the Channels panel shows why (why_not).
Defaults at import: core/channel_defaults.py (fill)."""

import bpy
from bpy.props import (BoolProperty, EnumProperty, FloatProperty, FloatVectorProperty,
                       IntVectorProperty)

from .core import channel_defaults, channel_plan, runtime

HISTOGRAM_BINS = 32  # as the scalar's, saved with the object

def _redraw(self, context):
    from .properties import tag_redraw
    tag_redraw(self, context)


class VoxlightChannel(bpy.types.PropertyGroup):
    # name: PropertyGroup's own, shown in the list and editable
    color: FloatVectorProperty(name="Color", subtype="COLOR", size=3, min=0.0, max=1.0,
                               default=(1.0, 1.0, 1.0), update=_redraw,
                               description="The channel's colour (scene-linear), times its "
                                           "brightness over the window")
    visible: BoolProperty(name="Visible", default=True, update=_redraw,
                          description="Draw this channel")
    solo: BoolProperty(name="Solo", default=False, update=_redraw,
                       description="Draw only the solo channels while any visible one is solo")
    window_low: FloatProperty(name="Low", default=0.0, update=_redraw,
                              description="The channel's value (its own data units) where it "
                                          "starts to show")
    window_high: FloatProperty(name="High", default=1.0, update=_redraw,
                               description="The channel's value (its own data units) where it "
                                           "is brightest and most opaque")
    opacity: FloatProperty(name="Opacity", default=1.0, min=0.0, soft_max=4.0, max=100.0,
                           update=_redraw,
                           description="Makes this channel more (above 1) or less (below 1) "
                                       "opaque")
    ramp: EnumProperty(name="Curve", default="LINEAR", update=_redraw,
                       items=[(r[0], r[1], r[2], i) for i, r in enumerate(channel_plan.RAMPS)],
                       description="How brightness and opacity grow from Low to High")
    # --- data, set at import (not animatable)
    data_min: FloatProperty(name="Data Minimum", options=set(),
                            description="The channel's lowest value (its data units)")
    data_max: FloatProperty(name="Data Maximum", options=set(),
                            description="The channel's highest value (its data units)")
    histogram: IntVectorProperty(name="Histogram", size=HISTOGRAM_BINS, options=set(),
                                 description="Voxel counts in 32 bins over the channel's range")


CLASSES = (VoxlightChannel,)

BLEND_ITEMS = [
    ("add", "Add", "Each channel glows on its own and the images add up (napari's and "
                   "Imaris' additive blending): overlapping channels mix their colours", 0),
    ("max", "Max", "At each step the most opaque channel wins and hides what is behind it", 1),
]


def fill(props, info):
    """The channels of a freshly loaded volume (props: Object.voxlight, info:
    the entry's information): its defaults (channel_defaults) and the
    histograms the loader counted. A one-channel volume gets none."""
    props.channels.clear()
    hists = info.get("channel_histograms") or []
    for c, d in enumerate(channel_defaults.channel_defaults(info)):
        ch = props.channels.add()
        ch.name = d["name"]
        ch.color = d["color"]
        ch.data_min, ch.data_max = d["range"]
        ch.window_low, ch.window_high = d["window"]
        ch.visible = d["visible"]
        if c < len(hists):
            ch.histogram = [int(min(n, 2**31 - 1)) for n in hists[c]]
    props.active_channel = 0
    if props.channels:
        # Fluorescence is drawn as light: the Phong model (the one the
        # library lights channels with) and emission only, as napari and
        # Imaris show it at first; Lighting's checkbox turns shading on.
        props.shading_model = "phong"
        props.shading = False


def why_not(props):
    """Why this volume's channels are not drawn now ("" when they are)."""
    from . import label_props, overlay_props
    ob = props.id_data
    return channel_plan.conflict(
        render_mode=props.render_mode, classify=props.classify,
        gradient_opacity=props.gradient_opacity, shading=props.shading,
        shading_model=props.shading_model, labels=bool(label_props.look_kwargs(props)),
        overlays=bool(overlay_props.listed(ob.original if ob.original is not None else ob)))


def refusal(props):
    """What the library said when it last refused this volume's channels
    ("" when it drew them): the frame was drawn with the scalar alone."""
    entry = runtime.find_entry(bpy.path.abspath(props.filepath), props.series)
    return runtime.channel_refusal(entry)


def drawn(props):
    """Whether this volume's frames draw its channels (not its scalar alone)."""
    return len(props.channels) >= 2 and props.use_channels and not why_not(props)


def look_kwargs(props):
    """make_params' channels and channel_blend for a volume object
    (props: Object.voxlight), or {} when it draws its scalar alone: one
    channel, Draw Channels off, or a setting that cannot go with channels
    (why_not, which the panel shows)."""
    if not drawn(props):
        return {}
    return {"channels": channel_plan.styles(props.channels), "channel_blend": props.channel_blend}
