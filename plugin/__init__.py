"""Voxlight for Blender: GPU ray casting of medical and scientific volumes with
selectable gradient filters, composited into the viewport and into F12 /
background renders. The ray caster is libvoxlight.so, shipped beside this
file and bound with ctypes (native.py).

Scripting:  voxlight.render_volume(obj, camera=None, resolution=(w, h),
            filepath=None) -> numpy RGBA (premultiplied, row 0 = bottom)
Import:     bpy.ops.voxlight.import_volume(filepath="brain.nii.gz")
"""

bl_info = {
    "name": "Voxlight",
    "author": "Voxlight developers",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "File > Import > Medical/Scientific Volume; Properties > Object > Voxlight",
    "description": "Ray cast medical volumes with selectable gradient filters",
    "category": "Import-Export",
}

if "bpy" in locals():
    # Executed again (a script reload, or an update installed over the
    # legacy add-on): forget every submodule, so the imports below load the
    # new code of all of them, in dependency order.
    import sys
    for _name in [n for n in sys.modules if n.startswith(__name__ + ".")]:
        del sys.modules[_name]
        globals().pop(_name.rsplit(".", 1)[1], None)

import bpy  # noqa: E402

from . import compat  # noqa: E402

# On a Blender older than the add-on supports, nothing else is imported (the
# other modules may use API that does not exist there): register() then only
# shows why, in the preferences and on the console.
UNSUPPORTED = compat.unsupported_message(bpy.app.version)

if UNSUPPORTED is None:
    from .core import native  # noqa: E402
    # The library's private copies (native.private_copy) go to the
    # extension's own folder where Blender gives one; set before any module
    # loads the library.
    native.CACHE_DIR = compat.private_data_dir(__package__)
    from . import (api, blender_volume, compositor, importer, offline, operators, panels, params,  # noqa: E402
                   preferences, properties, render_hooks, render_setup, scene_shadows, tf,
                   viewport, volume_object, world_light)
    from . import cutaway_ui, slice_planes  # noqa: E402
    from . import label_props, label_ui  # noqa: E402
    from . import overlay_props, overlay_ui  # noqa: E402  (overlays)
    from . import channel_ops, channel_props, channel_ui  # noqa: E402,F401  (channels; panels.py registers the UI)
    from .core import (depth, import_job, lights, native, runtime, scene_geometry,  # noqa: E402,F401
                       volume_space, zbuffer)
    from .api import render_volume  # noqa: E402,F401

    # Registration order: properties before the UI that shows them; handlers last.
    _modules = (preferences, properties, label_props, overlay_props, tf, operators, blender_volume, importer,
                volume_object,
                channel_ops, panels, slice_planes, cutaway_ui, label_ui, overlay_ui, render_setup, render_hooks, scene_shadows,
                world_light, viewport)
else:
    _modules = ()


class _UnsupportedPreferences(bpy.types.AddonPreferences):
    """Shown instead of the real preferences on an unsupported Blender."""
    bl_idname = __package__

    def draw(self, context):
        col = self.layout.column()
        col.alert = True
        for i, line in enumerate(compat.wrap(UNSUPPORTED, 90)):
            col.label(text=line, icon="ERROR" if i == 0 else "NONE")


def library_status():
    """(ok, message): whether libvoxlight loaded, and why not."""
    if UNSUPPORTED:
        return False, UNSUPPORTED
    return native.library_status()


def register():
    if UNSUPPORTED:
        print("Voxlight: %s" % UNSUPPORTED)
        bpy.utils.register_class(_UnsupportedPreferences)
        return
    for m in _modules:
        m.register()
    ok, msg = native.library_status()
    if not ok:
        # Registering anyway keeps the UI up to show the problem.
        print("Voxlight: %s" % msg)


def unregister():
    if UNSUPPORTED:
        bpy.utils.unregister_class(_UnsupportedPreferences)
        return
    for m in reversed(_modules):
        m.unregister()
    for msg in runtime.release_all():
        print("Voxlight: %s" % msg)
