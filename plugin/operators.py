"""File > Import > Medical volume (.nii/.nii.gz), also callable from
scripts as bpy.ops.voxlight.import_volume(filepath=...)."""

import os

import bpy
import numpy as np
from bpy.props import BoolProperty, FloatProperty, StringProperty
from bpy_extras.io_utils import ImportHelper
from mathutils import Matrix

from . import native, runtime, tf, volume_space


def _to_matrix(a):
    return Matrix([list(map(float, row)) for row in np.asarray(a).reshape(4, 4)])


class VOXLIGHT_OT_import_volume(bpy.types.Operator, ImportHelper):
    """Import a NIfTI volume as a Voxlight volume object"""
    bl_idname = "voxlight.import_volume"
    bl_label = "Import Medical Volume"
    bl_options = {"REGISTER", "UNDO"}

    filename_ext = ".nii"
    filter_glob: StringProperty(default="*.nii;*.nii.gz;*.hdr", options={"HIDDEN"})
    # Default 0.01: 1 mm becomes 1 cm, so a 180 mm head is 1.8 units across,
    # the size of Blender's default cube. Use 0.001 for true metres.
    unit_scale: FloatProperty(name="Scene Units per mm", default=0.01, min=1e-6, max=1e3,
                              soft_min=0.0001, soft_max=1.0,
                              description="Scene units per millimetre of the scan")
    center: BoolProperty(name="Center at 3D Cursor", default=True,
                         description="Put the volume's centre at the 3D cursor instead of "
                                     "at the scanner origin")

    def execute(self, context):
        path = bpy.path.abspath(self.filepath)
        wm = context.window_manager
        wm.progress_begin(0.0, 1.0)
        try:
            wm.progress_update(0.05)
            try:
                entry = runtime.load_volume(path, progress=wm.progress_update,
                                            **runtime.options_of(context.scene.voxlight))
            except (native.VoxlightError, OSError) as e:
                # Nothing has been created yet, so a failure leaves no trace.
                self.report({"ERROR"}, "Voxlight: cannot import %s: %s"
                            % (os.path.basename(path), e))
                return {"CANCELLED"}
            obj = self._create_object(context, path, entry.info)
            wm.progress_update(1.0)
        finally:
            wm.progress_end()
        info = entry.info
        self.report({"INFO"}, "Voxlight: imported %s (%d x %d x %d, %s)"
                    % (os.path.basename(path), *info["dims"], info["dtype"]))
        return {"FINISHED"}

    def _create_object(self, context, path, info):
        dims = info["dims"]
        cursor = context.scene.cursor.location if self.center else None
        s_from_v = volume_space.scene_from_voxel(info["affine"], dims, self.unit_scale,
                                                 center_at=cursor)
        name = os.path.basename(path)
        for ext in (".gz", ".nii", ".hdr", ".img"):
            if name.lower().endswith(ext):
                name = name[: -len(ext)]
        obj = bpy.data.objects.new(name, None)
        obj.empty_display_type = "CUBE"
        obj.empty_display_size = 1.0
        # Drawn in the "in front" pass: its wire cube then stays out of the
        # depth buffer the viewport reads at POST_VIEW, so rays do not stop
        # at the volume's own outline.
        obj.show_in_front = True
        obj.matrix_world = _to_matrix(volume_space.object_matrix(s_from_v, dims))
        # Blender keeps loc/rot/scale only; whatever it could not hold (shear)
        # stays in voxel_to_local so the render remains exact.
        v2l = volume_space.voxel_to_local(s_from_v, np.array(obj.matrix_world))
        p = obj.voxlight
        p.is_volume = True
        p.filepath = path
        p.unit_scale = self.unit_scale
        p.voxel_to_local = v2l.T.ravel().tolist()
        p.dims = dims
        p.data_min = info["value_min"]
        p.data_max = info["value_max"]
        p.window_low = info["value_min"]
        p.window_high = info["value_max"]
        if "histogram" in info:
            p.histogram = [int(min(c, 2**31 - 1)) for c in info["histogram"]]
        context.collection.objects.link(obj)
        tf.ensure_texture(obj)  # grey ramp until a preset or the user edits it
        for o in context.view_layer.objects:
            o.select_set(False)
        obj.select_set(True)
        context.view_layer.objects.active = obj
        return obj


class VOXLIGHT_OT_reload_volume(bpy.types.Operator):
    """Reload the active volume's file (after it changed on disk or failed)"""
    bl_idname = "voxlight.reload_volume"
    bl_label = "Reload Volume"

    @classmethod
    def poll(cls, context):
        obj = context.object
        return obj is not None and obj.voxlight.is_volume

    def execute(self, context):
        p = context.object.voxlight
        try:
            runtime.load_volume(bpy.path.abspath(p.filepath),
                                **runtime.options_of(context.scene.voxlight))
        except native.VoxlightError as e:
            self.report({"ERROR"}, "Voxlight: %s" % e)
            return {"CANCELLED"}
        from .properties import tag_redraw
        tag_redraw()
        return {"FINISHED"}


def menu_import(self, context):
    self.layout.operator(VOXLIGHT_OT_import_volume.bl_idname,
                         text="Medical volume (.nii/.nii.gz)")


_classes = (VOXLIGHT_OT_import_volume, VOXLIGHT_OT_reload_volume)


def register():
    for c in _classes:
        bpy.utils.register_class(c)
    bpy.types.TOPBAR_MT_file_import.append(menu_import)


def unregister():
    bpy.types.TOPBAR_MT_file_import.remove(menu_import)
    for c in reversed(_classes):
        bpy.utils.unregister_class(c)
