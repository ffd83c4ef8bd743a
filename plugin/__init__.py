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
    # Re-running register after a script reload: pick up edited modules.
    import importlib
    for _m in (native, depth, zbuffer, volume_space, runtime, lights, params,  # noqa: F821
               properties, operators, panels, scene_geometry, offline, compositor,  # noqa: F821
               render_hooks, viewport, api, preferences, tf, import_job, importer,  # noqa: F821
               volume_object):  # noqa: F821
        importlib.reload(_m)

import bpy  # noqa: E402

from . import (api, compositor, depth, import_job, importer, lights, native, offline,  # noqa: E402
               operators, panels, params, preferences, properties, render_hooks, runtime,
               scene_geometry, tf, viewport, volume_object, volume_space, zbuffer)
from .api import render_volume  # noqa: E402,F401

# Registration order: properties before the UI that shows them; handlers last.
_modules = (preferences, properties, tf, operators, importer, volume_object, panels, render_hooks,
            viewport)


def library_status():
    """(ok, message): whether libvoxlight loaded, and why not."""
    return native.library_status()


def register():
    for m in _modules:
        m.register()
    ok, msg = native.library_status()
    if not ok:
        # Registering anyway keeps the UI up to show the problem.
        print("Voxlight: %s" % msg)


def unregister():
    for m in reversed(_modules):
        m.unregister()
    runtime.release_all()
