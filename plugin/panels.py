"""Properties editor UI: Object tab "Voxlight" (only for Voxlight volumes)
and Render tab "Voxlight" (scene-wide settings). Library problems are shown
here rather than failing at add-on import."""

import bpy

from . import native, runtime, tf
from .properties import FIXED_TAP_FILTERS


def _draw_library_status(layout):
    ok, msg = native.library_status()
    if not ok:
        box = layout.box()
        box.alert = True
        box.label(text="Voxlight library unavailable", icon="ERROR")
        for i in range(0, len(msg), 70):
            box.label(text=msg[i:i + 70])
    return ok


class VOXLIGHT_PT_volume(bpy.types.Panel):
    bl_label = "Voxlight"
    bl_idname = "VOXLIGHT_PT_volume"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "object"

    @classmethod
    def poll(cls, context):
        obj = context.object
        return obj is not None and obj.voxlight.is_volume

    def draw(self, context):
        layout = self.layout
        p = context.object.voxlight
        layout.use_property_split = True
        layout.use_property_decorate = True  # keyframe dots: everything is animatable
        if _draw_library_status(layout):
            err = runtime.last_failure(bpy.path.abspath(p.filepath), p.series)
            if err:
                box = layout.box()
                box.alert = True
                box.label(text=err, icon="ERROR")
                box.operator("voxlight.reload_volume", icon="FILE_REFRESH")
        layout.prop(p, "filepath")
        col = layout.column(align=True)
        col.label(text="%d x %d x %d voxels, data range %.4g .. %.4g"
                  % (*p.dims, p.data_min, p.data_max))
        if p.series:
            col.label(text="DICOM series %s" % p.series)
        if p.frame_count > 1:  # 4D: which volume frame the scene frame shows
            col = layout.column(align=True)
            col.label(text="%d volume frames" % p.frame_count)
            col.prop(p, "frame_mode")
            col.prop(p, "frame_offset" if p.frame_mode == "TIMELINE" else "fixed_frame")

        layout.separator()
        col = layout.column()
        col.prop(p, "filter")
        sub = col.column()
        sub.active = p.filter not in FIXED_TAP_FILTERS
        sub.prop(p, "sample_distance", slider=True)
        col.prop(p, "reuse_gradients")
        if p.filter == "precomputed":
            col.prop(p, "gradient_16f")
        col.prop(p, "step")
        col.prop(p, "jitter")

        layout.separator()
        col = layout.column()
        col.prop(p, "use_color_ramp")
        if p.use_color_ramp:
            col.operator_menu_enum("voxlight.tf_preset", "preset", text="Load Preset",
                                   icon="PRESET")
            if p.tf_texture is not None and p.tf_texture.use_color_ramp:
                box = layout.box()
                box.template_color_ramp(p.tf_texture, "color_ramp", expand=True)
                box.label(text="Stop alpha = opacity per voxel")
            else:
                col.operator("voxlight.tf_ramp", icon="ADD")
        else:
            col.prop(p, "preset")
        col = layout.column()
        col.prop(p, "use_window")
        sub = col.column(align=True)
        sub.active = p.use_window
        sub.prop(p, "window_low")
        sub.prop(p, "window_high")
        col.label(text="Data range: %.4g .. %.4g" % (p.data_min, p.data_max))
        if any(p.histogram):
            hist = tf.histogram_text(p.histogram)
            col.label(text="Histogram (log): " + hist)
            if p.data_max > p.data_min:
                a = (min(p.window_low, p.window_high) - p.data_min) / (p.data_max - p.data_min)
                b = (max(p.window_low, p.window_high) - p.data_min) / (p.data_max - p.data_min)
                i0, i1 = (int(round(min(max(v, 0.0), 1.0) * len(hist))) for v in (a, b))
                col.label(text="Window:          " + " " * i0 + "▔" * max(i1 - i0, 1))
        col.prop(p, "opacity_scale")
        col.prop(p, "classify")
        col.prop(p, "gradient_opacity")
        if p.gradient_opacity != "off":
            sub = col.column(align=True)
            sub.prop(p, "gradient_ref")
            sub.prop(p, "gradient_exp")
            if p.gradient_opacity == "iso":
                sub.prop(p, "iso_value")
                sub.prop(p, "iso_thickness")

        layout.separator()
        col = layout.column()
        col.prop(p, "shading")
        sub = col.column(align=True)
        sub.active = p.shading
        sub.prop(p, "ambient", slider=True)
        sub.prop(p, "diffuse", slider=True)
        sub.prop(p, "specular", slider=True)
        sub.prop(p, "shininess")

        entry = runtime.find_entry(bpy.path.abspath(p.filepath), p.series)
        frame = entry.last_frame if entry is not None else None
        if frame:
            layout.separator()
            col = layout.column(align=True)
            col.label(text="Last frame (%s): %d x %d, %.0f ms, %d call%s"
                      % (frame["kind"], frame["width"], frame["height"],
                         frame["seconds"] * 1000.0, frame["calls"],
                         "" if frame["calls"] == 1 else "s"), icon="INFO")
            col.label(text="%.2f M samples on %d rays, step %.3g voxels"
                      % (frame["samples"] / 1e6, frame["rays"], frame["effective_step"]))
            if frame["bricks_total"]:
                col.label(text="Occupied bricks: %d of %d (%d³ voxels)"
                          % (frame["bricks_occupied"], frame["bricks_total"],
                             frame["brick_size"]))
            else:
                col.label(text="Empty-space skipping off")
            col.label(text=storage_text(frame))
            if frame.get("lod_level"):
                col.label(text=lod_text(frame), icon="ERROR")


def storage_text(frame):
    """How the volume is held on the GL side, from the last frame's stats."""
    mib = frame.get("resident_bytes", 0) / 1048576.0
    if not frame.get("pages_total"):
        return "Storage: %s, %.1f MiB" % (frame.get("storage_name", "dense"), mib)
    return "Storage: %s, %.1f MiB (%d of %d bricks resident, %d constant)" % (
        frame["storage_name"], mib, frame["pages_resident"], frame["pages_total"],
        frame["pages_constant"])


def lod_text(frame):
    """The level-of-detail fallback, said out loud (empty at full resolution)."""
    k = frame.get("lod_level", 0)
    if not k:
        return ""
    return "LOD fallback: %dx coarser, full resolution needs %.1f MiB (over budget)" % (
        1 << k, frame["lod_wanted_bytes"] / 1048576.0)


class VOXLIGHT_PT_scene(bpy.types.Panel):
    bl_label = "Voxlight"
    bl_idname = "VOXLIGHT_PT_scene"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "render"

    def draw(self, context):
        layout = self.layout
        s = context.scene.voxlight
        layout.use_property_split = True
        _draw_library_status(layout)
        col = layout.column(heading="Viewport")
        col.prop(s, "viewport_enabled")
        col.prop(s, "viewport_resolution", slider=True)
        col.prop(s, "interactive_resolution", slider=True)
        col.prop(s, "settle_time")
        col.label(text="Frames rendered: %d (%d library calls, %d stale frames dropped)"
                  % (runtime.render_count, runtime.call_count, runtime.cancelled_count))
        col = layout.column(heading="Render")
        col.prop(s, "render_enabled")
        col.prop(s, "render_occlusion")
        layout.prop(s, "use_scene_lights")
        layout.prop(s, "backend")
        layout.prop(s, "storage")
        layout.prop(s, "memory_budget_mib")


_classes = (VOXLIGHT_PT_volume, VOXLIGHT_PT_scene)


def register():
    for c in _classes:
        bpy.utils.register_class(c)


def unregister():
    for c in reversed(_classes):
        bpy.utils.unregister_class(c)
