"""The volumes' box outlines, made whole again over the composited volume.

Blender draws a volume's outline (an Empty's wire cube, a Volume object's
bounds) before the add-on composites the volume, which then covered the
lines in front of it unevenly: broken or dashed edges wherever tissue lay
behind them. After the volumes are composited, the edges that nothing in
the box can cover (plugin/core/box_edges.py) are drawn again in the
outline's own theme colour, depth-tested against the scene so a mesh in
front still hides them. Only when Blender draws the outline itself:
overlays on, and for an Empty, extras shown.
"""

import bpy
import gpu
import numpy as np
from gpu_extras.batch import batch_for_shader

from .core import box_edges

# Blender 3.4 still accepts the prefixed name; 4.0 removed it.
_SHADER_NAMES = ("POLYLINE_UNIFORM_COLOR", "3D_POLYLINE_UNIFORM_COLOR")
_shader = None


def _get_shader():
    global _shader
    if _shader is None:
        for name in _SHADER_NAMES:
            try:
                _shader = gpu.shader.from_builtin(name)
                break
            except ValueError:
                continue
    return _shader


def corners(ob):
    """The outline's 8 corners in world space as Blender draws them, or None
    when the object draws no box."""
    if ob.type == "EMPTY":
        if ob.empty_display_type != "CUBE":
            return None
        s = float(ob.empty_display_size)
        return box_edges.cube_corners(np.array(ob.matrix_world, np.float64) @ np.diag((s, s, s, 1.0)))
    if ob.display_type != "BOUNDS" and not ob.show_bounds:
        return None
    bb = np.array([tuple(c) for c in ob.bound_box], np.float64)
    return box_edges.box_corners(np.array(ob.matrix_world, np.float64), bb.min(axis=0), bb.max(axis=0))


def colour(ob, context):
    """The theme colour Blender draws this object's wire in."""
    theme = context.preferences.themes[0].view_3d
    if ob.select_get():
        c = theme.object_active if context.view_layer.objects.active == ob else theme.object_selected
    else:
        c = theme.empty if ob.type == "EMPTY" else theme.wire
    return (c[0], c[1], c[2], 1.0)


def draw(objs, view, perspective, space, viewport_size):
    """Draws the front edges of each object's outline (objs: the volume
    objects drawn in this view; view: world -> view 4x4)."""
    overlay = space.overlay
    if not overlay.show_overlays:
        return
    shader = _get_shader()
    if shader is None:
        return
    context = bpy.context
    gpu.state.depth_test_set("LESS_EQUAL")
    gpu.state.depth_mask_set(False)
    gpu.state.blend_set("ALPHA")
    shader.bind()
    shader.uniform_float("viewportSize", viewport_size)
    shader.uniform_float("lineWidth", float(context.preferences.system.pixel_size))
    for ob in objs:
        if ob.type == "EMPTY" and not overlay.show_extras:
            continue
        c = corners(ob)
        if c is None:
            continue
        edges = box_edges.front_edges(c, view, perspective)
        if not edges:
            continue
        shader.uniform_float("color", colour(ob, context))
        batch_for_shader(shader, "LINES", {"pos": box_edges.segments(c, edges)}).draw(shader)
    gpu.state.blend_set("NONE")
    gpu.state.depth_test_set("NONE")
