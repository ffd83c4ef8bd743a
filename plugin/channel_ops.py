"""Operators on a multi-channel volume's channels (channel_props.py): set a
channel's colour from a dye preset, fit its window to its data range, show
every channel again. Each is one undo step; scripts can equally set the
properties (obj.voxlight.channels[i].color = ...)."""

import bpy
from bpy.props import EnumProperty, IntProperty

from .core import channel_defaults
from .operators import OnActiveVolume

DYE_ITEMS = [(d[0], d[1], "The colour of %s" % d[1], i) for i, d in enumerate(channel_defaults.DYES)]


def _redraw():
    from .properties import tag_redraw
    tag_redraw()


class _OnChannels(OnActiveVolume):
    @classmethod
    def poll(cls, context):
        return super().poll(context) and len(context.object.voxlight.channels) > 0


class _OnOneChannel(_OnChannels):
    """An operator on one channel: `index`, or the active one (-1);
    apply(channel) does the work."""

    index: IntProperty(name="Channel", default=-1, min=-1,
                       description="The channel (-1: the active one)")

    def execute(self, context):
        p = context.object.voxlight
        i = p.active_channel if self.index < 0 else self.index
        if not 0 <= i < len(p.channels):
            self.report({"ERROR"}, "Voxlight: the volume has channels 0..%d, not %d"
                        % (len(p.channels) - 1, i))
            return {"CANCELLED"}
        self.apply(p.channels[i])
        _redraw()
        return {"FINISHED"}


class VOXLIGHT_OT_channel_dye(_OnOneChannel, bpy.types.Operator):
    """Colour the channel as its dye is usually shown"""
    bl_idname = "voxlight.channel_dye"
    bl_label = "Dye Preset"
    bl_options = {"REGISTER", "UNDO"}

    dye: EnumProperty(name="Dye", items=DYE_ITEMS)

    def apply(self, ch):
        ch.color = channel_defaults.DYE_COLORS[self.dye]


class VOXLIGHT_OT_channel_fit_window(_OnOneChannel, bpy.types.Operator):
    """Set the channel's window to its whole data range"""
    bl_idname = "voxlight.channel_fit_window"
    bl_label = "Fit Window to Data"
    bl_options = {"REGISTER", "UNDO"}

    def apply(self, ch):
        ch.window_low, ch.window_high = ch.data_min, ch.data_max


class VOXLIGHT_OT_channel_show_all(_OnChannels, bpy.types.Operator):
    """Show every channel and clear every solo"""
    bl_idname = "voxlight.channel_show_all"
    bl_label = "Show All Channels"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        for ch in context.object.voxlight.channels:
            ch.visible, ch.solo = True, False
        _redraw()
        return {"FINISHED"}


class VOXLIGHT_MT_channel_dyes(bpy.types.Menu):
    """The dye presets, for the active channel"""
    bl_idname = "VOXLIGHT_MT_channel_dyes"
    bl_label = "Dye Presets"

    def draw(self, context):
        for ident, name, _desc, _n in DYE_ITEMS:
            op = self.layout.operator(VOXLIGHT_OT_channel_dye.bl_idname, text=name)
            op.dye = ident


_classes = (VOXLIGHT_OT_channel_dye, VOXLIGHT_OT_channel_fit_window, VOXLIGHT_OT_channel_show_all,
            VOXLIGHT_MT_channel_dyes)

register, unregister = bpy.utils.register_classes_factory(_classes)
