"""Properties editor UI: Object tab "Voxlight" (only for Voxlight volumes)
and Render tab "Voxlight" (scene-wide settings). Library problems are shown
here rather than failing at add-on import.

The object panel is Blender-style: the volume's file and size on top, then
sub-panels (Transfer Function, Rendering, Lighting, and Advanced and
Statistics collapsed), all with the property-split layout so labels fit at
the editor's default width."""

import os

import bpy
import numpy as np

from . import channel_props, compat, tf
from .core import histogram_image, import_job, label_import, runtime
from .operators import OnActiveVolume
from .properties import FIXED_TAP_FILTERS


def _draw_library_status(layout):
    from .core import native
    ok, msg = native.library_status()
    if not ok:
        box = layout.box()
        box.alert = True
        box.label(text="Voxlight library unavailable", icon="ERROR")
        for i in range(0, len(msg), 70):
            box.label(text=msg[i:i + 70])
    return ok


def _split(layout, decorate=True):
    """Blender's own panel layout: label column, value column and (for
    animatable properties) the keyframe dots."""
    layout.use_property_split = True
    layout.use_property_decorate = decorate
    return layout


_KIND_TEXT = {"ct": "CT (Hounsfield units)", "mr": "MR (arbitrary units)",
              "pet": "PET/NM (arbitrary units)", "other": "arbitrary units"}
# characters of a reader's note a line holds beside its icon at the
# Properties editor's default width
_NOTE_CHARS = 26


def _own_label_count(ob):
    """How many labels the volume has when it is drawn as the label map of
    its own file (a labels object), else None (an intensity volume)."""
    s = getattr(ob, "voxlight_labels", None)
    if s is None or not s.enabled or not s.filepath:
        return None
    if os.path.abspath(bpy.path.abspath(s.filepath)) != os.path.abspath(bpy.path.abspath(ob.voxlight.filepath)):
        return None
    return label_import.label_count(len(s.labels), data_max=ob.voxlight.data_max)


class _VolumePanel(OnActiveVolume):
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    # The volume is an Empty, and an object's own kind of settings live in
    # its Object Data tab, as a Light's, a Camera's or a Blender Volume's do.
    # That tab holds only Blender's small "Empty" panel besides ours, so
    # Voxlight is one click away and in view without scrolling; the Object
    # tab would put it below Transform, Relations, Collections and the rest
    # (Blender keeps the panel order stored in the startup file's screen).
    bl_context = "data"


class VOXLIGHT_PT_volume(_VolumePanel, bpy.types.Panel):
    bl_label = "Voxlight"
    bl_idname = "VOXLIGHT_PT_volume"
    # above the Empty's own display panel (order 0) where the editor has
    # no stored order yet
    bl_order = -1

    def draw(self, context):
        layout = _split(self.layout, decorate=False)
        p = context.object.voxlight
        if _draw_library_status(layout):
            err = runtime.last_failure(bpy.path.abspath(p.filepath), p.series)
            if err:
                box = layout.box()
                box.alert = True
                box.label(text=err, icon="ERROR")
                box.operator("voxlight.reload_volume", icon="FILE_REFRESH")
        layout.prop(p, "filepath")
        col = layout.column(align=True)
        col.label(text="%d x %d x %d voxels" % tuple(p.dims), icon="VOLUME_DATA")
        # the kind on a line of its own and the notes wrapped: a label that
        # runs past the panel's default width is cut, not wrapped
        count = _own_label_count(context.object)
        col.label(text=label_import.values_line(p.data_min, p.data_max, "", count))
        if count is None and _KIND_TEXT.get(tf.kind_of(p)):
            col.label(text=_KIND_TEXT[tf.kind_of(p)])
        if p.series:
            col.label(text="DICOM series %s" % p.series)
        for note in import_job.note_lines(p.reader_notes):  # what the reader assumed at import
            for i, line in enumerate(compat.wrap(note, _NOTE_CHARS)):
                col.label(text=line, icon="INFO" if i == 0 else "BLANK1")
        if p.frame_count > 1:  # 4D: which volume frame the scene frame shows
            col = _split(layout.column(align=True), decorate=True)
            col.label(text="%d volume frames" % p.frame_count)
            col.prop(p, "frame_mode")
            col.prop(p, "frame_offset" if p.frame_mode == "TIMELINE" else "fixed_frame")
        layout.operator("voxlight.convert_to_blender_volume", icon="VOLUME_DATA")


# ------------------------------------------------------- transfer function

_previews = None   # bpy.utils.previews collection of the histogram pictures
_picture_keys = {}  # object name -> what its picture shows (redrawn when it changes)
PICTURE_SIZE = (256, 224)  # wide enough to align, tall enough to read


def histogram_icon(obj):
    """icon_id of the object's histogram picture (histogram_image.render),
    regenerated when the histogram, the window or the ramp changed."""
    p = obj.voxlight
    counts, lo, hi = tf.histogram_of(obj)
    return picture_icon(obj.name, counts, lo, hi, p.window_low, p.window_high, tf.table(p, 64))


def picture_icon(name, counts, lo, hi, window_low, window_high, table, size=PICTURE_SIZE):
    """icon_id of the histogram picture `name` (histogram_image.render of
    the other arguments), regenerated when what it shows changed."""
    global _previews
    from bpy.utils import previews
    if _previews is None:
        _previews = previews.new()
    counts = np.asarray(counts, np.int64)
    key = (counts.tobytes(), lo, hi, window_low, window_high,
           table.tobytes() if table is not None else b"", tuple(size))
    if _picture_keys.get(name) != key or name not in _previews:
        if name in _previews:
            del _previews[name]  # a fresh preview: the icon cache sees the new pixels
        w, h = size
        img = histogram_image.render(counts, lo, hi, window_low, window_high, table, w, h,
                                     strip=max(8, h * 40 // PICTURE_SIZE[1]))
        pv = _previews.new(name)
        pv.image_size = (w, h)
        pv.image_pixels_float.foreach_set(img.ravel())  # 15x faster than a list
        _picture_keys[name] = key
    return _previews[name].icon_id


class VOXLIGHT_PT_volume_tf(_VolumePanel, bpy.types.Panel):
    bl_label = "Transfer Function"
    bl_idname = "VOXLIGHT_PT_volume_tf"
    bl_parent_id = "VOXLIGHT_PT_volume"

    def draw(self, context):
        obj = context.object
        p = obj.voxlight
        layout = self.layout
        if channel_props.drawn(p):  # the channels have their own colours and windows
            layout.label(text="Used when the channels are not drawn", icon="INFO")
        name, modified = tf.preset_state(p)
        label = (name + (" (modified)" if modified else "")) if name else "Custom"
        layout.menu("VOXLIGHT_MT_tf_presets", text=label, icon="PRESET")
        tex = p.tf_texture
        if tex is None or not tex.use_color_ramp:
            layout.operator("voxlight.tf_ramp", icon="ADD")
            return
        layout.template_color_ramp(tex, "color_ramp", expand=True)
        # The histogram over the window, aligned with the ramp above it, and
        # the whole data range with the window marked (histogram_image).
        # Blender draws a preview icon as the largest square its button
        # holds, so the button is as wide as the ramp and square.
        ui = 20.0 * context.preferences.view.ui_scale
        width_units = max(context.region.width / ui - 1.5, 4.0) \
            if context.region is not None else 14.0
        layout.template_icon(icon_value=histogram_icon(obj), scale=width_units)
        col = _split(layout.column(align=True))
        col.prop(p, "window_low", text="Window")
        col.prop(p, "window_high", text="High")
        layout.operator("voxlight.tf_fit_window", icon="FULLSCREEN_EXIT")
        _split(layout).prop(p, "opacity_scale")
        if _components(p) >= 3:  # a colour volume: its own colour or the ramp's
            _split(layout).prop(p, "color_source")


class VOXLIGHT_PT_volume_rendering(_VolumePanel, bpy.types.Panel):
    bl_label = "Rendering"
    bl_idname = "VOXLIGHT_PT_volume_rendering"
    bl_parent_id = "VOXLIGHT_PT_volume"

    def draw(self, context):
        p = context.object.voxlight
        layout = _split(self.layout)
        col = layout.column()
        col.prop(p, "step")
        col.prop(p, "jitter")
        col = layout.column()
        col.prop(p, "filter", text="Normals")
        sub = col.column()
        sub.active = p.filter not in FIXED_TAP_FILTERS
        sub.prop(p, "sample_distance", text="Distance", slider=True)


class VOXLIGHT_PT_volume_lighting(_VolumePanel, bpy.types.Panel):
    bl_label = "Lighting"
    bl_idname = "VOXLIGHT_PT_volume_lighting"
    bl_parent_id = "VOXLIGHT_PT_volume"

    def draw_header(self, context):
        self.layout.prop(context.object.voxlight, "shading", text="")

    def draw(self, context):
        p = context.object.voxlight
        layout = _split(self.layout)
        layout.active = p.shading
        layout.prop(p, "shading_model", text="Model")
        col = layout.column(align=True)
        col.prop(p, "ambient", slider=True)
        col.prop(p, "diffuse", slider=True)
        col.prop(p, "specular", slider=True)
        col.prop(p, "shininess")
        # Shadows, occlusion and scattering: not in Phong.
        col = layout.column(align=True)
        col.active = p.shading_model != "phong"
        col.prop(p, "occlusion_radius", text="Occlusion")
        col.prop(p, "occlusion_strength", text="Strength", slider=True)
        col.prop(p, "shadow_quality", text="Shadows")
        sub = layout.column()
        sub.active = p.shading_model in ("scatter", "path")
        sub.prop(p, "anisotropy", slider=True)
        if p.shading_model == "path":  # Monte Carlo: how many samples and bounces
            col = layout.column(align=True)
            col.prop(p, "path_samples", text="Samples")
            col.prop(p, "path_viewport_samples", text="Viewport")
            col.prop(p, "path_bounces", text="Bounces")
        # Scene shadows: the volume and the scene's meshes.
        # Short texts: a checkbox's text shares the value column with the
        # checkbox (the tooltips keep the detail).
        col = layout.column(heading="Scene Shadows", align=True)
        col.prop(p, "cast_shadows", text="Cast")
        sub = col.column(align=True)
        sub.active = p.shading_model != "phong"  # Phong has no shadows to cut
        sub.prop(p, "receive_shadows", text="Receive")


class VOXLIGHT_PT_volume_advanced(_VolumePanel, bpy.types.Panel):
    bl_label = "Advanced"
    bl_idname = "VOXLIGHT_PT_volume_advanced"
    bl_parent_id = "VOXLIGHT_PT_volume"
    bl_options = {"DEFAULT_CLOSED"}

    def draw(self, context):
        p = context.object.voxlight
        layout = _split(self.layout)
        layout.prop(p, "classify")
        layout.prop(p, "gradient_opacity", text="Edges")
        if p.gradient_opacity != "off":
            sub = layout.column(align=True)
            sub.prop(p, "gradient_ref", text="Reference")
            sub.prop(p, "gradient_exp", text="Exponent")
            if p.gradient_opacity == "iso":
                sub.prop(p, "iso_value")
                sub.prop(p, "iso_thickness", text="Thickness")
        col = layout.column(heading="Normals")
        col.prop(p, "reuse_gradients", text="Reuse")
        if p.filter == "precomputed":
            col.prop(p, "gradient_16f", text="16-bit Float")


# -------------------------------------------------------------- statistics

stats_drawn = []  # (object name, frame kind) the Statistics header showed last (tests)


def _components(p):
    """1 for a grey volume, 3 or 4 for a colour one; 1 while not loaded."""
    entry = runtime.find_entry(bpy.path.abspath(p.filepath), p.series)
    return entry.info.get("components", 1) if entry is not None else 1


def _last_frame(p):
    entry = runtime.find_entry(bpy.path.abspath(p.filepath), p.series)
    return entry.last_frame if entry is not None else None


_KIND_NAMES = {"refined": "full", "interactive": "preview", "render": "render"}


class VOXLIGHT_PT_volume_stats(_VolumePanel, bpy.types.Panel):
    """What the last frame of this volume cost. The viewport redraws this
    editor when its full-resolution frame arrives (viewport._poll), so the
    numbers are the final frame's, not the preview's."""
    bl_label = "Statistics"
    bl_idname = "VOXLIGHT_PT_volume_stats"
    bl_parent_id = "VOXLIGHT_PT_volume"
    bl_options = {"DEFAULT_CLOSED"}

    def draw_header_preset(self, context):
        frame = _last_frame(context.object.voxlight)
        kind = frame["kind"] if frame else ""
        if len(stats_drawn) > 64:
            del stats_drawn[:32]
        stats_drawn.append((context.object.name, kind))
        if frame:
            self.layout.label(text="%s, %.0f ms" % (_KIND_NAMES.get(kind, kind),
                                                    frame.get("seconds", 0.0) * 1000.0))

    def draw(self, context):
        frame = _last_frame(context.object.voxlight)
        layout = self.layout
        if not frame:
            layout.label(text="No frame rendered yet")
            return
        col = layout.column(align=True)
        col.label(text="Last frame (%s): %d x %d, %.0f ms, %d call%s"
                  % (_KIND_NAMES.get(frame["kind"], frame["kind"]), frame["width"],
                     frame["height"], frame.get("seconds", 0.0) * 1000.0, frame.get("calls", 1),
                     "" if frame.get("calls", 1) == 1 else "s"))
        col.label(text="%.2f M samples on %d rays, step %.3g voxels"
                  % (frame["samples"] / 1e6, frame["rays"], frame["effective_step"]))
        if frame["bricks_total"]:
            col.label(text="Occupied bricks: %d of %d (%d³ voxels)"
                      % (frame["bricks_occupied"], frame["bricks_total"], frame["brick_size"]))
        else:
            col.label(text="Empty-space skipping off")
        col.label(text=storage_text(frame))
        if stream_text(frame):
            col.label(text=stream_text(frame))
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


def stream_text(frame):
    """What a streamed volume's last frame read and still waits for (issue
    21); empty for other volumes."""
    level, pending = frame.get("stream_level", 0), frame.get("refine_pending", 0)
    read = frame.get("bytes_read", 0)
    if not (level or pending or read):
        return ""
    text = "Streamed: %.1f MiB read" % (read / 1048576.0)
    if level:
        text += ", coarsest level %d (%dx)" % (level, 1 << level)
    if pending:
        text += ", %d bricks loading" % pending
    return text


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
        layout = _split(self.layout, decorate=False)
        s = context.scene.voxlight
        _draw_library_status(layout)
        col = layout.column(heading="Viewport")
        col.prop(s, "viewport_enabled", text="Show")
        col.prop(s, "viewport_resolution", text="Resolution", slider=True)
        col.prop(s, "interactive_resolution", text="While Moving", slider=True)
        col.prop(s, "settle_time")
        col = layout.column(heading="Render")
        col.prop(s, "render_enabled", text="Composite")
        col.prop(s, "render_occlusion", text="Mesh Occlusion")
        col.prop(s, "render_separate_layer", text="Separate Layer")
        from . import scene_shadows
        if scene_shadows.note:  # how the last render applied the volume's shadows
            for i, line in enumerate(compat.wrap(scene_shadows.note, 40)):
                col.label(text=line, icon="INFO" if i == 0 else "BLANK1")
        layout.prop(s, "use_scene_lights")
        row = layout.row()
        row.active = s.use_scene_lights  # the World follows Scene Lights
        row.prop(s, "use_world_light")
        layout.prop(s, "backend")
        layout.prop(s, "storage")
        layout.prop(s, "memory_budget_mib", text="Budget (MiB)")
        layout.label(text="Frames: %d (%d library calls, %d stale dropped)"
                     % (runtime.render_count, runtime.call_count, runtime.cancelled_count))


_classes = (VOXLIGHT_PT_volume, VOXLIGHT_PT_volume_rendering, VOXLIGHT_PT_volume_tf,
            VOXLIGHT_PT_volume_lighting, VOXLIGHT_PT_volume_advanced, VOXLIGHT_PT_volume_stats,
            VOXLIGHT_PT_scene)


def _all_classes():
    """The panels in the order the editor shows them: a multi-channel
    volume's Channels right under its Voxlight panel, above the Transfer
    Function (sub-panels appear in the order they are registered)."""
    from . import channel_ui
    return _classes[:1] + channel_ui.CLASSES + _classes[1:]


def register():
    for c in _all_classes():
        bpy.utils.register_class(c)


def unregister():
    global _previews
    for c in reversed(_all_classes()):
        bpy.utils.unregister_class(c)
    if _previews is not None:
        from bpy.utils import previews
        previews.remove(_previews)
        _previews = None
    _picture_keys.clear()
