"""The transfer function as Blender's own ColorRamp, and medical presets.

Each volume owns a hidden Blend texture (Object.voxlight.tf_texture, named
".VXL TF <object>") whose ColorRamp is the transfer function: stop colours
are straight RGB, each stop's alpha is the opacity per voxel of path. The
ramp is sampled to TABLE_SIZE entries (ColorRamp.evaluate) and passed to the
library as vxl_render_params.tf_rgba; the window (Low/High) maps the ramp's
[0, 1] onto data values. The sampled table is part of the frame key
(native.params_digest hashes the arrays a params struct points at), so
editing a stop re-renders the viewport; F12 builds its params the same way.
"""

import bpy
import numpy as np

TABLE_SIZE = 256

# Scalar-opacity and colour-transfer points copied from 3D Slicer,
# Modules/Loadable/VolumeRendering/Resources/presets.xml (VolumeProperty
# "scalarOpacity" = x, opacity pairs; "colorTransfer" = x, r, g, b
# quadruples; x in data units: Hounsfield units for CT).
SLICER_PRESETS = {
    "CT_BONE": {
        "name": "CT Bone", "slicer": "CT-Bone",
        "opacity": [(-3024, 0), (-16.4458, 0), (641.385, 0.715686), (3071, 0.705882)],
        "color": [(-3024, 0, 0, 0), (-16.4458, 0.729412, 0.254902, 0.301961),
                  (641.385, 0.905882, 0.815686, 0.552941), (3071, 1, 1, 1)],
    },
    "CT_SOFT_TISSUE": {
        "name": "CT Soft Tissue", "slicer": "CT-Soft-Tissue",
        "opacity": [(-2048, 0), (-167.01, 0), (-160, 1), (240, 1), (3661, 1)],
        "color": [(-2048, 0, 0, 0), (-167.01, 0, 0, 0),
                  (-160, 0.0556356, 0.0556356, 0.0556356), (240, 1, 1, 1), (3661, 1, 1, 1)],
    },
    "CT_LUNG": {
        "name": "CT Lung", "slicer": "CT-Lung",
        "opacity": [(-1000, 0), (-600, 0), (-599, 0.15), (-400, 0.15), (-399, 0), (2952, 0)],
        "color": [(-1000, 0.3, 0.3, 1), (-600, 0, 0, 1), (-530, 0.134704, 0.781726, 0.0724558),
                  (-460, 0.929244, 1, 0.109473), (-400, 0.888889, 0.254949, 0.0240258),
                  (2952, 1, 0.3, 0.3)],
    },
    "MR_DEFAULT": {
        "name": "MR Default", "slicer": "MR-Default",
        "opacity": [(0, 0), (20, 0), (40, 0.15), (120, 0.3), (220, 0.375), (1024, 0.5)],
        "color": [(0, 0, 0, 0), (20, 0.168627, 0, 0), (40, 0.403922, 0.145098, 0.0784314),
                  (120, 0.780392, 0.607843, 0.380392), (220, 0.847059, 0.835294, 0.788235),
                  (1024, 1, 1, 1)],
    },
    "MR_ANGIO": {
        "name": "MR Angio", "slicer": "MR-Angio",
        "opacity": [(-2048, 0), (151.354, 0), (158.279, 0.4375), (190.112, 0.580357),
                    (200.873, 0.732143), (3661, 0.741071)],
        "color": [(-2048, 0, 0, 0), (151.354, 0, 0, 0), (158.279, 0.74902, 0.376471, 0),
                  (190.112, 1, 0.866667, 0.733333), (200.873, 0.937255, 0.937255, 0.937255),
                  (3661, 1, 1, 1)],
    },
}
PRESET_ITEMS = [(k, v["name"], "3D Slicer's %s volume-rendering preset" % v["slicer"])
                for k, v in SLICER_PRESETS.items()]


def preset_stops(key):
    """(window_low, window_high, [(position, (r, g, b, a)), ...]) for a
    preset: stops at the union of the opacity and colour points, positions
    normalised to the window. The window starts at the last point before
    the opacity first rises (everything below is transparent and the table
    clamps), so the 256 entries are spent where the preset changes."""
    pr = SLICER_PRESETS[key]
    op = np.array(pr["opacity"], np.float64)
    co = np.array(pr["color"], np.float64)
    xs = np.unique(np.concatenate([op[:, 0], co[:, 0]]))
    first_visible = np.nonzero(op[:, 1] > 0)[0]
    lo = op[max(first_visible[0] - 1, 0), 0] if len(first_visible) else xs[0]
    hi = xs[-1]
    xs = xs[xs >= lo]
    stops = []
    for x in xs:
        rgb = [float(np.interp(x, co[:, 0], co[:, c])) for c in (1, 2, 3)]
        a = float(np.interp(x, op[:, 0], op[:, 1]))
        stops.append((float((x - lo) / (hi - lo)), (*rgb, a)))
    return float(lo), float(hi), stops


def ensure_texture(obj):
    """The object's ColorRamp texture, created (grey ramp) when missing."""
    p = obj.voxlight
    tex = p.tf_texture
    if tex is None or not tex.use_color_ramp:
        tex = bpy.data.textures.new(".VXL TF %s" % obj.name, type="BLEND")
        tex.use_color_ramp = True
        ramp = tex.color_ramp
        ramp.interpolation = "LINEAR"
        ramp.elements[0].position, ramp.elements[0].color = 0.0, (0.0, 0.0, 0.0, 0.0)
        ramp.elements[1].position, ramp.elements[1].color = 1.0, (1.0, 1.0, 1.0, 1.0)
        p.tf_texture = tex
    return tex


def set_ramp(ramp, stops):
    """Replace a ColorRamp's stops with [(position, rgba), ...]."""
    els = ramp.elements
    while len(els) > 1:
        els.remove(els[-1])
    els[0].position = stops[0][0]
    els[0].color = stops[0][1]
    for pos, rgba in stops[1:]:
        e = els.new(min(max(pos, 0.0), 1.0))
        e.color = rgba
    # new() keeps elements sorted; an element at exactly the first stop's
    # position may sort before it, which evaluate() handles the same way.
    ramp.interpolation = "LINEAR"
    ramp.color_mode = "RGB"


def apply_preset(obj, key):
    """Rewrite the object's ramp from a preset and set its window."""
    lo, hi, stops = preset_stops(key)
    tex = ensure_texture(obj)
    set_ramp(tex.color_ramp, stops)
    p = obj.voxlight
    p.window_low, p.window_high = lo, hi
    p.use_window = True
    p.use_color_ramp = True
    tex.update_tag()


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


_BARS = " ▁▂▃▄▅▆▇█"


def histogram_text(counts):
    """One line of block characters, log-scaled counts."""
    c = np.log1p(np.asarray(counts, np.float64))
    if c.max() <= 0:
        return ""
    lv = np.round(c / c.max() * (len(_BARS) - 1)).astype(int)
    return "".join(_BARS[i] for i in lv)


class VOXLIGHT_OT_tf_preset(bpy.types.Operator):
    """Rewrite the volume's ColorRamp and window from a 3D Slicer preset"""
    bl_idname = "voxlight.tf_preset"
    bl_label = "Load Transfer-Function Preset"
    bl_options = {"REGISTER", "UNDO"}

    preset: bpy.props.EnumProperty(name="Preset", items=PRESET_ITEMS)

    @classmethod
    def poll(cls, context):
        return context.object is not None and context.object.voxlight.is_volume

    def execute(self, context):
        apply_preset(context.object, self.preset)
        _redraw()
        return {"FINISHED"}


class VOXLIGHT_OT_tf_ramp(bpy.types.Operator):
    """Give the volume a ColorRamp transfer function (grey ramp)"""
    bl_idname = "voxlight.tf_ramp"
    bl_label = "Create ColorRamp"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        return context.object is not None and context.object.voxlight.is_volume

    def execute(self, context):
        ensure_texture(context.object)
        context.object.voxlight.use_color_ramp = True
        _redraw()
        return {"FINISHED"}


def _redraw():
    from .properties import tag_redraw
    tag_redraw()


@bpy.app.handlers.persistent
def _on_depsgraph_update(scene, depsgraph=None):
    # Editing a ramp stop updates the texture ID; the 3D views then redraw,
    # and the frame key (which holds the sampled table) decides to render.
    if depsgraph is not None and depsgraph.id_type_updated("TEXTURE"):
        _redraw()


_classes = (VOXLIGHT_OT_tf_preset, VOXLIGHT_OT_tf_ramp)


def register():
    for c in _classes:
        bpy.utils.register_class(c)
    if _on_depsgraph_update not in bpy.app.handlers.depsgraph_update_post:
        bpy.app.handlers.depsgraph_update_post.append(_on_depsgraph_update)


def unregister():
    for h in list(bpy.app.handlers.depsgraph_update_post):
        if getattr(h, "__name__", "") == "_on_depsgraph_update" and \
                getattr(h, "__module__", "").startswith(__name__.rsplit(".", 1)[0]):
            bpy.app.handlers.depsgraph_update_post.remove(h)
    for c in reversed(_classes):
        bpy.utils.unregister_class(c)
