"""Add-on preferences: where the user sees whether the library loaded."""

import bpy

from .core import native


class VoxlightPreferences(bpy.types.AddonPreferences):
    # The module name differs between a legacy add-on ("voxlight") and a
    # 4.2+ extension ("bl_ext.<repo>.voxlight"); __package__ is right in both.
    bl_idname = __package__

    def draw(self, context):
        ok, msg = native.library_status()
        col = self.layout.column()
        if ok:
            col.label(text=msg, icon="CHECKMARK")
        else:
            col.alert = True
            col.label(text="Voxlight library unavailable:", icon="ERROR")
            for i in range(0, len(msg), 90):
                col.label(text=msg[i:i + 90])


def register():
    bpy.utils.register_class(VoxlightPreferences)


def unregister():
    bpy.utils.unregister_class(VoxlightPreferences)
