"""Blender properties: Object.voxlight (per volume) and Scene.voxlight
(viewport and F12 settings). Every render-affecting property is animatable
(Blender's default for PropertyGroup members) and redraws the viewports."""

import bpy
from bpy.props import (BoolProperty, EnumProperty, FloatProperty, FloatVectorProperty,
                       IntProperty, IntVectorProperty, PointerProperty, StringProperty)

from . import native

# UI names of the filters this add-on knows. The list itself comes from the
# library (vxl_filter_name up to VXL_FILTER_COUNT), so a filter added there
# appears in the panel without editing this file; each item's number is the
# library's VXL_FILTER_* value, so saved files and keyframes stay valid.
_FILTER_UI = {
    "central": ("Central", "Central differences, 6 taps"),
    "forward3": ("Forward", "Forward differences, 3 taps against the centre sample"),
    "sobel8": ("Sobel 8", "8 trilinear taps at (±d, ±d, ±d)"),
    "sobel14": ("Sobel 14", "6 face and 8 corner taps"),
    "sobel26": ("Sobel 26", "Classic weighted 26-neighbour Sobel"),
    "precomputed": ("Precomputed", "Blur + Sobel once per volume, stored in a texture"),
    "cubic": ("Cubic B-spline", "Analytic derivative of the interpolating cubic B-spline "
                                "(prefiltered once per volume), 24 fetches"),
}
# Filters whose taps do not depend on sampleDistance.
FIXED_TAP_FILTERS = {"precomputed", "cubic"}

_PRESET_UI = {
    "auto": ("Auto", "MRI or CT default, chosen from the data range"),
    "gray": ("Gray", "Gray ramp"),
    "bone": ("Bone", "Bone"),
    "hot": ("Hot", "Hot metal"),
    "mri": ("MRI", "MRI default"),
    "ct": ("CT", "CT default"),
}


def _items(names, ui, what):
    return [(n, *ui.get(n, (n.replace("_", " ").title(), "%s '%s' of libvoxlight" % (what, n))), i)
            for i, n in enumerate(names)]


def _library_names(method, fallback):
    try:
        return getattr(native.load_library(), method)() or fallback
    except native.LibraryUnavailable:
        return fallback  # the panels say why; the properties still register


FILTER_ITEMS = _items(_library_names("filter_names", native.FILTERS), _FILTER_UI,
                      "Gradient filter")
PRESET_ITEMS = _items(_library_names("preset_names", native.PRESETS), _PRESET_UI,
                      "Transfer-function preset")


def tag_redraw(self=None, context=None):
    """Property update callback: every 3D viewport shows the change."""
    wm = getattr(bpy.context, "window_manager", None)
    if wm is None:
        return
    for win in wm.windows:
        for area in win.screen.areas:
            if area.type == "VIEW_3D":
                area.tag_redraw()


class VoxlightVolumeProperties(bpy.types.PropertyGroup):
    # --- identity, set by the importer (not animatable: they are data, not looks)
    is_volume: BoolProperty(name="Voxlight Volume", default=False, options=set())
    filepath: StringProperty(name="File", subtype="FILE_PATH", options=set(),
                             description="The file (or folder) this volume renders",
                             update=tag_redraw)
    unit_scale: FloatProperty(name="Scene Units per mm", default=0.01, options=set(),
                              description="Scale applied at import (information only)")
    voxel_to_local: FloatVectorProperty(
        name="Voxel to Local", size=16, options=set(),
        description="Voxel -> object local matrix, column-major (set by the importer)")
    dims: IntVectorProperty(name="Dimensions", size=3, options=set())
    data_min: FloatProperty(name="Data Minimum", options=set())
    data_max: FloatProperty(name="Data Maximum", options=set())
    histogram: IntVectorProperty(name="Histogram", size=32, options=set(),
                                 description="Voxel counts in 32 bins over the data range "
                                             "(computed at import)")
    # --- DICOM series and 4D time series (frames.py maps scene frames to volume frames)
    series: StringProperty(name="DICOM Series", options=set(), update=tag_redraw,
                           description="Series of a DICOM folder: index or SeriesInstanceUID "
                                       "(empty = the only one)")
    frame_count: IntProperty(name="Volume Frames", default=1, min=1, options=set(),
                             description="Volumes in the file (4D: fMRI, cardiac phases)")
    frame_mode: EnumProperty(name="Frame", default="TIMELINE", update=tag_redraw,
                             items=[("TIMELINE", "Follow Timeline",
                                     "Scene frame Start Frame + n shows volume frame n", 0),
                                    ("FIXED", "Fixed", "Always show Volume Frame", 1)])
    frame_offset: IntProperty(name="Start Frame", default=1, update=tag_redraw,
                              description="Scene frame that shows volume frame 0")
    fixed_frame: IntProperty(name="Volume Frame", default=0, min=0, update=tag_redraw,
                             description="Volume frame shown in Fixed mode (0-based)")

    # --- gradients
    filter: EnumProperty(name="Gradient Filter", items=FILTER_ITEMS, default="central",
                         update=tag_redraw)
    sample_distance: FloatProperty(name="Sample Distance", default=1.0, min=0.25, max=3.0,
                                   description="Gradient tap offset in voxels",
                                   update=tag_redraw)
    reuse_gradients: BoolProperty(name="Reuse Gradients", default=False,
                                  description="Keep the previous sample's gradient direction "
                                              "when the gradient magnitude drops",
                                  update=tag_redraw)
    gradient_16f: BoolProperty(name="16-bit Float Gradients", default=False,
                               description="Store precomputed gradients as 16-bit float "
                                           "instead of 8 bit", update=tag_redraw)
    # --- sampling
    step: FloatProperty(name="Step", default=0.5, min=0.05, max=4.0, soft_min=0.1, soft_max=2.0,
                        description="Ray step in voxels (smaller = higher quality, slower)",
                        update=tag_redraw)
    jitter: BoolProperty(name="Jitter", default=True,
                         description="Jitter ray starts to remove wood-grain banding",
                         update=tag_redraw)
    # --- classification
    preset: EnumProperty(name="Transfer Function", items=PRESET_ITEMS, default="auto",
                         update=tag_redraw)
    use_color_ramp: BoolProperty(name="Use ColorRamp", default=False,
                                 description="Use the volume's ColorRamp (colour stops and "
                                             "their alpha = opacity) instead of the library "
                                             "preset", update=tag_redraw)
    tf_texture: PointerProperty(type=bpy.types.Texture, name="Transfer Function",
                                options=set(),
                                description="Hidden Blend texture whose ColorRamp is this "
                                            "volume's transfer function")
    classify: EnumProperty(
        name="Classification", default="post", update=tag_redraw,
        items=[("post", "Post", "Interpolate the value, then look it up", 0),
               ("pre", "Pre", "Classify voxels, then interpolate colour and opacity", 1),
               ("preint", "Pre-integrated", "Pre-integrated segments (sharp transfer "
                                            "functions without slabs)", 2)])
    gradient_opacity: EnumProperty(
        name="Gradient Opacity", default="off", update=tag_redraw,
        items=[("off", "Off", "Opacity from the transfer function only", 0),
               ("boundary", "Boundary", "Scale opacity by gradient magnitude "
                                        "(Levoy's boundary emphasis)", 1),
               ("iso", "Iso-surface", "Levoy's iso-value contour surface", 2)])
    gradient_ref: FloatProperty(name="Gradient Reference", default=0.05, min=0.0001,
                                soft_max=1.0, update=tag_redraw,
                                description="Gradient magnitude (normalised value per "
                                            "voxel) that gives full opacity")
    gradient_exp: FloatProperty(name="Gradient Exponent", default=1.0, min=0.01, max=16.0,
                                update=tag_redraw,
                                description="Exponent of the gradient-magnitude term")
    iso_value: FloatProperty(name="Iso Value", default=0.0, update=tag_redraw,
                             description="Data value of the iso-surface")
    iso_thickness: FloatProperty(name="Iso Thickness", default=1.0, min=0.01, max=16.0,
                                 update=tag_redraw,
                                 description="Thickness of the iso-surface in voxels")
    use_window: BoolProperty(name="Custom Window", default=False,
                             description="Map the transfer function onto Low..High instead of "
                                         "the preset's default window", update=tag_redraw)
    window_low: FloatProperty(name="Low", default=0.0, update=tag_redraw,
                              description="Data value at the start of the transfer function")
    window_high: FloatProperty(name="High", default=1.0, update=tag_redraw,
                               description="Data value at the end of the transfer function")
    opacity_scale: FloatProperty(name="Opacity", default=1.0, min=0.0, soft_max=4.0, max=100.0,
                                 description="Multiplies the transfer function's opacity",
                                 update=tag_redraw)
    # --- shading
    shading: BoolProperty(name="Shading", default=True,
                          description="Phong shading from the scene's lights; off = pure "
                                      "emission-absorption", update=tag_redraw)
    ambient: FloatProperty(name="Ambient", default=0.3, min=0.0, max=1.0, update=tag_redraw)
    diffuse: FloatProperty(name="Diffuse", default=0.7, min=0.0, max=1.0, update=tag_redraw)
    specular: FloatProperty(name="Specular", default=0.3, min=0.0, max=1.0, update=tag_redraw)
    shininess: FloatProperty(name="Shininess", default=24.0, min=1.0, max=256.0,
                             update=tag_redraw)


BACKEND_ITEMS = [("auto", "Auto", "EGL on a GPU, then OSMesa, then EGL on Mesa"),
                 ("osmesa", "OSMesa", "Software rendering (llvmpipe)"),
                 ("egl", "EGL", "EGL without a window (GPU or Mesa surfaceless)")]


class VoxlightSceneProperties(bpy.types.PropertyGroup):
    viewport_enabled: BoolProperty(name="Show in Viewport", default=True, update=tag_redraw)
    viewport_resolution: FloatProperty(
        name="Viewport Resolution", default=1.0, min=0.05, max=1.0, subtype="FACTOR",
        description="Fraction of the viewport's pixels rendered once the view is still",
        update=tag_redraw)
    interactive_resolution: FloatProperty(
        name="Interactive Resolution", default=0.35, min=0.05, max=1.0, subtype="FACTOR",
        description="Fraction of the pixels rendered while the view moves", update=tag_redraw)
    settle_time: FloatProperty(name="Refine After", default=0.3, min=0.0, max=5.0,
                               subtype="TIME_ABSOLUTE", unit="TIME_ABSOLUTE",
                               description="Seconds without view change before the "
                                           "full-resolution render")
    use_scene_lights: BoolProperty(name="Scene Lights", default=True,
                                   description="Light volumes with the scene's lights "
                                               "(off: headlight)", update=tag_redraw)
    render_enabled: BoolProperty(name="Composite in Renders", default=True,
                                 description="Render volumes in F12/animation renders and "
                                             "composite them over the render")
    render_occlusion: BoolProperty(name="Mesh Occlusion", default=True,
                                   description="Rasterise the scene's meshes so rays stop at "
                                               "them in F12 renders")
    backend: EnumProperty(name="Backend", items=BACKEND_ITEMS, default="auto",
                          description="OpenGL backend for new renderers")
    storage: EnumProperty(name="Storage", default="auto",
                          items=[("auto", "Auto", "One texture when it fits the texture limit and "
                                  "the budget, else bricked"),
                                 ("dense", "Dense", "One 3D texture"),
                                 ("bricked", "Bricked", "Bricks in a pool texture; constant bricks "
                                  "cost nothing"),
                                 ("sparse", "Sparse", "Only the bricks the transfer function can "
                                  "show; a coarser level when even they exceed the budget"),
                                 ("compressed", "Compressed", "Every brick as a palette of up to 256 "
                                  "values and 8-bit codes; the visible ones decoded into a cache")],
                          description="How volumes are held on the GPU (volumes reload when "
                                      "this changes)")
    memory_budget_mib: IntProperty(name="Memory Budget (MiB)", default=2048, min=1,
                                   max=1 << 20,
                                   description="GPU memory a volume may use (volumes reload "
                                               "when this changes)")


_classes = (VoxlightVolumeProperties, VoxlightSceneProperties)


def register():
    for c in _classes:
        bpy.utils.register_class(c)
    bpy.types.Object.voxlight = PointerProperty(type=VoxlightVolumeProperties)
    bpy.types.Scene.voxlight = PointerProperty(type=VoxlightSceneProperties)


def unregister():
    del bpy.types.Scene.voxlight
    del bpy.types.Object.voxlight
    for c in reversed(_classes):
        bpy.utils.unregister_class(c)
