"""Add-on preferences: where the user sees whether the library loaded, and
how files larger than memory are opened: the streaming mode and
the folder for bricked caches. These two are per user, not per .blend, so
they live here; runtime.stream_settings carries them to the loads (which run
on worker threads, without bpy)."""

import bpy
from bpy.props import EnumProperty, StringProperty

from .core import native, runtime
from .properties import _items, _library_names

_STREAMING_UI = {
    "auto": ("Auto", "Read bricks on demand when the volume is larger than half of its share of "
                     "the memory budget, else read it whole"),
    "off": ("Off", "Always read the whole volume (larger than the budget: an error)"),
    "on": ("On", "Always read bricks on demand, whatever the size"),
}


def _sync(prefs, _context=None):
    """The preferences into runtime.stream_settings (read by every load)."""
    runtime.stream_settings["streaming"] = prefs.streaming
    runtime.stream_settings["cache_dir"] = bpy.path.abspath(prefs.cache_dir) if prefs.cache_dir else ""


class VoxlightPreferences(bpy.types.AddonPreferences):
    # The module name differs between a legacy add-on ("voxlight") and a
    # 4.2+ extension ("bl_ext.<repo>.voxlight"); __package__ is right in both.
    bl_idname = __package__

    streaming: EnumProperty(name="Streaming", default="auto", update=_sync,
                            items=_items(_library_names("streaming"), _STREAMING_UI, "Streaming mode"),
                            description="Whether volumes are read whole or brick by brick from disk "
                                        "as the view needs them (volumes opened later)")
    cache_dir: StringProperty(name="Cache Folder", subtype="DIR_PATH", default="", update=_sync,
                              description="Where the bricked caches of compressed files (.nii.gz) go; "
                                          "empty: beside the file (or the user cache folder when "
                                          "that is read-only)")

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
        col = self.layout.column()
        col.label(text="Data larger than memory:")
        col.prop(self, "streaming")
        col.prop(self, "cache_dir")


def sync(context=None):
    """Reads the preferences into runtime.stream_settings; the importer calls
    it too, since Blender may register the add-on before its preferences
    exist."""
    addon = (context or bpy.context).preferences.addons.get(__package__)
    if addon is not None and addon.preferences is not None:
        _sync(addon.preferences)


def register():
    bpy.utils.register_class(VoxlightPreferences)
    sync()


def unregister():
    bpy.utils.unregister_class(VoxlightPreferences)
