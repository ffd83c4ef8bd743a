"""Overlays on a volume object: other volume objects drawn in the
same ray march as it (the base), each with its own placement, transfer
function, window and preset (its own Object.voxlight, as any volume object).

Object.voxlight_overlays holds both sides:
  * as a base: `links`, the volume objects linked in its panel, and
    `use_children`, whether its volume children are overlays too (up to
    MAX_OVERLAYS in all: links first, then children by name);
  * as an overlay: `fuse` (drawn inside its base, else on its own as
    before), `blend` (the library's VXL_BLEND_* names), `opacity` (times its
    own opacity scale), `shading` and `interpolation`.
Everything that changes the look is animatable and lives on the overlay
object itself, so keyframes go there. overlay_frames.py turns them into the
frame's params.overlays."""

import bpy
from bpy.props import (BoolProperty, CollectionProperty, EnumProperty, FloatProperty, IntProperty,
                       PointerProperty)

from .core import native
from .operators import OnActiveVolume

_BLEND_UI = {
    "over": ("Over", "One medium with the base: absorbs and emits (fused modalities)"),
    "add": ("Add", "A glow added to what the ray carries, absorbing nothing (PET hot spots)"),
    "max": ("Max", "Where it is more opaque than the rest of the step, its sample wins"),
}
_INTERP_UI = {
    "nearest": ("Nearest", "The nearest voxel's value (blocky)"),
    "linear": ("Linear", "Trilinear interpolation"),
    "cubic": ("Cubic", "Cubic B-spline: smoother, slower"),
}


def _items(kind, fallback, ui):
    try:
        names = native.load_library().names(kind) or fallback
    except native.LibraryUnavailable:
        names = fallback
    return [(n, *ui.get(n, (n.title(), n)), i) for i, n in enumerate(names)]


BLEND_ITEMS = _items("blend", native.BLENDS, _BLEND_UI)
INTERPOLATION_ITEMS = _items("interpolation", native.INTERPOLATIONS, _INTERP_UI)


def tag_redraw(self=None, context=None):
    from .properties import tag_redraw as redraw
    redraw(self, context)


def is_volume_object(obj):
    return obj is not None and getattr(obj, "voxlight", None) is not None and obj.voxlight.is_volume


def _poll_link(self, obj):
    return is_volume_object(obj) and obj is not self.id_data


class VoxlightOverlayLink(bpy.types.PropertyGroup):
    object: PointerProperty(type=bpy.types.Object, name="Overlay", poll=_poll_link, update=tag_redraw,
                            description="A volume object drawn in this volume's ray march")


class VoxlightOverlaySettings(bpy.types.PropertyGroup):
    # --- as a base
    links: CollectionProperty(type=VoxlightOverlayLink)
    active_index: IntProperty(name="Active Overlay", default=0)
    use_children: BoolProperty(name="Children as Overlays", default=True, update=tag_redraw,
                               description="Volume objects parented to this one are drawn in its "
                                           "ray march (fused), not on their own")
    # --- as an overlay
    fuse: BoolProperty(name="Fuse into Base", default=True, update=tag_redraw,
                       description="Drawn inside the volume it is a child of or linked to; off: "
                                   "drawn on its own")
    blend: EnumProperty(name="Blend", items=BLEND_ITEMS, update=tag_redraw,
                        description="How this overlay combines with the base at every step")
    opacity: FloatProperty(name="Opacity", default=1.0, min=0.0, soft_max=1.0, max=100.0,
                           update=tag_redraw,
                           description="Multiplies the overlay's own opacity (0 hides it)")
    shading: BoolProperty(name="Shading", default=True, update=tag_redraw,
                          description="Lit like the base; off: emission only")
    interpolation: EnumProperty(name="Interpolation", items=INTERPOLATION_ITEMS,
                                default="linear" if any(i[0] == "linear" for i in INTERPOLATION_ITEMS)
                                else INTERPOLATION_ITEMS[0][0],
                                update=tag_redraw,
                                description="How the overlay is sampled between its voxels")


def listed(obj):
    """The volume objects `obj` (original) wants as overlays, in slot order:
    its links, then its volume children by name; those whose Fuse is off are
    left out, and each appears once. Not capped: overlay_runtime.plan keeps
    MAX_OVERLAYS."""
    s = obj.voxlight_overlays
    out = [l.object for l in s.links if is_volume_object(l.object)]
    if s.use_children:
        out += sorted((c for c in obj.children if is_volume_object(c)), key=lambda c: c.name)
    seen, result = set(), []
    for o in out:
        if o is obj or o.name in seen or not o.voxlight_overlays.fuse:
            continue
        seen.add(o.name)
        result.append(o)
    return result


def bases_of(obj, scene):
    """The volume objects of `scene` that list obj as an overlay."""
    return [o for o in scene.objects if is_volume_object(o) and o is not obj and obj in listed(o)]


class VOXLIGHT_OT_add_overlay(OnActiveVolume, bpy.types.Operator):
    """Link volume objects as overlays of the active volume: the other selected volumes, or an
    empty row to pick one in"""
    bl_idname = "voxlight.add_overlay"
    bl_label = "Add Overlay"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        base = context.object
        s = base.voxlight_overlays
        have = {l.object.name for l in s.links if l.object is not None}
        picked = [o for o in context.selected_objects
                  if is_volume_object(o) and o is not base and o.name not in have]
        if len(s.links) + max(1, len(picked)) > native.MAX_OVERLAYS:
            self.report({"ERROR"}, "Voxlight: at most %d overlays per volume" % native.MAX_OVERLAYS)
            return {"CANCELLED"}
        for o in picked or [None]:
            item = s.links.add()
            item.object = o
        s.active_index = len(s.links) - 1
        tag_redraw()
        return {"FINISHED"}


class VOXLIGHT_OT_remove_overlay(OnActiveVolume, bpy.types.Operator):
    """Unlink the active overlay (the object itself stays)"""
    bl_idname = "voxlight.remove_overlay"
    bl_label = "Remove Overlay"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        return super().poll(context) and len(context.object.voxlight_overlays.links) > 0

    def execute(self, context):
        s = context.object.voxlight_overlays
        i = min(max(s.active_index, 0), len(s.links) - 1)
        s.links.remove(i)
        s.active_index = max(0, i - 1)
        tag_redraw()
        return {"FINISHED"}


_classes = (VoxlightOverlayLink, VoxlightOverlaySettings, VOXLIGHT_OT_add_overlay,
            VOXLIGHT_OT_remove_overlay)

_register_classes, _unregister_classes = bpy.utils.register_classes_factory(_classes)


def register():
    _register_classes()
    bpy.types.Object.voxlight_overlays = PointerProperty(type=VoxlightOverlaySettings)


def unregister():
    del bpy.types.Object.voxlight_overlays
    _unregister_classes()
