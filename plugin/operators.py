"""Operators on Voxlight volumes (the importer is in importer.py)."""

import bpy

from .core import native, runtime


class OnActiveVolume:
    """Mixin of the operators and panels that act on the active object when
    it is a Voxlight volume (put it before bpy.types.Operator/Panel)."""

    @classmethod
    def poll(cls, context):
        obj = context.object
        return obj is not None and obj.voxlight.is_volume


class VOXLIGHT_OT_reload_volume(OnActiveVolume, bpy.types.Operator):
    """Reload the active volume's file (after it changed on disk or failed)"""
    bl_idname = "voxlight.reload_volume"
    bl_label = "Reload Volume"

    def execute(self, context):
        p = context.object.voxlight
        try:
            runtime.load_volume(bpy.path.abspath(p.filepath), series=p.series,
                                **runtime.options_of(context.scene.voxlight))
        except native.VoxlightError as e:
            self.report({"ERROR"}, "Voxlight: %s" % e)
            return {"CANCELLED"}
        from .properties import tag_redraw
        tag_redraw()
        return {"FINISHED"}


_classes = (VOXLIGHT_OT_reload_volume,)


def register():
    for c in _classes:
        bpy.utils.register_class(c)


def unregister():
    for c in reversed(_classes):
        bpy.utils.unregister_class(c)
