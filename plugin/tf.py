"""The transfer function: one editor, Blender's own ColorRamp, and the
presets that load into it.

Each volume owns a hidden Blend texture (Object.voxlight.tf_texture, named
".VXL TF <object>") whose ColorRamp is the transfer function: stop colours
are straight RGB, each stop's alpha is the opacity per voxel of path. The
ramp is sampled to TABLE_SIZE entries (ColorRamp.evaluate) and passed to the
library as vxl_render_params.tf_rgba; the window (Low/High) maps the ramp's
[0, 1] onto data values. The sampled table is part of the frame key
(native.params_digest hashes the arrays a params struct points at), so
editing a stop re-renders the viewport; F12 builds its params the same way.

Presets (tf_presets: the library's built-in tables and 3D Slicer's) are
placed on the volume's data by tf_fit (Hounsfield units on CT, the data's
histogram otherwise) and written into the ramp; the panel names the loaded
preset and says when the ramp has been edited since.

Files and scripts from before the single editor: the old "Transfer
Function" enum (Object.voxlight.preset) and "Use ColorRamp" still exist.
Setting the enum loads that preset into the ramp; a file saved with them
is converted when it is opened (migrate_legacy) so it looks as it did.
"""

import os

import bpy
import numpy as np

from .core import colour_space, lighting, runtime, tf_fit, tf_presets
from .operators import OnActiveVolume

TABLE_SIZE = tf_presets.TABLE_SIZE
# Object.voxlight.tf_version: the file format of a volume's look.
# 1: the single editor (ramp + explicit window); 2: the gradient filter's
# default became sobel8, so a volume saved before with the old default
# (central, never set, so not stored) is given central when its file opens;
# 3: shading models, new volumes default to shadowed, so a volume from
# before is given phong, its look then (lighting.upgrade);
# 4: the library renders in scene-linear colour, as Blender's ColorRamp and
# colour properties hold colours; a volume saved before held its ramp's and
# labels' colours as display (sRGB) values, which are decoded when its file
# opens (linear_colours), so its image looks as it did.
TF_SINGLE_EDITOR = 1
TF_LINEAR_COLOUR = 4
TF_VERSION = 4

# Kept for scripts written against the ColorRamp presets.
SLICER_PRESETS = tf_presets.SLICER_PRESETS
PRESET_ITEMS = [(k, p.name, p.description) for k, p in tf_presets.PRESETS.items()]


# ------------------------------------------------------------------ data

def kind_of(p):
    """The volume's kind of data ('ct', 'mr', 'pet', 'other'), as guessed
    at import; volumes from older files are guessed from their range."""
    return p.data_kind or tf_fit.guess_kind(p.data_min, p.data_max)


def stats_of(obj, info=None):
    """tf_fit.DataStats of the volume: the fine histogram of its live
    entry (or of `info`, during import) when there is one, else the
    32-bin histogram saved with the object."""
    p = obj.voxlight
    if info is None:
        entry = runtime.find_entry(bpy.path.abspath(p.filepath), p.series)
        info = entry.info if entry is not None else None
    if info is not None and info.get("histogram_fine") is not None:
        return tf_fit.DataStats(info["histogram_fine"], info["value_min"], info["value_max"])
    return tf_fit.DataStats(list(p.histogram), p.data_min, p.data_max)


def histogram_of(obj):
    """(counts, lo, hi) for the panel's picture: the finest one at hand."""
    s = stats_of(obj)
    return s.counts, s.lo, s.hi


def dicom_modality(path, series="", dims=None):
    """The DICOM Modality (0008,0060) of the imported series, "" when the
    input is not DICOM or the library does not say. Without a series
    choice: the only series, or the one of the volume's size `dims`."""
    from .core import native
    low = path.lower()
    if not (os.path.isdir(path) or low.endswith(".dcm") or os.path.basename(low) == "dicomdir"):
        return ""
    try:
        found = native.list_dicom_series(path)
    except Exception:  # a modality is a hint; its absence is not an error
        return ""
    if not found:
        return ""
    pick = None
    if series:
        for i, s in enumerate(found):
            if series in (str(i), s["uid"]):
                pick = s
    elif len(found) == 1:
        pick = found[0]
    elif dims is not None:
        same = [s for s in found if tuple(s["dims"]) == tuple(dims)]
        pick = same[0] if len(same) == 1 else None
    return (pick or {}).get("modality", "") or ""


# ------------------------------------------------------------------ ramp

def ensure_texture(obj, info=None):
    """The object's ColorRamp texture. A volume without one gets it, loaded
    with the preset that suits its data (tf_fit.default_preset: from the
    DICOM modality, the value range and the histogram). `info` is the
    import's volume info while the entry is not registered yet."""
    p = obj.voxlight
    tex = p.tf_texture
    if tex is not None and tex.use_color_ramp:
        return tex
    tex = bpy.data.textures.new(".VXL TF %s" % obj.name, type="BLEND")
    tex.use_color_ramp = True
    ramp = tex.color_ramp
    ramp.interpolation = "LINEAR"
    ramp.elements[0].position, ramp.elements[0].color = 0.0, (0.0, 0.0, 0.0, 0.0)
    ramp.elements[1].position, ramp.elements[1].color = 1.0, (1.0, 1.0, 1.0, 1.0)
    p.tf_texture = tex
    if not p.data_kind:
        p.data_kind = tf_fit.guess_kind(p.data_min, p.data_max,
                                        dicom_modality(bpy.path.abspath(p.filepath), p.series,
                                                       tuple(p.dims)))
    p.tf_version = TF_VERSION
    load_preset(obj, tf_fit.default_preset(p.data_kind), info=info)
    return tex


def preset_stops(stops):
    """A preset's stops [(position, rgba)] with their colours made
    scene-linear, as a ColorRamp holds colours: the presets' tables are
    display-referred (sRGB), as MRIcroGL's and 3D Slicer's are."""
    return [(pos, colour_space.rgba_to_linear(rgba)) for pos, rgba in stops]


def set_ramp(ramp, stops):
    """Replace a ColorRamp's stops with [(position, rgba), ...] (at most
    32, Blender's limit)."""
    els = ramp.elements
    while len(els) > 1:
        els.remove(els[-1])
    els[0].position = min(max(stops[0][0], 0.0), 1.0)
    els[0].color = stops[0][1]
    for pos, rgba in stops[1:]:
        e = els.new(min(max(pos, 0.0), 1.0))
        e.color = rgba
    # new() keeps elements sorted; an element at exactly the first stop's
    # position may sort before it, which evaluate() handles the same way.
    ramp.interpolation = "LINEAR"
    ramp.color_mode = "RGB"


def ramp_signature(ramp):
    """A string that changes when any stop, colour or the interpolation of
    the ramp changes (the panel's "modified" mark)."""
    parts = [ramp.interpolation, ramp.color_mode]
    for e in ramp.elements:
        parts.append("%.4f:%.4f,%.4f,%.4f,%.4f" % (e.position, *e.color))
    return ";".join(parts)


def preset_state(p):
    """(name of the loaded preset or "", edited since it was loaded)."""
    pr = tf_presets.PRESETS.get(p.tf_preset)
    if pr is None:
        return "", True
    tex = p.tf_texture
    modified = tex is None or not tex.use_color_ramp or \
        ramp_signature(tex.color_ramp) != p.tf_preset_signature
    return pr.name, modified


def load_preset(obj, key, info=None):
    """Write preset `key` (tf_presets.PRESETS), placed on this volume's
    data, into its ramp, and set the window."""
    p = obj.voxlight
    lo, hi, stops = tf_fit.place(key, kind_of(p), stats_of(obj, info))
    tex = p.tf_texture
    if tex is None or not tex.use_color_ramp:
        tex = ensure_texture(obj, info)  # creates, then loads the default: reloaded below
    set_ramp(tex.color_ramp, preset_stops(stops))
    p.window_low, p.window_high = lo, hi
    _set_legacy_flags(p)
    p.tf_preset = key
    p.tf_preset_signature = ramp_signature(tex.color_ramp)
    tex.update_tag()


def apply_preset(obj, key):
    """Kept for scripts: load a preset (now fitted to the data)."""
    load_preset(obj, key)


def fit_window(obj, low_quantile=0.0, high_quantile=0.995):
    """Place the window by the data's histogram. An unedited preset is
    placed again as loading it would; an edited ramp keeps its stops and is
    stretched over the non-background voxels from low_quantile to
    high_quantile. Returns (low, high)."""
    p = obj.voxlight
    if p.render_mode != "dvr":  # the other modes have their own windows
        from . import mode_start
        lo_hi = mode_start.fit_window(obj)
        if lo_hi is not None:
            return lo_hi
    name, modified = preset_state(p)
    if name and not modified:
        load_preset(obj, p.tf_preset)
    else:
        p.window_low, p.window_high = tf_fit.fit_window(stats_of(obj), low_quantile,
                                                        high_quantile)
    return p.window_low, p.window_high


def table(props, size=TABLE_SIZE):
    """The ramp sampled to a (size, 4) float32 straight-RGBA table, or None
    when the volume has no ramp."""
    tex = props.tf_texture
    if tex is None or not tex.use_color_ramp:
        return None
    ev = tex.color_ramp.evaluate
    out = np.empty((size, 4), np.float32)
    for i in range(size):
        out[i] = ev(i / (size - 1))
    return out


# ------------------------------------------------ files and scripts before TF_VERSION 1

_quiet = False  # set while this module writes the legacy flags itself


def _set_legacy_flags(p):
    """The old switches say what is now always true: the window and the
    ramp are in use."""
    global _quiet
    _quiet = True
    try:
        if not p.use_window:
            p.use_window = True
        if not p.use_color_ramp:
            p.use_color_ramp = True
    finally:
        _quiet = False


def _legacy_window(p, key):
    """The window the library used when the old settings gave none."""
    if p.use_window:
        return p.window_low, p.window_high
    if key == "CT":  # vxl_preset_window: Hounsfield air to dense bone
        return -1000.0, 2000.0
    return p.data_min, p.data_max


def _legacy_key(p):
    if p.preset == "auto":  # vxl_preset_resolve
        return "CT" if p.data_min <= -500 else "MRI"
    return tf_presets.LEGACY_ENUM.get(p.preset, "MRI")


def migrate_legacy(obj):
    """Convert a volume saved before the single editor so it looks the same:
    a library preset becomes its table in the ramp, and the window the
    library chose becomes the explicit window."""
    p = obj.voxlight
    key = _legacy_key(p)
    had_ramp = p.use_color_ramp and p.tf_texture is not None and p.tf_texture.use_color_ramp
    p.window_low, p.window_high = _legacy_window(p, key)
    if not had_ramp:
        tex = p.tf_texture
        if tex is None or not tex.use_color_ramp:
            tex = bpy.data.textures.new(".VXL TF %s" % obj.name, type="BLEND")
            tex.use_color_ramp = True
            p.tf_texture = tex
        set_ramp(tex.color_ramp, preset_stops(tf_presets.table_to_stops(tf_presets.builtin_table(key.lower()))))
        p.tf_preset = key
        p.tf_preset_signature = ramp_signature(tex.color_ramp)
    _set_legacy_flags(p)
    if not p.data_kind:
        p.data_kind = tf_fit.guess_kind(p.data_min, p.data_max)
    p.tf_version = TF_VERSION


def on_legacy_preset(props, context):
    """Update of the old "Transfer Function" enum: load that preset."""
    if _quiet:
        return
    obj = props.id_data
    if isinstance(obj, bpy.types.Object) and props.is_volume:
        key = _legacy_key(props) if props.preset != "auto" else \
            tf_fit.default_preset(kind_of(props))
        load_preset(obj, key)
    _redraw()


def on_legacy_use_ramp(props, context):
    """Update of the old "Use ColorRamp": off meant the library preset,
    which now means loading it into the ramp."""
    if _quiet:
        return
    if not props.use_color_ramp:
        on_legacy_preset(props, context)
    else:
        _redraw()


# ------------------------------------------------------------- operators

class VOXLIGHT_OT_tf_preset(OnActiveVolume, bpy.types.Operator):
    """Load a transfer-function preset into the volume's ColorRamp, placed on its data"""
    bl_idname = "voxlight.tf_preset"
    bl_label = "Load Transfer-Function Preset"
    bl_options = {"REGISTER", "UNDO"}

    preset: bpy.props.EnumProperty(name="Preset", items=PRESET_ITEMS,
                                   description="The preset to load")

    @classmethod
    def description(cls, context, properties):
        pr = tf_presets.PRESETS.get(properties.preset)
        return pr.description if pr is not None else cls.__doc__

    def execute(self, context):
        load_preset(context.object, self.preset)
        _redraw()
        return {"FINISHED"}


class VOXLIGHT_OT_tf_fit_window(OnActiveVolume, bpy.types.Operator):
    """Place the window by the data's histogram: an unedited preset is placed again, an edited ramp is stretched over the non-background values"""
    bl_idname = "voxlight.tf_fit_window"
    bl_label = "Fit Window to Data"
    bl_options = {"REGISTER", "UNDO"}

    low_quantile: bpy.props.FloatProperty(
        name="Low", default=0.0, min=0.0, max=1.0, subtype="FACTOR",
        description="Share of the non-background voxels below the window's start "
                    "(edited ramps)")
    high_quantile: bpy.props.FloatProperty(
        name="High", default=0.995, min=0.0, max=1.0, subtype="FACTOR",
        description="Share of the non-background voxels below the window's end "
                    "(edited ramps)")

    def execute(self, context):
        lo, hi = sorted((self.low_quantile, self.high_quantile))
        fit_window(context.object, lo, hi)
        _redraw()
        return {"FINISHED"}


class VOXLIGHT_OT_tf_ramp(OnActiveVolume, bpy.types.Operator):
    """Give the volume a ColorRamp transfer function again (with the preset that suits its data)"""
    bl_idname = "voxlight.tf_ramp"
    bl_label = "Create ColorRamp"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        ensure_texture(context.object)
        _redraw()
        return {"FINISHED"}


class VOXLIGHT_MT_tf_presets(bpy.types.Menu):
    """Presets by the data they are made for"""
    bl_idname = "VOXLIGHT_MT_tf_presets"
    bl_label = "Transfer-Function Presets"

    def draw(self, context):
        layout = self.layout
        for i, (heading, presets) in enumerate(tf_presets.menu_sections()):
            if i:
                layout.separator()
            layout.label(text=heading)
            for pr in presets:
                layout.operator(VOXLIGHT_OT_tf_preset.bl_idname, text=pr.name).preset = pr.key


def _redraw():
    from .properties import tag_redraw
    tag_redraw()
    wm = getattr(bpy.context, "window_manager", None)
    for win in (wm.windows if wm is not None else ()):
        for area in win.screen.areas:
            if area.type == "PROPERTIES":
                area.tag_redraw()


@bpy.app.handlers.persistent
def _on_depsgraph_update(scene, depsgraph=None):
    # Editing a ramp stop updates the texture ID; the 3D views then redraw,
    # and the frame key (which holds the sampled table) decides to render.
    if depsgraph is not None and depsgraph.id_type_updated("TEXTURE"):
        _redraw()


def upgrade(obj):
    """Bring a volume from an older file up to TF_VERSION, looking the same."""
    p = obj.voxlight
    old = p.tf_version
    if old < TF_SINGLE_EDITOR:
        migrate_legacy(obj)
    if old < 2 and p.get("filter") is None:
        p.filter = "central"  # the default it was saved with
    lighting.upgrade(p, old)
    if TF_SINGLE_EDITOR <= old < TF_LINEAR_COLOUR:  # a migrated legacy ramp is linear already
        linear_colours(obj)
    p.tf_version = TF_VERSION


def linear_colours(obj):
    """Decode the display (sRGB) colours a volume saved before
    TF_LINEAR_COLOUR holds: its ramp's stops and its labels' colours."""
    p = obj.voxlight
    tex = p.tf_texture
    if tex is not None and tex.use_color_ramp:
        signature_current = ramp_signature(tex.color_ramp) == p.tf_preset_signature
        for e in tex.color_ramp.elements:
            e.color = colour_space.rgba_to_linear(tuple(e.color))
        if signature_current:  # an unedited preset stays unedited
            p.tf_preset_signature = ramp_signature(tex.color_ramp)
    for lab in getattr(getattr(obj, "voxlight_labels", None), "labels", ()):
        lab.color = colour_space.rgba_to_linear(tuple(lab.color))


@bpy.app.handlers.persistent
def _on_load_post(*_args):
    for obj in bpy.data.objects:
        p = getattr(obj, "voxlight", None)
        if p is not None and p.is_volume and p.tf_version < TF_VERSION and obj.library is None:
            upgrade(obj)


_classes = (VOXLIGHT_OT_tf_preset, VOXLIGHT_OT_tf_fit_window, VOXLIGHT_OT_tf_ramp,
            VOXLIGHT_MT_tf_presets)
_handlers = (("depsgraph_update_post", _on_depsgraph_update), ("load_post", _on_load_post))


def register():
    for c in _classes:
        bpy.utils.register_class(c)
    for name, fn in _handlers:
        lst = getattr(bpy.app.handlers, name)
        if fn not in lst:
            lst.append(fn)


def unregister():
    pkg = __name__.rsplit(".", 1)[0]
    for name, fn in _handlers:
        lst = getattr(bpy.app.handlers, name)
        for h in list(lst):
            if getattr(h, "__name__", "") == fn.__name__ and \
                    getattr(h, "__module__", "").startswith(pkg):
                lst.remove(h)
    for c in reversed(_classes):
        bpy.utils.unregister_class(c)
