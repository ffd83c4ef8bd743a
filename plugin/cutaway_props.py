"""The properties on a volume (Object.voxlight): the render mode, the
MatCap, clip planes, the crop box, cutter meshes and caps. The property
groups of one clip plane and one cutter live here; properties.py puts them
(and the fields below) on VoxlightVolumeProperties. Every number is
animatable (Blender's default); the objects are picked in the panel, and
their own transforms animate the cut."""

import zlib

import bpy
from bpy.props import BoolProperty, FloatProperty, PointerProperty

from .core import native


def tag_redraw(self=None, context=None):
    from .properties import tag_redraw as redraw
    redraw(self, context)


class VoxlightClipPlane(bpy.types.PropertyGroup):
    """One clip plane: an object's local XY plane, keeping its +Z side."""
    object: PointerProperty(type=bpy.types.Object, name="Plane", update=tag_redraw,
                            description="The object (an Empty of type Plain Axes, Single Arrow or "
                                        "Plane) whose local XY plane cuts the volume; its +Z "
                                        "(arrow) side is kept")
    thickness: FloatProperty(name="Thickness", default=0.0, min=0.0, soft_max=10.0,
                             subtype="DISTANCE", update=tag_redraw,
                             description="0 keeps the whole +Z side; above 0 only a slab this "
                                         "thick on that side (scene units)")
    enabled: BoolProperty(name="Enabled", default=True, update=tag_redraw,
                          description="Cut with this plane")


class VoxlightCutter(bpy.types.PropertyGroup):
    """One cutter: a closed mesh that removes its inside or its outside."""
    object: PointerProperty(type=bpy.types.Object, name="Mesh", update=tag_redraw,
                            description="A closed mesh object; its evaluated shape (modifiers "
                                        "applied) cuts the volume")
    remove_outside: BoolProperty(name="Keep Inside", default=False, update=tag_redraw,
                                 description="Off: the mesh removes what is inside it. On: "
                                             "only what is inside it is kept")
    enabled: BoolProperty(name="Enabled", default=True, update=tag_redraw,
                          description="Cut with this mesh")


CLASSES = (VoxlightClipPlane, VoxlightCutter)

# The render modes' UI names; the list and numbers are the library's
# (vxl_mode_name), so a mode added there appears without editing this.
MODE_UI = {
    "dvr": ("Volume", "Direct volume rendering: light absorbed and emitted along each ray"),
    "mip": ("Maximum", "Maximum intensity projection: the brightest value along each ray "
                       "(vessels in angiography)"),
    "minip": ("Minimum", "Minimum intensity projection: the darkest value along each ray "
                         "(airways)"),
    "average": ("Average", "The mean value along each ray: an X-ray look"),
    "iso": ("Iso-surface", "A solid surface where the data first crosses the Iso Value, lit "
                           "like a mesh"),
}


INTERPOLATION_UI = {
    "nearest": ("Nearest", "Each pixel shows the nearest voxel: blocky, the exact values"),
    "linear": ("Linear", "Trilinear blend of the 8 nearest voxels"),
    "cubic": ("Cubic", "Cubic B-spline through every voxel: smooth, sharper than linear"),
}


# MatCaps: Blender's own (Preferences > Lights > MatCaps). Each item's
# number is a hash of its name, so keyframes and saved files keep naming the
# same picture when MatCaps are added or removed.
MATCAP_NONE = "NONE"
_matcap_items_cache = []  # Blender needs the item strings to outlive the callback


def matcap_number(name):
    return zlib.crc32(name.encode()) & 0x7FFFFFFF or 1


def matcap_items(self, context):
    items = [(MATCAP_NONE, "None", "The material and the lights shade the volume", "NONE", 0)]
    try:
        lights = bpy.context.preferences.studio_lights
    except AttributeError:
        lights = ()
    for sl in sorted((s for s in lights if s.type == "MATCAP"), key=lambda s: s.name):
        label = sl.name.rsplit(".", 1)[0].replace("_", " ").title()
        items.append((sl.name, label, "Shade with Blender's MatCap %s (as Solid mode's)" % sl.name,
                      "MATSPHERE", matcap_number(sl.name)))
    _matcap_items_cache[:] = items
    return _matcap_items_cache


def studio_matcap_path(name):
    """The file of Blender's MatCap `name`, or None."""
    for sl in bpy.context.preferences.studio_lights:
        if sl.type == "MATCAP" and sl.name == name:
            return sl.path
    return None


MAX_CLIP_PLANES = native.MAX_CLIP_PLANES
MAX_CUTTERS = native.MAX_CUTTERS
