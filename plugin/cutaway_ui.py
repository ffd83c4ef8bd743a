"""The UI: the volume's Render Mode and Cutaway sub-panels, the
Slice Plane panel of a plane object, and the operators that set up what
artists expect: a clip plane (an arrow Empty through the volume's centre,
its arrow pointing at the kept side), a crop box (a cube Empty around the
volume), a cutter slot, and a slice plane (a mesh plane across the volume,
showing it)."""

import bpy
import numpy as np
from bpy.props import EnumProperty, IntProperty

from . import cutaway, cutaway_props, params, slice_planes
from .core import volume_space
from .operators import OnActiveVolume
from .panels import _VolumePanel
from .properties import tag_redraw


def _split(layout, decorate=True):
    layout.use_property_split = True
    layout.use_property_decorate = decorate
    return layout


def _volume_frame(obj):
    """(centre, half extents along the volume's own axes (3 vectors)) in world space."""
    model = params.model_matrix(obj)
    corners = volume_space.world_corners(model, tuple(obj.voxlight.dims))
    centre = np.asarray(corners, np.float64).mean(axis=0)
    dims = np.asarray(obj.voxlight.dims, np.float64)
    axes = [model[:3, i] * dims[i] / 2.0 for i in range(3)]
    return centre, axes


def _link(context, ob):
    context.collection.objects.link(ob) if context.collection is not None else \
        context.scene.collection.objects.link(ob)


def _basis(axes):
    """Rotation (3x3) whose columns are the volume's axes, normalised."""
    return np.stack([a / max(np.linalg.norm(a), 1e-12) for a in axes], axis=1)


def _matrix(centre, rot, scale):
    m = np.eye(4)
    m[:3, :3] = rot * np.asarray(scale, np.float64)
    m[:3, 3] = centre
    return m


def _set_matrix(ob, m):
    from mathutils import Matrix
    ob.matrix_world = Matrix([list(r) for r in m])


# ------------------------------------------------------------ operators

def _new_empty(context, name, display, size, m):
    e = bpy.data.objects.new(name, None)
    e.empty_display_type = display
    e.empty_display_size = size
    _set_matrix(e, m)
    _link(context, e)
    tag_redraw()
    return e


class VOXLIGHT_OT_add_clip_plane(OnActiveVolume, bpy.types.Operator):
    """Add a clip plane: an arrow Empty through the volume's centre; the volume on its
    arrow's side is kept. Move and turn it to cut"""
    bl_idname = "voxlight.add_clip_plane"
    bl_label = "Add Clip Plane"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        vol = context.object
        if len(vol.voxlight.clip_planes) >= cutaway_props.MAX_CLIP_PLANES:
            self.report({"ERROR"}, "A volume has at most %d clip planes" % cutaway_props.MAX_CLIP_PLANES)
            return {"CANCELLED"}
        centre, axes = _volume_frame(vol)
        size = float(max(np.linalg.norm(a) for a in axes))
        e = _new_empty(context, "%s Clip Plane" % vol.name, "SINGLE_ARROW", size,
                       _matrix(centre, _basis(axes), (1, 1, 1)))
        vol.voxlight.clip_planes.add().object = e
        return {"FINISHED"}


class VOXLIGHT_OT_add_crop_box(OnActiveVolume, bpy.types.Operator):
    """Add a crop box: a cube Empty around the volume; only what is inside it is kept.
    Scale and move it to crop"""
    bl_idname = "voxlight.add_crop_box"
    bl_label = "Add Crop Box"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        vol = context.object
        centre, axes = _volume_frame(vol)
        vol.voxlight.crop_box = _new_empty(context, "%s Crop Box" % vol.name, "CUBE", 1.0,
                                           _matrix(centre, _basis(axes),
                                                   [np.linalg.norm(a) for a in axes]))
        return {"FINISHED"}


class VOXLIGHT_OT_add_cutter(OnActiveVolume, bpy.types.Operator):
    """Add a cutter slot: pick a closed mesh in it; it removes its inside (or keeps only it)"""
    bl_idname = "voxlight.add_cutter"
    bl_label = "Add Cutter"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        p = context.object.voxlight
        if len(p.cutters) >= cutaway_props.MAX_CUTTERS:
            self.report({"ERROR"}, "A volume has at most %d cutters" % cutaway_props.MAX_CUTTERS)
            return {"CANCELLED"}
        slot = p.cutters.add()
        sel = [o for o in context.selected_objects if o.type == "MESH" and o != context.object]
        if sel:
            slot.object = sel[0]
        tag_redraw()
        return {"FINISHED"}


class VOXLIGHT_OT_remove_cut(OnActiveVolume, bpy.types.Operator):
    """Stop cutting with this clip plane or mesh (the object itself stays)"""
    bl_idname = "voxlight.remove_cut"
    bl_label = "Remove Cut"
    bl_options = {"REGISTER", "UNDO"}
    collection: EnumProperty(items=[("clip_planes", "Clip Plane", ""), ("cutters", "Cutter", "")])
    index: IntProperty(default=0)

    def execute(self, context):
        slots = getattr(context.object.voxlight, self.collection)
        if 0 <= self.index < len(slots):
            slots.remove(self.index)
        tag_redraw()
        return {"FINISHED"}


class VOXLIGHT_OT_add_slice_plane(OnActiveVolume, bpy.types.Operator):
    """Add a slice plane: a mesh plane through the volume's centre that shows the volume
    resampled on it (window and colour map). Move and turn it for oblique slices"""
    bl_idname = "voxlight.add_slice_plane"
    bl_label = "Add Slice Plane"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        vol = context.object
        centre, axes = _volume_frame(vol)
        mesh = bpy.data.meshes.new("%s Slice" % vol.name)
        mesh.from_pydata([(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)], [], [(0, 1, 2, 3)])
        mesh.update()
        ob = bpy.data.objects.new("%s Slice" % vol.name, mesh)
        # An axial slice: the plane spans the volume's first two axes.
        size = (np.linalg.norm(axes[0]), np.linalg.norm(axes[1]), 1.0)
        _set_matrix(ob, _matrix(centre, _basis(axes), size))
        _link(context, ob)
        ob.voxlight_slice.volume = vol
        slice_planes.update(ob, context.scene, None)
        return {"FINISHED"}


class VOXLIGHT_OT_update_slice(bpy.types.Operator):
    """Resample the volume on this slice plane now"""
    bl_idname = "voxlight.update_slice"
    bl_label = "Update Slice"

    @classmethod
    def poll(cls, context):
        return slice_planes.is_slice(context.object)

    def execute(self, context):
        slice_planes._keys.pop(context.object.name, None)
        slice_planes.update(context.object, context.scene, None)
        msg = slice_planes.error(context.object)
        if msg:
            self.report({"ERROR"}, "Voxlight: %s" % msg)
            return {"CANCELLED"}
        return {"FINISHED"}


# ------------------------------------------------------------- panels

class _VolumeChild(_VolumePanel):
    bl_parent_id = "VOXLIGHT_PT_volume"


class VOXLIGHT_PT_volume_mode(_VolumeChild, bpy.types.Panel):
    bl_label = "Render Mode"
    bl_idname = "VOXLIGHT_PT_volume_mode"

    def draw(self, context):
        layout = _split(self.layout)
        p = context.object.voxlight
        layout.prop(p, "render_mode")
        if p.render_mode == "iso":
            layout.prop(p, "iso_value")
        elif p.render_mode == "minip":
            row = layout.row(heading="Floor")
            row.prop(p, "use_minip_floor", text="")
            sub = row.row()
            sub.active = p.use_minip_floor
            sub.prop(p, "minip_floor", text="")
        sub = layout.column()
        sub.active = p.render_mode in ("dvr", "iso")  # the projections are not shaded
        sub.prop(p, "matcap")


class VOXLIGHT_PT_volume_cutaway(_VolumeChild, bpy.types.Panel):
    bl_label = "Cutaway"
    bl_idname = "VOXLIGHT_PT_volume_cutaway"
    bl_options = {"DEFAULT_CLOSED"}

    def draw(self, context):
        layout = self.layout
        obj = context.object
        p = obj.voxlight
        col = layout.column(align=True)
        col.label(text="Clip Planes")
        for i, cp in enumerate(p.clip_planes):
            row = col.row(align=True)
            row.prop(cp, "enabled", text="")
            row.prop(cp, "object", text="")
            row.prop(cp, "thickness", text="Slab")
            op = row.operator("voxlight.remove_cut", text="", icon="X")
            op.collection, op.index = "clip_planes", i
        col.operator("voxlight.add_clip_plane", icon="ADD")
        layout.separator()
        col = _split(layout.column(align=True))
        col.prop(p, "crop_box")
        col.operator("voxlight.add_crop_box", icon="ADD")
        layout.separator()
        col = layout.column(align=True)
        col.label(text="Cutter Meshes")
        for i, c in enumerate(p.cutters):
            row = col.row(align=True)
            row.prop(c, "enabled", text="")
            row.prop(c, "object", text="")
            row.prop(c, "remove_outside", text="Keep Inside", toggle=True)
            op = row.operator("voxlight.remove_cut", text="", icon="X")
            op.collection, op.index = "cutters", i
        col.operator("voxlight.add_cutter", icon="ADD")
        _split(layout).prop(p, "caps")
        layout.operator("voxlight.add_slice_plane", icon="MESH_PLANE")
        msgs = cutaway.problems(obj)
        if msgs:
            box = layout.box()
            box.alert = True
            for m in msgs:
                box.label(text=m, icon="ERROR")


class VOXLIGHT_PT_slice_plane(bpy.types.Panel):
    bl_label = "Voxlight Slice"
    bl_idname = "VOXLIGHT_PT_slice_plane"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "object"
    bl_order = -1  # on top of Object properties, like the volume's panel

    @classmethod
    def poll(cls, context):
        """A slice plane, or a flat mesh (a plane: the slice is its
        bounding rectangle) while the file has a Voxlight volume to slice;
        never the default Cube or other solid meshes."""
        ob = context.object
        if slice_planes.is_slice(ob):
            return True
        if ob is None or ob.type != "MESH" or min(ob.dimensions) > 1e-6:
            return False
        return any(o.voxlight.is_volume for o in bpy.data.objects)

    def draw(self, context):
        layout = _split(self.layout)
        ob = context.object
        s = ob.voxlight_slice
        layout.prop(s, "volume")
        col = layout.column()
        col.active = s.volume is not None
        col.prop(s, "interpolation")
        col.prop(s, "resolution")
        col.operator("voxlight.update_slice", icon="FILE_REFRESH")
        msg = slice_planes.error(ob)
        if msg:
            box = layout.box()
            box.alert = True
            box.label(text=msg, icon="ERROR")


_classes = (VOXLIGHT_OT_add_clip_plane, VOXLIGHT_OT_add_crop_box, VOXLIGHT_OT_add_cutter,
            VOXLIGHT_OT_remove_cut, VOXLIGHT_OT_add_slice_plane,
            VOXLIGHT_OT_update_slice, VOXLIGHT_PT_volume_mode, VOXLIGHT_PT_volume_cutaway,
            VOXLIGHT_PT_slice_plane)

register, unregister = bpy.utils.register_classes_factory(_classes)
