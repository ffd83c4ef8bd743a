"""Blender Volume objects (OpenVDB, e.g. baked smoke/fluid) rendered by
Voxlight: a "Render with Voxlight" toggle in Properties › Object.

On: the Volume's .vdb file (the current frame's file for sequences, read
once when switched on or reloaded) is loaded by libvoxlight ("density",
else the first float grid), and the object becomes a Voxlight volume like
an imported one: voxel_to_local is the grid's own index-to-object transform
(OpenVDB files are in scene units), so the render follows matrix_world x
grid transform, in the viewport and in F12. Blender's own viewport drawing
of the volume is switched to its bounding box (the previous display type is
restored when switched off); the Volume's material, if any, still renders in
F12 under Voxlight's layer.
Off: the object is an ordinary Volume again; its Voxlight settings (transfer
function, window...) are kept for the next time.
"""

import os

import bpy
from bpy.props import BoolProperty, PointerProperty, StringProperty

from . import tf
from .core import native, runtime
from .importer import fill_volume_properties


def vdb_file(ob):
    """Absolute path of the .vdb that Blender shows for this Volume now."""
    vol = ob.data
    path = ""
    try:
        if vol.is_sequence and vol.grids.load():  # cheap: Blender has the frame's file at hand
            path = vol.grids.frame_filepath
    except (AttributeError, RuntimeError):
        path = ""
    return bpy.path.abspath(path or vol.filepath, library=vol.library)


def _switch_on(ob, backend):
    path = vdb_file(ob)
    entry = runtime.load_volume(path, backend=backend)  # raises native.VoxlightError
    s = ob.voxlight_vdb
    if not s.saved_display:
        s.saved_display = ob.display_type
        s.saved_in_front = ob.show_in_front
    # The grid transform is already in object space (scene units).
    fill_volume_properties(ob, path, entry.info, entry.info["affine"], 1.0)
    tf.ensure_texture(ob)
    ob.display_type = "BOUNDS"
    # As for imported volumes: not "in front", so meshes in front of the box
    # hide it (importer.py says why rays stopping at its lines is right).
    ob.show_in_front = False


def _switch_off(ob):
    s = ob.voxlight_vdb
    ob.voxlight.is_volume = False
    if s.saved_display:
        ob.display_type = s.saved_display
        ob.show_in_front = s.saved_in_front
        s.saved_display = ""


def _load_into(ob, backend):
    """Switches ob on; returns "" or the library's message, which the panel
    shows (an update callback cannot report). On failure the object stays
    an ordinary Volume."""
    try:
        _switch_on(ob, backend)
        err = ""
    except (native.VoxlightError, OSError) as e:
        err = str(e)
        ob.voxlight.is_volume = False
    ob.voxlight_vdb.error = err
    from .properties import tag_redraw
    tag_redraw()
    return err


def _on_toggle(self, context):
    ob = self.id_data
    if not self.enabled:
        self.error = ""
        _switch_off(ob)
        return
    scene = context.scene if context and context.scene else bpy.context.scene
    _load_into(ob, scene.voxlight.backend)


class VoxlightVolumeObjectSettings(bpy.types.PropertyGroup):
    enabled: BoolProperty(name="Render with Voxlight", default=False, update=_on_toggle,
                          options=set(),
                          description="Ray cast this Volume's OpenVDB grid with Voxlight in the "
                                      "viewport and in renders")
    error: StringProperty(name="Error", options={"SKIP_SAVE"})
    saved_display: StringProperty(options={"HIDDEN"})
    saved_in_front: BoolProperty(options={"HIDDEN"})


class VOXLIGHT_OT_volume_object_reload(bpy.types.Operator):
    """Load the Volume's file again (current frame's file for sequences)"""
    bl_idname = "voxlight.volume_object_reload"
    bl_label = "Reload VDB"

    @classmethod
    def poll(cls, context):
        ob = context.object
        return ob is not None and ob.type == "VOLUME" and ob.voxlight_vdb.enabled

    def execute(self, context):
        err = _load_into(context.object, context.scene.voxlight.backend)
        if err:
            self.report({"ERROR"}, "Voxlight: %s" % err)
            return {"CANCELLED"}
        return {"FINISHED"}


class VOXLIGHT_PT_volume_object(bpy.types.Panel):
    bl_label = "Voxlight"
    bl_idname = "VOXLIGHT_PT_volume_object"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "data"  # the Volume's own settings' tab, where the Voxlight panels appear when on
    bl_order = -2  # above the Voxlight settings panel (order -1) that appears when on

    @classmethod
    def poll(cls, context):
        ob = context.object
        return ob is not None and ob.type == "VOLUME"

    def draw(self, context):
        ob = context.object
        s = ob.voxlight_vdb
        layout = self.layout
        row = layout.row()
        row.prop(s, "enabled")
        row.operator(VOXLIGHT_OT_volume_object_reload.bl_idname, text="", icon="FILE_REFRESH")
        if s.error:
            box = layout.box()
            box.alert = True
            for i in range(0, len(s.error), 70):
                box.label(text=s.error[i:i + 70], icon="ERROR" if i == 0 else "NONE")
        elif s.enabled:
            layout.label(text=os.path.basename(ob.voxlight.filepath), icon="FILE_VOLUME")


_classes = (VoxlightVolumeObjectSettings, VOXLIGHT_OT_volume_object_reload, VOXLIGHT_PT_volume_object)


def register():
    for c in _classes:
        bpy.utils.register_class(c)
    bpy.types.Object.voxlight_vdb = PointerProperty(type=VoxlightVolumeObjectSettings)


def unregister():
    del bpy.types.Object.voxlight_vdb
    for c in reversed(_classes):
        bpy.utils.unregister_class(c)
