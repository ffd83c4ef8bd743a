"""The Channels sub-panel of a multi-channel volume (channel_props.py): a
list with a row per channel (name, colour swatch, visibility and solo
toggles), the blend, and for the active channel its window (data units of
that channel), opacity, opacity curve, dye presets and its histogram over
the window. When the channels cannot be drawn, an alert says why and that
channel 0 is drawn alone with the Transfer Function panel's settings."""

import bpy
import numpy as np

from . import channel_props, compat
from .core import channel_defaults, channel_plan
from .panels import _split, _VolumePanel, picture_icon

CHANNEL_PICTURE = (256, 128)  # a smaller picture than the scalar's: one channel's
_LINE_CHARS = 52


class VOXLIGHT_UL_channels(bpy.types.UIList):
    """One row per channel: name, colour, visibility, solo."""

    def draw_item(self, context, layout, data, item, icon, active_data, active_propname, index):
        row = layout.row(align=True)
        row.prop(item, "name", text="", emboss=False)
        sub = row.row(align=True)
        sub.scale_x = 0.45
        sub.prop(item, "color", text="")
        row.prop(item, "visible", text="", emboss=False,
                 icon="HIDE_OFF" if item.visible else "HIDE_ON")
        row.prop(item, "solo", text="", emboss=False,
                 icon="SOLO_ON" if item.solo else "SOLO_OFF")


def channel_table(ch, n=64):
    """The channel's look over its window as the histogram picture's table:
    its colour times the curve, the curve's opacity times its scale."""
    table = channel_plan.ramp_table(ch.ramp, n)
    if table is None:  # LINEAR: the library's GRAY preset
        v = np.linspace(0.0, 1.0, n, dtype=np.float32)
        table = np.stack([v, v, v, channel_plan.GRAY_OPACITY * v], axis=1)
    out = table.copy()
    out[:, :3] *= np.asarray(tuple(ch.color), np.float32)
    out[:, 3] *= ch.opacity
    return out


def _alert(layout, lines):
    box = layout.box()
    box.alert = True
    for k, line in enumerate(lines):
        for i, part in enumerate(compat.wrap(line, _LINE_CHARS)):
            box.label(text=part, icon="ERROR" if k == 0 and i == 0 else "BLANK1")


class VOXLIGHT_PT_volume_channels(_VolumePanel, bpy.types.Panel):
    bl_label = "Channels"
    bl_idname = "VOXLIGHT_PT_volume_channels"
    bl_parent_id = "VOXLIGHT_PT_volume"

    @classmethod
    def poll(cls, context):
        return super().poll(context) and len(context.object.voxlight.channels) >= 2

    def draw_header(self, context):
        self.layout.prop(context.object.voxlight, "use_channels", text="")

    def draw(self, context):
        obj = context.object
        p = obj.voxlight
        layout = self.layout
        if p.use_channels:
            why = channel_props.why_not(p) or channel_props.refusal(p)
            if why:
                _alert(layout, ["Channels not drawn: " + why,
                                "Channel 0 is drawn alone with the Transfer Function."])
            elif context.scene.voxlight.use_scene_lights and context.scene.voxlight.use_world_light \
                    and p.shading:
                layout.label(text="The World's light does not light channels", icon="INFO")
        else:
            layout.label(text="Channel 0 alone, with the Transfer Function", icon="INFO")
        layout.active = p.use_channels
        _split(layout.column()).prop(p, "channel_blend")
        row = layout.row()
        row.template_list("VOXLIGHT_UL_channels", "", p, "channels", p, "active_channel", rows=3)
        col = row.column(align=True)
        col.operator("voxlight.channel_show_all", text="", icon="HIDE_OFF")
        if not 0 <= p.active_channel < len(p.channels):
            return
        ch = p.channels[p.active_channel]
        box = layout.box()
        dye = channel_defaults.dye_of_color(ch.color)
        row = box.row()
        row.prop(ch, "color", text="")
        row.menu("VOXLIGHT_MT_channel_dyes", icon="COLOR",
                 text=dict((d[0], d[1]) for d in channel_defaults.DYES).get(dye, "Dye Presets"))
        box.template_icon(icon_value=picture_icon(
            "%s/channel %d" % (obj.name, p.active_channel), list(ch.histogram), ch.data_min,
            ch.data_max, ch.window_low, ch.window_high, channel_table(ch), CHANNEL_PICTURE),
            scale=8.0)
        col = _split(box.column(align=True))
        col.prop(ch, "window_low", text="Window")
        col.prop(ch, "window_high", text="High")
        box.label(text="Data %.6g to %.6g" % (ch.data_min, ch.data_max))
        box.operator("voxlight.channel_fit_window", icon="FULLSCREEN_EXIT")
        col = _split(box.column())
        col.prop(ch, "opacity", slider=True)
        col.prop(ch, "ramp")


# registered by panels.py, between the Voxlight panel and its other sub-panels
CLASSES = (VOXLIGHT_UL_channels, VOXLIGHT_PT_volume_channels)
