"""The Labels sub-panel of a volume object: the label image and
lookup file, the label mode and boundaries, and a list of the labels (searchable by name
with the list's own filter) with colour, opacity and visibility per row,
Show All / Hide All and how many labels are visible; the active label's id
and own material below."""

import bpy

from .core import label_runtime
from .panels import _split, _VolumePanel


# The share of the row beside the visibility icon and swatch that the name
# gets; the opacity slider takes the rest. Five items (visibility, swatch,
# name, opacity, id) used to share a row about evenly, which cut AAL's names
# to "Fronta..." at the Properties editor's default width; its longest names
# ("Frontal_Sup_Medial_L", 20 characters) need about three times what a
# fifth of the row gave. The id, which few users need, is shown with the
# active label below the list.
NAME_SHARE = 0.7


class VOXLIGHT_UL_labels(bpy.types.UIList):
    """One row per label: visibility, colour (alpha is the opacity), name, opacity."""

    def draw_item(self, context, layout, data, item, icon, active_data, active_propname, index):
        row = layout.row(align=True)
        row.prop(item, "visible", text="", emboss=False,
                 icon="HIDE_OFF" if item.visible else "HIDE_ON")
        sub = row.row(align=True)
        sub.scale_x = 0.35
        sub.prop(item, "color", text="")
        split = row.split(factor=NAME_SHARE, align=True)
        split.label(text=item.name)
        split.prop(item, "color", index=3, text="", slider=True)  # opacity


def visible_count(settings):
    return sum(1 for lab in settings.labels if lab.visible)


class VOXLIGHT_PT_volume_labels(_VolumePanel, bpy.types.Panel):
    """Collapsed by default: most volumes have no label map."""
    bl_idname = "VOXLIGHT_PT_volume_labels"
    bl_parent_id = "VOXLIGHT_PT_volume"
    bl_options = {"DEFAULT_CLOSED"}
    bl_label = "Labels"

    def draw_header(self, context):
        self.layout.prop(context.object.voxlight_labels, "enabled", text="")

    def draw(self, context):
        s = context.object.voxlight_labels
        # A wrong guess at import is undone here, without importing again.
        row = self.layout.row(align=True)
        row.operator("voxlight.use_as_labels", text="Intensity Volume",
                     depress=not s.enabled).labels = False
        row.operator("voxlight.use_as_labels", text="Label Map", depress=s.enabled).labels = True
        layout = _split(self.layout)
        col = layout.column()
        col.prop(s, "filepath")
        row = col.row(align=True)
        row.prop(s, "lookup_file")
        row.operator("voxlight.load_label_lookup", text="", icon="FILE_REFRESH")
        col.prop(s, "mode")
        col.prop(s, "boundary")
        err = s.error or label_runtime.failure(s.active_path)
        if err:
            box = layout.box()
            box.alert = True
            for i in range(0, len(err), 70):
                box.label(text=err[i:i + 70], icon="ERROR" if i == 0 else "NONE")
        layout.use_property_split = False
        layout.template_list("VOXLIGHT_UL_labels", "", s, "labels", s, "active_index", rows=6)
        row = layout.row(align=True)
        row.operator("voxlight.label_visibility", text="Show All", icon="HIDE_OFF").visible = True
        row.operator("voxlight.label_visibility", text="Hide All", icon="HIDE_ON").visible = False
        layout.label(text="%d of %d labels visible" % (visible_count(s), len(s.labels)))
        if 0 <= s.active_index < len(s.labels):  # the active label's own material
            lab = s.labels[s.active_index]
            box = layout.box()
            box.use_property_split = True
            box.label(text="%s: id %d" % (lab.name or "Label", lab.label_id))
            box.prop(lab, "use_material", text="Own Material (%s)" % (lab.name or lab.label_id))
            col = box.column(align=True)
            col.active = lab.use_material
            for name in ("ambient", "diffuse", "specular", "shininess"):
                col.prop(lab, name)


_classes = (VOXLIGHT_UL_labels, VOXLIGHT_PT_volume_labels)

register, unregister = bpy.utils.register_classes_factory(_classes)
