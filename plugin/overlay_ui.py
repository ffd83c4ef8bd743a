"""The Overlays sub-panel of a volume object: the volumes linked
as its overlays (a list with Add / Remove) and whether its volume children
are overlays too; then, per overlay in slot order, its blend, opacity,
shading and interpolation (properties of the overlay object, so keyframes
go there). An overlay's own panel says which base draws it."""

import bpy

from . import overlay_frames, overlay_props
from .core import native
from .panels import _split, _VolumePanel


class VOXLIGHT_UL_overlay_links(bpy.types.UIList):
    """One row per linked overlay: the object to pick."""

    def draw_item(self, context, layout, data, item, icon, active_data, active_propname, index):
        layout.prop(item, "object", text="", icon="VOLUME_DATA")


def _draw_style(layout, ov):
    s = ov.voxlight_overlays
    box = layout.box()
    row = box.row()
    row.label(text=ov.name, icon="VOLUME_DATA")
    row.prop(s, "fuse", text="")
    col = _split(box.column())
    col.prop(s, "blend")
    col.prop(s, "opacity", slider=True)
    col.prop(s, "shading")
    col.prop(s, "interpolation")


class VOXLIGHT_PT_volume_overlays(_VolumePanel, bpy.types.Panel):
    """Collapsed by default: most volumes are drawn alone."""
    bl_idname = "VOXLIGHT_PT_volume_overlays"
    bl_parent_id = "VOXLIGHT_PT_volume"
    bl_options = {"DEFAULT_CLOSED"}
    bl_label = "Overlays"

    def draw(self, context):
        obj = context.object
        s = obj.voxlight_overlays
        layout = self.layout
        bases = overlay_props.bases_of(obj, context.scene)
        if bases:
            layout.label(text="Drawn inside %s" % ", ".join(b.name for b in bases), icon="INFO")
        _split(layout.column()).prop(s, "use_children")
        row = layout.row()
        row.template_list("VOXLIGHT_UL_overlay_links", "", s, "links", s, "active_index", rows=3)
        col = row.column(align=True)
        col.operator("voxlight.add_overlay", text="", icon="ADD")
        col.operator("voxlight.remove_overlay", text="", icon="REMOVE")
        overlays = overlay_props.listed(obj)
        note = overlay_frames.why_not(obj.voxlight) if overlays else ""
        problems = ([note] if note else []) + [p for p in overlay_frames.problems.get(obj.name, ())
                                              if p != note]
        if len(overlays) > native.MAX_OVERLAYS:
            problems.append("only the first %d overlays are drawn" % native.MAX_OVERLAYS)
        if problems:
            box = layout.box()
            box.alert = True
            for p in problems:
                for i in range(0, len(p), 70):
                    box.label(text=p[i:i + 70], icon="ERROR" if i == 0 else "NONE")
        for ov in overlays[:native.MAX_OVERLAYS]:
            _draw_style(layout, ov)
        if not overlays and not bases:
            layout.label(text="Link volumes here or parent them to this one")
        # As an overlay itself: its own blend and opacity are here too.
        if bases and obj not in overlays:
            _draw_style(layout, obj)


_classes = (VOXLIGHT_UL_overlay_links, VOXLIGHT_PT_volume_overlays)

register, unregister = bpy.utils.register_classes_factory(_classes)
