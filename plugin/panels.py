"""Properties editor UI: Object tab "Voxlight" (only for Voxlight volumes)
and Render tab "Voxlight" (scene-wide settings). Library problems are shown
here rather than failing at add-on import."""

import bpy

from . import native, runtime


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
            err = runtime.last_failure(bpy.path.abspath(p.filepath))
            if err:
                box = layout.box()
                box.alert = True
                box.label(text=err, icon="ERROR")
                box.operator("voxlight.reload_volume", icon="FILE_REFRESH")
        layout.prop(p, "filepath")
        col = layout.column(align=True)
        col.label(text="%d x %d x %d voxels, data range %.4g .. %.4g"
                  % (*p.dims, p.data_min, p.data_max))

        layout.separator()
        col = layout.column()
        col.prop(p, "filter")
        sub = col.column()
        sub.active = p.filter != "precomputed"
        sub.prop(p, "sample_distance", slider=True)
        col.prop(p, "reuse_gradients")
        if p.filter == "precomputed":
            col.prop(p, "gradient_16f")
        col.prop(p, "step")
        col.prop(p, "jitter")

        layout.separator()
        col = layout.column()
        col.prop(p, "preset")
        col.prop(p, "use_window")
        sub = col.column(align=True)
        sub.active = p.use_window
        sub.prop(p, "window_low")
        sub.prop(p, "window_high")
        col.label(text="Data range: %.4g .. %.4g" % (p.data_min, p.data_max))
        col.prop(p, "opacity_scale")

        layout.separator()
        col = layout.column()
        col.prop(p, "shading")
        sub = col.column(align=True)
        sub.active = p.shading
        sub.prop(p, "ambient", slider=True)
        sub.prop(p, "diffuse", slider=True)
        sub.prop(p, "specular", slider=True)
        sub.prop(p, "shininess")


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
        col = layout.column(heading="Render")
        col.prop(s, "render_enabled")
        col.prop(s, "render_occlusion")
        layout.prop(s, "use_scene_lights")
        layout.prop(s, "backend")


_classes = (VOXLIGHT_PT_volume, VOXLIGHT_PT_scene)


def register():
    for c in _classes:
        bpy.utils.register_class(c)


def unregister():
    for c in reversed(_classes):
        bpy.utils.unregister_class(c)
