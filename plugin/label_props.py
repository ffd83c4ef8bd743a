"""Label maps on a volume object: Object.voxlight_labels holds the
label image, its lookup file, how labels are drawn (surface / mask / tint,
the library's VXL_LABEL_MODE_* names), the boundaries (smooth or the raw
voxels, VXL_LABEL_BOUNDARY_*) and one entry per label (id, name,
colour with opacity as alpha, visible). Colours, visibility and the
boundaries are animatable; the viewport and F12 pass them as params.labels (look_kwargs,
called by params.look_kwargs), and runtime.entry_for puts the label volume
on the renderer (core/label_runtime.py). Hiding or recolouring a label
changes only the params, so the library re-uploads a small table."""

import os

import bpy
from bpy.props import (BoolProperty, CollectionProperty, EnumProperty, FloatProperty, FloatVectorProperty,
                       IntProperty, PointerProperty, StringProperty)

from .core import colour_space, label_import, label_runtime, native
from .operators import OnActiveVolume

_MODE_UI = {
    "surface": ("Surface", "Label-only: each visible label shaded as a surface in its colour"),
    "mask": ("Mask", "The transfer function, only inside visible labels (hidden ones are cut away)"),
    "tint": ("Tint", "The transfer function inside visible labels, its colour times the label's"),
}


def _mode_items():
    try:
        names = native.load_library().names("label_mode") or native.LABEL_MODES
    except native.LibraryUnavailable:
        names = native.LABEL_MODES
    return [(n, *_MODE_UI.get(n, (n.title(), n)), i) for i, n in enumerate(names)]


LABEL_MODE_ITEMS = _mode_items()

# The library's VXL_LABEL_BOUNDARY_* in order (the enum's number is the value).
LABEL_BOUNDARY_ITEMS = [
    ("smooth", "Smooth", "Each label's boundary smoothed (no voxel stairs), as MRIcroGL and Slicer show labels", 0),
    ("voxels", "Voxels", "The raw voxels: each label's boundary on its voxels' faces", 1),
]


def tag_redraw(self=None, context=None):
    from .properties import tag_redraw as redraw
    redraw(self, context)


class VoxlightLabel(bpy.types.PropertyGroup):
    """One label; `name` (the PropertyGroup's own) is the lookup file's."""
    label_id: IntProperty(name="ID", min=0, max=native.MAX_LABEL_ID,
                          description="The label's value in the label image")
    color: FloatVectorProperty(name="Color", subtype="COLOR", size=4, min=0.0, max=1.0,
                               default=(1.0, 1.0, 1.0, 1.0), update=tag_redraw,
                               description="Colour; alpha is the opacity")
    visible: BoolProperty(name="Visible", default=True, update=tag_redraw,
                          description="Show this label (hidden labels are not drawn)")
    use_material: BoolProperty(name="Own Material", default=False, update=tag_redraw,
                               description="Light this label with its own material instead of the volume's")
    ambient: FloatProperty(name="Ambient", default=0.3, min=0.0, soft_max=1.0, update=tag_redraw,
                           description="The label's ambient light")
    diffuse: FloatProperty(name="Diffuse", default=0.7, min=0.0, soft_max=1.0, update=tag_redraw,
                           description="The label's diffuse reflection")
    specular: FloatProperty(name="Specular", default=0.3, min=0.0, soft_max=1.0, update=tag_redraw,
                            description="The label's specular highlight")
    shininess: FloatProperty(name="Shininess", default=24.0, min=0.01, soft_max=128.0, update=tag_redraw,
                             description="How sharp the label's highlight is")


class VoxlightLabelSettings(bpy.types.PropertyGroup):
    enabled: BoolProperty(name="Use Labels", default=False, update=tag_redraw,
                          description="Draw the volume with its label map")
    filepath: StringProperty(name="Label Image", subtype="FILE_PATH", update=tag_redraw,
                             description="Integer volume of label ids (same grid as the volume "
                                         "or its own, placed by its affine)")
    lookup_file: StringProperty(name="Lookup File", subtype="FILE_PATH",
                                description="Names and colours of the labels (FreeSurfer LUT, "
                                            "ITK-SNAP, Slicer .ctbl, MRIcron .lut/.txt)")
    mode: EnumProperty(name="Label Mode", items=LABEL_MODE_ITEMS, update=tag_redraw,
                       description="How the labels are drawn")
    boundary: EnumProperty(name="Boundaries", items=LABEL_BOUNDARY_ITEMS, default="smooth", update=tag_redraw,
                           description="How label boundaries are drawn: smoothed, or the raw voxels' faces")
    labels: CollectionProperty(type=VoxlightLabel)
    active_index: IntProperty(name="Active Label", default=0)
    error: StringProperty(name="Error", options={"SKIP_SAVE"})

    @property
    def active_path(self):
        """The label image to put on the renderer ("" = none)."""
        if not (self.enabled and self.filepath):
            return ""
        return bpy.path.abspath(self.filepath, library=self.id_data.library)


def read_lookup(path):
    """(labels of the lookup file at absolute `path`, "") or (None, message)."""
    try:
        if not os.path.isfile(path):
            raise native.VoxlightError("lookup file %s not found" % path)
        return native.load_label_table(path), ""
    except (native.VoxlightError, native.LibraryUnavailable, OSError) as e:
        return None, str(e)


def fill_labels(settings, table):
    """settings.labels from load_label_table's list (the background, id 0, is
    never drawn and not listed)."""
    settings.labels.clear()
    for t in table:
        if t["id"] == 0:
            continue
        item = settings.labels.add()
        item.label_id = t["id"]
        item.name = t["name"] or "Label %d" % t["id"]
        item.color = colour_space.rgba_to_linear(t["color"])  # lookup files hold sRGB
        item.visible = t["visible"]
    settings.active_index = 0
    settings.error = ""
    tag_redraw()


def load_lookup(settings, path=None):
    """Fills settings.labels from the lookup file (settings.lookup_file, or
    `path`, which becomes it). Returns "" or the error's message; on error
    the list is left as it was."""
    if path is not None:
        settings.lookup_file = path
    if not settings.lookup_file:
        settings.error = "no lookup file chosen"
        return settings.error
    table, err = read_lookup(bpy.path.abspath(settings.lookup_file, library=settings.id_data.library))
    if table is None:
        settings.error = err
        return err
    fill_labels(settings, table)
    return ""


def attach(obj, label_path, lookup_path, table, mode):
    """Makes obj draw the labels of label_path (absolute) named by table."""
    s = obj.voxlight_labels
    s.filepath = label_path
    s.lookup_file = lookup_path
    s.mode = mode
    fill_labels(s, table)
    s.enabled = True


def look_kwargs(props):
    """make_params' labels=(mode, [(id, rgba, visible), ...], boundary) for a volume
    object (props: Object.voxlight), or {} when it draws no labels (then
    its frames are exactly those of a volume without labels)."""
    ob = getattr(props, "id_data", None)
    s = getattr(ob, "voxlight_labels", None)
    if s is None or not s.active_path or not label_runtime.usable(s.active_path):
        return {}
    return {"labels": (s.mode, [(lab.label_id, tuple(lab.color), bool(lab.visible), label_material(lab))
                                for lab in s.labels], s.boundary)}


def own_label_ids(obj, entry):
    """The distinct ids of obj's label image when it is the volume's own
    file (a labels object: entry.info's distinct_ids), else None (unknown)."""
    s = obj.voxlight_labels
    path = s.active_path
    if not path or os.path.abspath(path) != os.path.abspath(entry.path):
        return None
    return entry.info.get("distinct_ids")


def label_material(lab):
    """The label's own (ambient, diffuse, specular, shininess), or None for the volume's."""
    if not lab.use_material:
        return None
    return (lab.ambient, lab.diffuse, lab.specular, lab.shininess)


class VOXLIGHT_OT_load_label_lookup(OnActiveVolume, bpy.types.Operator):
    """Read the label names and colours from the lookup file (replaces the list)"""
    bl_idname = "voxlight.load_label_lookup"
    bl_label = "Load Lookup File"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        err = load_lookup(context.object.voxlight_labels)
        if err:
            self.report({"ERROR"}, "Voxlight: %s" % err)
            return {"CANCELLED"}
        return {"FINISHED"}


class VOXLIGHT_OT_label_visibility(OnActiveVolume, bpy.types.Operator):
    """Show or hide every label (those filtered out of the list too)"""
    bl_idname = "voxlight.label_visibility"
    bl_label = "Show/Hide All Labels"
    bl_options = {"REGISTER", "UNDO"}

    visible: BoolProperty(name="Visible", default=True)

    def execute(self, context):
        for lab in context.object.voxlight_labels.labels:
            lab.visible = self.visible
        tag_redraw()
        return {"FINISHED"}


class VOXLIGHT_OT_use_as_labels(OnActiveVolume, bpy.types.Operator):
    """Draw this volume as the label map of its own file (or as an intensity
    volume again), without importing it again: for a guess that went the
    wrong way"""
    bl_idname = "voxlight.use_as_labels"
    bl_label = "Use as Label Map"
    bl_options = {"REGISTER", "UNDO"}

    labels: BoolProperty(name="Labels", default=True,
                         description="On: its values are label ids; off: an intensity volume")

    def execute(self, context):
        obj = context.object
        s = obj.voxlight_labels
        if not self.labels:
            s.enabled = False
            return {"FINISHED"}
        own = bpy.path.abspath(obj.voxlight.filepath, library=obj.library)
        if not s.filepath or not s.labels or \
                os.path.abspath(bpy.path.abspath(s.filepath)) != os.path.abspath(own):
            lookup = bpy.path.abspath(s.lookup_file) if s.lookup_file else ""
            found = label_import.candidates(own, lookup)
            if not found:
                self.report({"ERROR"}, "Voxlight: no lookup file beside %s: choose one in "
                                       "Labels > Lookup File" % os.path.basename(own))
                return {"CANCELLED"}
            table, err = read_lookup(found[0][0])
            if table is None:
                self.report({"ERROR"}, "Voxlight: %s" % err)
                return {"CANCELLED"}
            attach(obj, own, found[0][0], table, "surface")
        s.enabled = True
        return {"FINISHED"}


_classes = (VoxlightLabel, VoxlightLabelSettings, VOXLIGHT_OT_load_label_lookup,
            VOXLIGHT_OT_label_visibility, VOXLIGHT_OT_use_as_labels)


_register_classes, _unregister_classes = bpy.utils.register_classes_factory(_classes)


def register():
    _register_classes()
    bpy.types.Object.voxlight_labels = PointerProperty(type=VoxlightLabelSettings)


def unregister():
    del bpy.types.Object.voxlight_labels
    _unregister_classes()
