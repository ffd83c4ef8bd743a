"""Blender properties: Object.voxlight (per volume) and Scene.voxlight
(viewport and F12 settings). Every render-affecting property is animatable
(Blender's default for PropertyGroup members) and redraws the viewports."""

import bpy
from bpy.props import (BoolProperty, CollectionProperty, EnumProperty, FloatProperty,
                       FloatVectorProperty, IntProperty, IntVectorProperty, PointerProperty,
                       StringProperty)

from . import channel_props, cutaway_props, tf
from .core import lighting, native

# UI names of the filters this add-on knows. The list itself comes from the
# library (vxl_filter_name up to VXL_FILTER_COUNT), so a filter added there
# appears in the panel without editing this file; each item's number is the
# library's VXL_FILTER_* value, so saved files and keyframes stay valid.
_FILTER_UI = {
    "central": ("Central", "Central: fast, good on clean data; on noisy 8-bit scans it can draw "
                           "faint diagonal stripes on flat regions (6 samples per step)"),
    "forward3": ("Forward", "Forward: the fastest, normals slightly shifted; for quick previews "
                            "(3 samples)"),
    "sobel8": ("Sobel 8", "Sobel 8: the default; about Central's cost, smoother, and no "
                          "lattice stripes on noisy scans (8 samples)"),
    "sobel14": ("Sobel 14", "Sobel 14: smoother, for mildly noisy scans (14 samples)"),
    "sobel26": ("Sobel 26", "Sobel 26: smooth normals on noisy scans (26 samples, slower)"),
    "precomputed": ("Precomputed", "Precomputed: blurred normals worked out once per volume "
                                   "and stored; smooth and fast while orbiting, costs GPU "
                                   "memory"),
    "cubic": ("Cubic B-spline", "Cubic B-spline: normals of a cubic through every voxel; "
                                "detailed surfaces on clean or synthetic data, grainy on noisy "
                                "scans (64 voxels per sample)"),
    "cubic-smooth": ("Cubic Smooth", "Cubic Smooth: an approximating B-spline that smooths as it "
                                     "reconstructs; the smoothest cubic normals on real scans "
                                     "(no extra memory)"),
}
# Filters whose taps do not depend on sampleDistance.
FIXED_TAP_FILTERS = {"precomputed", "cubic", "cubic-smooth"}

# The library's presets by name: the old "Transfer Function" enum, kept so
# files and scripts that set it keep working (tf.on_legacy_preset loads the
# chosen preset into the ColorRamp).
_PRESET_UI = {
    "auto": ("Auto", "The preset that suits the data (CT or MRI)"),
    "gray": ("Gray", "Grey ramp"),
    "bone": ("Bone", "Ivory surfaces"),
    "hot": ("Hot", "Heat map"),
    "mri": ("MRI", "Warm skin fading to white"),
    "ct": ("CT", "Soft tissue faint red, bone ivory"),
}


def _items(names, ui, what):
    return [(n, *ui.get(n, (n.replace("_", " ").title(), "%s '%s' of libvoxlight" % (what, n))), i)
            for i, n in enumerate(names)]


def _library_names(kind):
    """The library's names of enumeration `kind` (vxl_<kind>_name), or the
    binding's fallback copy when no library loads."""
    fallback = native.ENUM_FALLBACKS[kind]
    try:
        return native.load_library().names(kind) or fallback
    except native.LibraryUnavailable:
        return fallback  # the panels say why; the properties still register


# UI names of the other enumerations the panels offer; like the filters, the
# identifiers and numbers are the library's (VXL_CLASSIFY_*, VXL_GOPACITY_*,
# VXL_BACKEND_*, VXL_STORAGE_*).
_CLASSIFY_UI = {
    "post": ("Post", "Post: look up each sample's value; sharp, the usual choice"),
    "pre": ("Pre", "Pre: colour the voxels, then blend between them; softer, blockier edges"),
    "preint": ("Pre-integrated", "Pre-integrated: exact between samples; for narrow spikes in "
                                 "the ramp (no slab artefacts)"),
}
_GRADIENT_OPACITY_UI = {
    "off": ("Off", "Opacity from the transfer function only"),
    "boundary": ("Boundary", "Boundary: only where values change (edges between tissues) stays "
                             "opaque; uniform regions fade"),
    "iso": ("Iso-surface", "Iso-surface: a thin shell at one value, like a surface mesh"),
}
_SHADING_MODEL_UI = {
    "phong": ("Phong", "Phong: each sample lit on its own, no shadows (the look of files from "
                       "before shadows)"),
    "shadowed": ("Shadowed", "Shadowed: Phong with the volume's own shadows from every light "
                             "and ambient occlusion in folds and crevices"),
    "scatter": ("Scatter", "Scatter: shadows, and light scattered through soft tissue where "
                           "there is no clear surface (Anisotropy sets its direction)"),
    "path": ("Path", "Path: light scattered many times through the volume (Monte Carlo, as "
                     "Cycles): the viewport refines sample by sample, F12 takes Samples"),
}
_BACKEND_UI = {
    "auto": ("Auto", "EGL on a GPU, then OSMesa, then EGL on Mesa"),
    "osmesa": ("OSMesa", "Software rendering (llvmpipe)"),
    "egl": ("EGL", "EGL without a window (GPU or Mesa surfaceless)"),
    "wgl": ("WGL", "Windows' OpenGL (the GPU's driver)"),
}
_STORAGE_UI = {
    "auto": ("Auto", "One texture when it fits the texture limit and the budget, else bricked"),
    "dense": ("Dense", "One 3D texture"),
    "bricked": ("Bricked", "Bricks in a pool texture; constant bricks cost nothing"),
    "sparse": ("Sparse", "Only the bricks the transfer function can show; a coarser level when "
                         "even they exceed the budget"),
    "compressed": ("Compressed", "Every brick as a palette of up to 256 values and 8-bit codes; "
                                 "the visible ones decoded into a cache"),
}

FILTER_ITEMS = _items(_library_names("filter"), _FILTER_UI, "Gradient filter")
PRESET_ITEMS = _items(_library_names("preset"), _PRESET_UI, "Transfer-function preset")
CLASSIFY_ITEMS = _items(_library_names("classify"), _CLASSIFY_UI, "Classification")
GRADIENT_OPACITY_ITEMS = _items(_library_names("gradient_opacity"), _GRADIENT_OPACITY_UI,
                                "Gradient opacity mode")
SHADING_MODEL_ITEMS = _items(_library_names("shading_model"), _SHADING_MODEL_UI,
                             "Shading model")
BACKEND_ITEMS = _items(_library_names("backend"), _BACKEND_UI, "Backend")
STORAGE_ITEMS = _items(_library_names("storage"), _STORAGE_UI, "Storage")
MODE_ITEMS = _items(_library_names("mode"), cutaway_props.MODE_UI, "Render mode")
INTERPOLATION_ITEMS = _items(_library_names("interpolation"), cutaway_props.INTERPOLATION_UI,
                             "Interpolation")


def tag_redraw(self=None, context=None):
    """Property update callback: every 3D viewport shows the change."""
    wm = getattr(bpy.context, "window_manager", None)
    if wm is None:
        return
    for win in wm.windows:
        for area in win.screen.areas:
            if area.type == "VIEW_3D":
                area.tag_redraw()


def _render_mode_changed(self, context):
    from . import mode_start
    mode_start.switched(self, context)
    tag_redraw(self, context)


class VoxlightVolumeProperties(bpy.types.PropertyGroup):
    # --- identity, set by the importer (not animatable: they are data, not looks)
    is_volume: BoolProperty(name="Voxlight Volume", default=False, options=set(),
                            description="This object is a volume Voxlight renders")
    filepath: StringProperty(name="File", subtype="FILE_PATH", options=set(),
                             description="The file (or folder) this volume renders",
                             update=tag_redraw)
    unit_scale: FloatProperty(name="Scene Units per mm", default=0.01, options=set(),
                              description="Scale applied at import (information only)")
    voxel_to_local: FloatVectorProperty(
        name="Voxel to Local", size=16, options=set(),
        description="Voxel -> object local matrix, column-major (set by the importer)")
    dims: IntVectorProperty(name="Dimensions", size=3, options=set(),
                            description="Voxels along x, y and z")
    data_min: FloatProperty(name="Data Minimum", options=set(),
                            description="Lowest value in the volume (data units)")
    data_max: FloatProperty(name="Data Maximum", options=set(),
                            description="Highest value in the volume (data units)")
    data_kind: StringProperty(name="Kind of Data", options=set(),
                              description="ct, mr, pet or other: decides how presets are "
                                          "placed (set at import from the DICOM modality or "
                                          "the value range)")
    histogram: IntVectorProperty(name="Histogram", size=32, options=set(),
                                 description="Voxel counts in 32 bins over the data range "
                                             "(computed at import)")
    # --- DICOM series and 4D time series (frames.py maps scene frames to volume frames)
    series: StringProperty(name="DICOM Series", options=set(), update=tag_redraw,
                           description="Series of a DICOM folder: index or SeriesInstanceUID "
                                       "(empty = the only one)")
    # Set by the importer (orientation.py); the turn is baked into the
    # object's matrix, so reloads keep it and this records which it was.
    orientation: EnumProperty(
        name="Orientation", default="FILE", options=set(),
        description="How the import placed the file's axes in the scene",
        items=[("FILE", "File Axes", "As in the file: scanner RAS (face toward +Y) for medical "
                                     "formats, the data's own axes for stacks and OpenVDB", 0),
               ("BLENDER_VIEWS", "Blender Views", "Turned 180 degrees about Z so Blender's Front "
                                                  "view shows the face", 1)])
    frame_count: IntProperty(name="Volume Frames", default=1, min=1, options=set(),
                             description="Volumes in the file (4D: fMRI, cardiac phases)")
    # Set at import from vxl_volume_info.notes, so the panel keeps showing
    # what the reader assumed after the import's report has scrolled away.
    reader_notes: StringProperty(name="Reader Notes", default="", options=set(),
                                 description="What the reader decided rather than read at import "
                                             "(e.g. a voxel size assumed), a sentence per decision")
    frame_mode: EnumProperty(name="Frame", default="TIMELINE", update=tag_redraw,
                             description="Which volume of a 4D series is shown",
                             items=[("TIMELINE", "Follow Timeline",
                                     "Scene frame Start Frame + n shows volume frame n", 0),
                                    ("FIXED", "Fixed", "Always show Volume Frame", 1)])
    frame_offset: IntProperty(name="Start Frame", default=1, update=tag_redraw,
                              description="Scene frame that shows volume frame 0")
    fixed_frame: IntProperty(name="Volume Frame", default=0, min=0, update=tag_redraw,
                             description="Volume frame shown in Fixed mode (0-based)")

    # --- gradients
    # sobel8 by default: on 8-bit scans central differences draw the voxel
    # lattice as faint stripes in orthographic views (tests/test_stripes.c,
    # docs/filters_on_scans.md); sobel8 does not, for ~10% more per frame.
    filter: EnumProperty(name="Gradient Filter", items=FILTER_ITEMS, default="sobel8",
                         description="How the surface normals that lighting needs are worked "
                                     "out: smoother filters hide scanner noise, cost more",
                         update=tag_redraw)
    sample_distance: FloatProperty(name="Sample Distance", default=1.0, min=0.25, max=3.0,
                                   description="How far apart, in voxels, the filter's samples "
                                               "are: larger is smoother, smaller keeps fine "
                                               "detail",
                                   update=tag_redraw)
    reuse_gradients: BoolProperty(name="Reuse Gradients", default=False,
                                  description="Where the surface normal becomes unreliable "
                                              "(flat regions), keep the last good one: fewer "
                                              "speckles inside uniform tissue",
                                  update=tag_redraw)
    gradient_16f: BoolProperty(name="16-bit Float Gradients", default=False,
                               description="Store the precomputed normals more precisely "
                                           "(16-bit float instead of 8 bit): smoother shading, "
                                           "twice the memory", update=tag_redraw)
    # --- sampling
    step: FloatProperty(name="Step", default=0.5, min=0.05, max=4.0, soft_min=0.1, soft_max=2.0,
                        description="Distance between samples along each ray, in voxels: "
                                    "smaller is finer and slower",
                        update=tag_redraw)
    jitter: BoolProperty(name="Jitter", default=True,
                         description="Start each ray at a slightly different depth: trades "
                                     "wood-grain banding for fine noise",
                         update=tag_redraw)
    # --- classification
    preset: EnumProperty(name="Library Preset", items=PRESET_ITEMS, default="auto",
                         description="Old files and scripts: setting it loads that preset into "
                                     "the ColorRamp", update=tf.on_legacy_preset)
    use_color_ramp: BoolProperty(name="Use ColorRamp", default=False,
                                 description="Old files and scripts: the ColorRamp is always the "
                                             "transfer function now; switching this off loads "
                                             "the Library Preset into it",
                                 update=tf.on_legacy_use_ramp)
    tf_preset: StringProperty(name="Loaded Preset", options=set(),
                              description="The preset last loaded into the ColorRamp")
    tf_preset_signature: StringProperty(options={"HIDDEN"},
                                        description="The ramp as the preset left it (to tell "
                                                    "when it has been edited)")
    tf_version: IntProperty(options={"HIDDEN"}, default=0,
                            description="1: transfer function in the ColorRamp only; 0: a file "
                                        "from before, converted when opened")
    tf_texture: PointerProperty(type=bpy.types.Texture, name="Transfer Function",
                                options=set(),
                                description="Hidden Blend texture whose ColorRamp is this "
                                            "volume's transfer function")
    classify: EnumProperty(
        name="Classification", default="post", update=tag_redraw,
        description="When the transfer function is applied: to each sample (sharp) or to "
                    "the voxels before sampling (soft)",
        items=CLASSIFY_ITEMS)
    gradient_opacity: EnumProperty(
        name="Gradient Opacity", default="off", update=tag_redraw,
        description="Make opacity depend on how fast values change, not only on the value",
        items=GRADIENT_OPACITY_ITEMS)
    gradient_ref: FloatProperty(name="Gradient Reference", default=0.05, min=0.0001,
                                soft_max=1.0, update=tag_redraw,
                                description="How sharp an edge must be for full opacity "
                                            "(change of the normalised value per voxel)")
    gradient_exp: FloatProperty(name="Gradient Exponent", default=1.0, min=0.01, max=16.0,
                                update=tag_redraw,
                                description="Above 1, weak edges fade faster; below 1, "
                                            "they stay visible")
    iso_value: FloatProperty(name="Iso Value", default=0.0, update=tag_redraw,
                             description="The value, in data units, the surface is drawn "
                                         "at")
    iso_thickness: FloatProperty(name="Iso Thickness", default=1.0, min=0.01, max=16.0,
                                 update=tag_redraw,
                                 description="How thick the surface is, in voxels")
    use_window: BoolProperty(name="Custom Window", default=False, update=tag_redraw,
                             description="Old files and scripts: the window is always used "
                                         "now (files from before are converted when opened)")
    window_low: FloatProperty(name="Low", default=0.0, update=tag_redraw,
                              description="The data value at the ramp's left end: lower values "
                                          "take the leftmost colour")
    window_high: FloatProperty(name="High", default=1.0, update=tag_redraw,
                               description="The data value at the ramp's right end: higher "
                                           "values take the rightmost colour")
    color_source: EnumProperty(
        name="Colour", default="auto", update=tag_redraw,
        items=[("auto", "Data", "A colour volume's own colour (RGB, RGBA) at each sample; the "
                                "transfer function gives the opacity"),
               ("tf", "Transfer Function", "The ramp's colour, as for a grey volume: the colour "
                                           "volume shows its opacity source")],
        description="Where the colour of a colour volume (RGB, RGBA) comes from; grey volumes "
                    "always take the ramp's")
    opacity_scale: FloatProperty(name="Opacity", default=1.0, min=0.0, soft_max=4.0, max=100.0,
                                 description="Makes the whole volume more (above 1) or less "
                                             "(below 1) opaque",
                                 update=tag_redraw)
    # --- shading
    shading: BoolProperty(name="Shading", default=True,
                          description="Light the volume's surfaces with the scene's lights; "
                                      "off shows the colours unlit, like an X-ray in colour",
                          update=tag_redraw)
    ambient: FloatProperty(name="Ambient", default=0.3, min=0.0, max=1.0, update=tag_redraw,
                           description="Light everywhere, even in shadow: higher is flatter")
    diffuse: FloatProperty(name="Diffuse", default=0.7, min=0.0, max=1.0, update=tag_redraw,
                           description="Light that depends on the surface facing the lamp: "
                                       "shows shape")
    specular: FloatProperty(name="Specular", default=0.3, min=0.0, max=1.0, update=tag_redraw,
                            description="Strength of the shiny highlights")
    shininess: FloatProperty(name="Shininess", default=24.0, min=1.0, max=256.0,
                             update=tag_redraw,
                             description="Size of the highlights: higher is smaller and "
                                         "sharper, like a glossier surface")
    # --- lighting (defaults and old files: lighting.py)
    shading_model: EnumProperty(name="Shading Model", items=SHADING_MODEL_ITEMS,
                                default=lighting.DEFAULT_MODEL, update=tag_redraw,
                                description="How light reaches each sample: local Phong, with "
                                            "shadows and occlusion, or with scattering too")
    path_samples: IntProperty(name="Samples", default=64, min=1, max=65536, soft_max=1024,
                              update=tag_redraw,
                              description="Path: samples per pixel in F12; the viewport refines "
                                          "up to Viewport Samples")
    path_viewport_samples: IntProperty(name="Viewport Samples", default=16, min=1, max=65536,
                                       soft_max=256, update=tag_redraw,
                                       description="Path: samples the still viewport accumulates, "
                                                   "one a redraw")
    path_bounces: IntProperty(name="Bounces", default=4, min=1, max=64, update=tag_redraw,
                              description="Path: how many times light may scatter on its way to "
                                          "the eye (1 is single scattering)")
    occlusion_radius: FloatProperty(name="Occlusion Radius",
                                    default=lighting.DEFAULT_OCCLUSION_RADIUS, min=0.0, max=64.0,
                                    soft_max=16.0, update=tag_redraw,
                                    description="How far, in voxels, the surroundings of a "
                                                "sample shade it (ambient occlusion): folds "
                                                "and crevices darken; 0 is off")
    occlusion_strength: FloatProperty(name="Occlusion Strength", subtype="FACTOR",
                                      default=lighting.DEFAULT_OCCLUSION_STRENGTH, min=0.0,
                                      max=1.0, update=tag_redraw,
                                      description="How much ambient occlusion darkens the "
                                                  "ambient light: 1 fully, 0 not at all")
    anisotropy: FloatProperty(name="Anisotropy", default=0.0, min=-0.99, max=0.99,
                              subtype="FACTOR", update=tag_redraw,
                              description="Scatter: which way light scatters in tissue; above "
                                          "0 forward (glows when lit from behind), below 0 "
                                          "back towards the light, 0 evenly")
    shadow_quality: EnumProperty(name="Shadow Quality", items=lighting.SHADOW_QUALITIES,
                                 default="AUTO", update=tag_redraw,
                                 description="Resolution of the volumes that hold each light's "
                                             "shadows: higher is crisper and slower to update "
                                             "when a light moves")
    # --- scene shadows (scene_shadows.py, compositor.py)
    cast_shadows: BoolProperty(name="Cast Shadows", default=True, update=tag_redraw,
                               description="The volume darkens the meshes behind it as seen "
                                           "from each light (F12: each light's direct light; "
                                           "viewport: a preview)")
    receive_shadows: BoolProperty(name="Receive Shadows", default=True, update=tag_redraw,
                                  description="Meshes between a light and the volume shadow it "
                                              "(meshes whose Shadow visibility is on; Shadowed "
                                              "and Scatter models)")
    # --- render mode, MatCap and cutaways (cutaway_props.py, cutaway.py)
    render_mode: EnumProperty(name="Render Mode", items=MODE_ITEMS, default="dvr",
                              update=_render_mode_changed,
                              description="How each ray's samples become a pixel: volume "
                                          "rendering, a projection, or an iso-surface")
    # Each mode's own window (mode_start.py): (low, high) per mode in
    # mode_fit.MODES order, a bit per mode that has one, and the mode the
    # current Low/High belong to.
    mode_windows: FloatVectorProperty(name="Mode Windows", size=10, options={"HIDDEN"},
                                      description="Low/High of each render mode, kept while "
                                                  "another mode is shown")
    mode_windows_set: IntProperty(name="Mode Windows Set", default=0, options={"HIDDEN"},
                                  description="Which render modes have a kept window")
    window_mode: StringProperty(name="Window Mode", default="dvr", options={"HIDDEN"},
                                description="The render mode the current window belongs to")
    use_minip_floor: BoolProperty(name="MinIP Floor", default=True, update=tag_redraw,
                                  description="MinIP ignores values below the floor (the air "
                                              "around the scan, which would be every ray's "
                                              "minimum)")
    minip_floor: FloatProperty(name="Floor", default=0.0, update=tag_redraw,
                               description="MinIP shows the smallest value at or above this one "
                                           "(data units); fitted to the background's level the "
                                           "first time MinIP is picked")
    matcap: EnumProperty(name="MatCap", items=cutaway_props.matcap_items, update=tag_redraw,
                         description="Shade surfaces with one of Blender's MatCaps (a picture "
                                     "of a lit sphere, as in Solid mode) instead of the "
                                     "material and lights")
    clip_planes: CollectionProperty(type=cutaway_props.VoxlightClipPlane, name="Clip Planes",
                                    description="Planes that cut the volume (at most 6)")
    crop_box: PointerProperty(type=bpy.types.Object, name="Crop Box", update=tag_redraw,
                              description="A cube Empty: only the volume inside its cube "
                                          "(its Size, scaled by its transform) is kept")
    cutters: CollectionProperty(type=cutaway_props.VoxlightCutter, name="Cutters",
                                description="Closed meshes that cut the volume (at most 4)")
    caps: BoolProperty(name="Caps", default=True, update=tag_redraw,
                       description="Shade a cut face with the cut's own direction, so it "
                                   "looks like a clean cut surface instead of noisy tissue")
    # --- channels of a multi-channel volume (channel_props.py, set at import)
    channels: CollectionProperty(type=channel_props.VoxlightChannel, name="Channels",
                                 description="The volume's channels, channels[N] is channel N "
                                             "of the file")
    active_channel: IntProperty(name="Active Channel", default=0, options=set(),
                                description="The channel the Channels panel shows below its list")
    use_channels: BoolProperty(name="Draw Channels", default=True, update=tag_redraw,
                               description="Draw every channel in its colour in one pass; off: "
                                           "channel 0 alone with the transfer function above, "
                                           "as a one-channel file")
    channel_blend: EnumProperty(name="Blend", items=channel_props.BLEND_ITEMS, default="add",
                                update=tag_redraw,
                                description="How the channels combine where they overlap")


class VoxlightSceneProperties(bpy.types.PropertyGroup):
    viewport_enabled: BoolProperty(name="Show in Viewport", default=True, update=tag_redraw,
                                   description="Draw Voxlight volumes in the 3D viewports")
    viewport_resolution: FloatProperty(
        name="Viewport Resolution", default=1.0, min=0.05, max=1.0, subtype="FACTOR",
        description="Fraction of the viewport's pixels rendered once the view is still",
        update=tag_redraw)
    interactive_resolution: FloatProperty(
        name="Interactive Resolution", default=0.35, min=0.05, max=1.0, subtype="FACTOR",
        description="Most of the viewport's resolution used while the view moves; lowered "
                    "automatically to keep about 10 frames a second", update=tag_redraw)
    settle_time: FloatProperty(name="Refine After", default=0.3, min=0.0, max=5.0,
                               subtype="TIME_ABSOLUTE", unit="TIME_ABSOLUTE",
                               description="Seconds without view change before the "
                                           "full-resolution render")
    use_scene_lights: BoolProperty(name="Scene Lights", default=True,
                                   description="Light volumes with the scene's lights "
                                               "(off: headlight)", update=tag_redraw)
    use_world_light: BoolProperty(name="World Light", default=True,
                                  description="Light volumes with the World too: its colour or "
                                              "Environment Texture, strength and Mapping rotation, "
                                              "in place of the material's ambient term (with no "
                                              "lights it replaces the headlight)",
                                  update=tag_redraw)
    render_enabled: BoolProperty(name="Composite in Renders", default=True,
                                 description="Render volumes in F12/animation renders and "
                                             "composite them over the render")
    render_separate_layer: BoolProperty(
        name="Volume as Separate Layer", default=False,
        description="Leave the compositing nodes alone and give the volume as images to wire "
                    "yourself (Voxlight Color, Alpha, Depth). Off: the volume is laid into the "
                    "render before your own compositing nodes, so they affect it too")
    render_occlusion: BoolProperty(name="Mesh Occlusion", default=True,
                                   description="Rasterise the scene's meshes so rays stop at "
                                               "them in F12 renders")
    backend: EnumProperty(name="Backend", items=BACKEND_ITEMS, default="auto",
                          description="How the library reaches OpenGL; Auto picks the GPU when "
                                      "there is one (volumes loaded later use it)")
    storage: EnumProperty(name="Storage", default="auto", items=STORAGE_ITEMS,
                          description="How volumes are held on the GPU (volumes reload when "
                                      "this changes)")
    memory_budget_mib: IntProperty(name="Memory Budget (MiB)", default=2048, min=1,
                                   max=1 << 20,
                                   description="Memory a volume may use, CPU and GPU together: "
                                               "half for its own copy (a streamed volume's bricks), "
                                               "the rest for its renderer, all of it once a volume "
                                               "read whole is uploaded (volumes reload when this "
                                               "changes)")


_classes = cutaway_props.CLASSES + channel_props.CLASSES + (VoxlightVolumeProperties, VoxlightSceneProperties)


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
