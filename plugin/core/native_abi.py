"""The C ABI of libvoxlight (csrc/include/voxlight.h and voxlight_dev.h) as
ctypes: constants, the parameter and result structs, the error types, and
the pointer and matrix conversions every call uses. No library is loaded
here. tests/python/test_abi.py checks every struct's size and field offsets
against the C compiler's.

Part of the ctypes binding; plugin/core/native.py re-exports it."""

import ctypes

import numpy as np

ABI_VERSION = 1

# The names this binding was written against, in VXL_* order. The library is
# the authority: Library.names(kind) reads vxl_<kind>_name() up to the first
# NULL, so a value added to the library shows up in the add-on without
# editing this file; these tuples are only the fallback when no library can
# be loaded (the UI still registers). tests/python/test_abi.py keeps them
# equal to the library's.
FILTERS = ("central", "forward3", "sobel8", "sobel14", "sobel26", "precomputed", "cubic",
           "cubic-smooth")
PRESETS = ("auto", "gray", "bone", "hot", "mri", "ct")
BACKENDS = ("auto", "osmesa", "egl", "wgl")
STORAGES = ("auto", "dense", "bricked", "sparse", "compressed")  # VXL_STORAGE_*
CLASSIFY_MODES = ("post", "pre", "preint")  # VXL_CLASSIFY_*
GRADIENT_OPACITY_MODES = ("off", "boundary", "iso")  # VXL_GOPACITY_*
SHADING_MODELS = ("phong", "shadowed", "scatter", "path")  # VXL_SHADING_*
MODES = ("dvr", "mip", "minip", "average", "iso")  # VXL_MODE_*
INTERPOLATIONS = ("nearest", "linear", "cubic")  # VXL_INTERP_*
LABEL_MODES = ("surface", "mask", "tint")  # VXL_LABEL_MODE_*
LABEL_BOUNDARIES = ("smooth", "voxels")  # VXL_LABEL_BOUNDARY_* (no name functions: two values)
BLENDS = ("over", "add", "max")  # VXL_BLEND_*
STREAMING_MODES = ("auto", "off", "on")  # VXL_STREAMING_*
OPACITY_SOURCES = ("luminance", "channel", "alpha")  # VXL_OPACITY_SOURCE_*: a colour volume's scalar
COLOR_SOURCES = ("auto", "data", "tf")  # VXL_COLOR_SOURCE_*
COLOR_SPACES = ("display", "linear")  # VXL_COLOR_SPACE_*: what render params' colours mean
MAX_OVERLAYS = 3  # VXL_MAX_OVERLAYS
CHANNEL_BLENDS = ("add", "max")  # VXL_CHANNEL_BLEND_*
MAX_CHANNELS = 8  # VXL_MAX_CHANNELS
MAX_LABEL_ID = 65535  # VXL_MAX_LABEL_ID
NOTES_MAX = 512  # VXL_NOTES_MAX: vxl_volume_info.notes, its NUL included
CHANNEL_NAME_MAX = 64  # VXL_CHANNEL_NAME_MAX: vxl_volume_info.channel_names[c], its NUL included
# The enumerations with vxl_<kind>_name / vxl_<kind>_from_name, and their fallbacks.
ENUM_FALLBACKS = {"filter": FILTERS, "preset": PRESETS, "backend": BACKENDS, "storage": STORAGES,
                  "classify": CLASSIFY_MODES, "gradient_opacity": GRADIENT_OPACITY_MODES,
                  "gradient_store": ("8bit", "16f", "32f"), "shading_model": SHADING_MODELS,
                  "technique": ("raycast", "slices2d", "slices3d"), "mode": MODES,
                  "interpolation": INTERPOLATIONS, "label_mode": LABEL_MODES,
                  "blend": BLENDS, "streaming": STREAMING_MODES,
                  "opacity_source": OPACITY_SOURCES, "color_source": COLOR_SOURCES,
                  "channel_blend": CHANNEL_BLENDS}
MAX_LIGHTS = 8
RENDER_PARAMS_RESERVED = 2  # VXL_RENDER_PARAMS_RESERVED
MAX_CLIP_PLANES = 6  # VXL_MAX_CLIP_PLANES
MAX_CUTTERS = 4  # VXL_MAX_CUTTERS

_DTYPES = {
    np.dtype(np.uint8): 1, np.dtype(np.int8): 2,
    np.dtype(np.uint16): 3, np.dtype(np.int16): 4,
    np.dtype(np.uint32): 5, np.dtype(np.int32): 6,
    np.dtype(np.float32): 7, np.dtype(np.float64): 8,
}

c_float4x4 = ctypes.c_float * 16
c_double4x4 = ctypes.c_double * 16


# int (*progress)(void *user, double fraction, const char *stage): nonzero cancels
PROGRESS_CALLBACK = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_void_p, ctypes.c_double, ctypes.c_char_p)

# --------------------------------------------------------------- structs
# Field order and types copied from voxlight.h (vxl_phantom_desc from
# voxlight_dev.h); only fixed-width types.

class LoadOptions(ctypes.Structure):
    _fields_ = [("struct_size", ctypes.c_uint32),
                ("max_dim", ctypes.c_uint32),
                ("memory_budget_bytes", ctypes.c_uint64),
                ("voxel_size", ctypes.c_double * 3),
                ("frame", ctypes.c_uint32),      # 4D inputs: which volume
                ("reserved0", ctypes.c_uint32),
                ("series", ctypes.c_char_p),     # DICOM: index or SeriesInstanceUID
                # appended: streaming
                ("streaming", ctypes.c_uint32),
                ("reserved1", ctypes.c_uint32),
                ("cache_dir", ctypes.c_char_p),
                ("progress", PROGRESS_CALLBACK),
                ("progress_user", ctypes.c_void_p),
                ("opacity_source", ctypes.c_uint32),   # appended: a colour volume's scalar
                ("opacity_channel", ctypes.c_uint32),
                ("channels", ctypes.c_uint32),         # appended: multi-channel volumes (VXL_CHANNELS_*)
                ("scalar_channel", ctypes.c_uint32)]


class DicomSeries(ctypes.Structure):
    _fields_ = [("struct_size", ctypes.c_uint32),
                ("slice_count", ctypes.c_uint32),
                ("dims", ctypes.c_uint32 * 3),
                ("loadable", ctypes.c_uint32),
                ("frame_count", ctypes.c_uint32),
                ("gantry_tilt_deg", ctypes.c_double),
                ("uid", ctypes.c_char * 72),
                ("modality", ctypes.c_char * 20),
                ("description", ctypes.c_char * 72),
                ("problem", ctypes.c_char * 256)]


class VolumeDesc(ctypes.Structure):
    _fields_ = [("struct_size", ctypes.c_uint32),
                ("dtype", ctypes.c_uint32),
                ("dims", ctypes.c_uint32 * 3),
                ("has_affine", ctypes.c_uint32),
                ("data", ctypes.c_void_p),
                ("spacing", ctypes.c_double * 3),
                ("affine", c_double4x4),
                ("scl_slope", ctypes.c_double),
                ("scl_inter", ctypes.c_double),
                ("components", ctypes.c_uint32),       # appended: 3 RGB, 4 RGBA, interleaved
                ("reserved", ctypes.c_uint32),
                ("channels", ctypes.c_uint32),         # appended: 2..8 channels on the grid
                ("channels_interleaved", ctypes.c_uint32)]


class VolumeInfo(ctypes.Structure):
    _fields_ = [("struct_size", ctypes.c_uint32),
                ("dtype", ctypes.c_uint32),
                ("dims", ctypes.c_uint32 * 3),
                ("nifti_version", ctypes.c_uint32),
                ("spacing", ctypes.c_double * 3),
                ("affine", c_double4x4),
                ("value_min", ctypes.c_double),
                ("value_max", ctypes.c_double),
                ("nan_count", ctypes.c_uint64),
                ("inf_count", ctypes.c_uint64),
                ("storage_bytes", ctypes.c_uint64),
                ("texture_bits", ctypes.c_uint32),
                ("affine_source", ctypes.c_uint32),
                ("frame_count", ctypes.c_uint32),
                ("frame", ctypes.c_uint32),
                ("streamed", ctypes.c_uint32),        # appended
                ("level_count", ctypes.c_uint32),
                ("resident_bytes", ctypes.c_uint64),
                ("bytes_read", ctypes.c_uint64),
                ("notes", ctypes.c_char * NOTES_MAX),  # appended: what the reader decided
                ("components", ctypes.c_uint32),       # appended: 1 grey, 3 RGB, 4 RGBA
                ("opacity_source", ctypes.c_uint32),
                ("color_bytes", ctypes.c_uint64),
                ("channel_count", ctypes.c_uint32),    # appended: multi-channel volumes
                ("scalar_channel", ctypes.c_uint32),
                ("channel_min", ctypes.c_double * 8),
                ("channel_max", ctypes.c_double * 8),
                ("channel_bytes", ctypes.c_uint64),
                # appended: what the file says about its channels (OME metadata)
                ("channel_names", (ctypes.c_char * CHANNEL_NAME_MAX) * 8),
                ("channel_colors", (ctypes.c_float * 3) * 8),  # the file's sRGB, not decoded
                ("channel_color_known", ctypes.c_uint32 * 8),
                ("channel_window_low", ctypes.c_double * 8),
                ("channel_window_high", ctypes.c_double * 8),
                ("channel_window_known", ctypes.c_uint32 * 8),
                ("channel_active", ctypes.c_uint32 * 8)]


class PhantomDesc(ctypes.Structure):
    _fields_ = [("struct_size", ctypes.c_uint32),
                ("kind", ctypes.c_uint32),
                ("dims", ctypes.c_uint32 * 3),
                ("seed", ctypes.c_uint32),
                ("noise_sigma", ctypes.c_double)]


class RendererOptions(ctypes.Structure):
    _fields_ = [("struct_size", ctypes.c_uint32),
                ("backend", ctypes.c_uint32),
                ("memory_budget_bytes", ctypes.c_uint64),
                ("shader_dir", ctypes.c_char_p),
                ("storage", ctypes.c_uint32),
                ("page_brick", ctypes.c_uint32),
                ("compressed_domain", ctypes.c_uint32)]  # developer hook (voxlight_dev.h)


class RendererInfo(ctypes.Structure):
    _fields_ = [("struct_size", ctypes.c_uint32),
                ("backend", ctypes.c_uint32),
                ("max_3d_texture_size", ctypes.c_int32),
                ("reserved", ctypes.c_uint32),
                ("backend_name", ctypes.c_char * 32),
                ("gl_renderer", ctypes.c_char * 128),
                ("gl_version", ctypes.c_char * 128)]


class Light(ctypes.Structure):
    _fields_ = [("position", ctypes.c_float * 4),
                ("color", ctypes.c_float * 3),
                ("intensity", ctypes.c_float)]


class LightShape(ctypes.Structure):
    _fields_ = [("struct_size", ctypes.c_uint32),
                ("spot_direction", ctypes.c_float * 3),
                ("spot_angle", ctypes.c_float),
                ("spot_blend", ctypes.c_float),
                ("size", ctypes.c_float)]


class LabelEntry(ctypes.Structure):
    _fields_ = [("struct_size", ctypes.c_uint32),
                ("id", ctypes.c_int32),
                ("color", ctypes.c_float * 4),
                ("visible", ctypes.c_uint32),
                ("name", ctypes.c_char * 64),
                ("has_material", ctypes.c_uint32),  # appended: the label's own material
                ("material", ctypes.c_float * 4)]


class LabelStyle(ctypes.Structure):
    _fields_ = [("struct_size", ctypes.c_uint32),
                ("mode", ctypes.c_uint32),
                ("entry_count", ctypes.c_uint32),
                ("reserved", ctypes.c_uint32),
                ("entries", ctypes.POINTER(LabelEntry)),
                ("boundary", ctypes.c_uint32),   # appended: VXL_LABEL_BOUNDARY_* (0 smooth, 1 voxels)
                ("reserved2", ctypes.c_uint32)]


class ClipPlane(ctypes.Structure):
    _fields_ = [("plane", ctypes.c_float * 4),
                ("thickness", ctypes.c_float),
                ("reserved", ctypes.c_uint32)]


class Cutter(ctypes.Structure):
    _fields_ = [("struct_size", ctypes.c_uint32),
                ("remove_outside", ctypes.c_uint32),
                ("vertices", ctypes.POINTER(ctypes.c_float)),
                ("indices", ctypes.POINTER(ctypes.c_uint32)),
                ("vertex_count", ctypes.c_uint32),
                ("triangle_count", ctypes.c_uint32)]


class Cutaway(ctypes.Structure):
    _fields_ = [("struct_size", ctypes.c_uint32),
                ("clip_plane_count", ctypes.c_uint32),
                ("clip_planes", ClipPlane * MAX_CLIP_PLANES),
                ("has_crop", ctypes.c_uint32),
                ("crop_box", c_float4x4),
                ("cutter_count", ctypes.c_uint32),
                ("cutters", ctypes.POINTER(Cutter)),
                ("caps_off", ctypes.c_uint32),
                ("reserved", ctypes.c_uint32)]


class Matcap(ctypes.Structure):
    _fields_ = [("struct_size", ctypes.c_uint32),
                ("width", ctypes.c_uint32),
                ("height", ctypes.c_uint32),
                ("reserved", ctypes.c_uint32),
                ("rgba", ctypes.POINTER(ctypes.c_float)),
                ("key", ctypes.c_uint64)]


class Environment(ctypes.Structure):
    """vxl_environment: the World's light (a lat-long map, strength, Z rotation)."""
    _fields_ = [("struct_size", ctypes.c_uint32),
                ("width", ctypes.c_uint32),
                ("height", ctypes.c_uint32),
                ("reserved", ctypes.c_uint32),
                ("rgb", ctypes.POINTER(ctypes.c_float)),
                ("strength", ctypes.c_float),
                ("rotation_deg", ctypes.c_float),
                ("key", ctypes.c_uint64)]


class SceneShadows(ctypes.Structure):
    _fields_ = [("struct_size", ctypes.c_uint32),
                ("occluder_vertex_count", ctypes.c_uint32),
                ("occluder_vertices", ctypes.POINTER(ctypes.c_float)),
                ("occluder_indices", ctypes.POINTER(ctypes.c_uint32)),
                ("occluder_triangle_count", ctypes.c_uint32),
                ("shadow_map_size", ctypes.c_uint32),
                ("occluder_key", ctypes.c_uint64)]


class SliceParams(ctypes.Structure):
    _fields_ = [("struct_size", ctypes.c_uint32),
                ("interpolation", ctypes.c_uint32),
                ("plane_to_world", c_float4x4)]


class GridParams(ctypes.Structure):
    _fields_ = [("struct_size", ctypes.c_uint32),
                ("dims", ctypes.c_uint32 * 3)]


class GridInfo(ctypes.Structure):
    _fields_ = [("struct_size", ctypes.c_uint32),
                ("dims", ctypes.c_uint32 * 3),
                ("index_to_world", c_double4x4),
                ("voxel_length", ctypes.c_double),
                ("max_density", ctypes.c_double)]


class OverlayStyle(ctypes.Structure):
    _fields_ = [("struct_size", ctypes.c_uint32),
                ("slot", ctypes.c_uint32),
                ("blend", ctypes.c_uint32),
                ("interpolation", ctypes.c_uint32),
                ("interpolation_set", ctypes.c_uint32),
                ("preset", ctypes.c_uint32),
                ("tf_size", ctypes.c_uint32),
                ("has_window", ctypes.c_uint32),
                ("tf_rgba", ctypes.POINTER(ctypes.c_float)),
                ("window_low", ctypes.c_float),
                ("window_high", ctypes.c_float),
                ("opacity_scale", ctypes.c_float),
                ("shading_off", ctypes.c_uint32),
                ("has_model", ctypes.c_uint32),
                ("model", c_float4x4),
                ("reserved", ctypes.c_uint32)]


class ChannelStyle(ctypes.Structure):
    _fields_ = [("struct_size", ctypes.c_uint32),
                ("channel", ctypes.c_uint32),
                ("hidden", ctypes.c_uint32),
                ("solo", ctypes.c_uint32),
                ("has_color", ctypes.c_uint32),
                ("color", ctypes.c_float * 3),
                ("has_window", ctypes.c_uint32),
                ("window_low", ctypes.c_float),
                ("window_high", ctypes.c_float),
                ("preset", ctypes.c_uint32),
                ("tf_size", ctypes.c_uint32),
                ("tf_rgba", ctypes.POINTER(ctypes.c_float)),
                ("opacity_scale", ctypes.c_float),
                ("reserved", ctypes.c_uint32)]


class RenderParams(ctypes.Structure):
    _fields_ = [("struct_size", ctypes.c_uint32),
                ("width", ctypes.c_uint32),
                ("height", ctypes.c_uint32),
                ("has_camera", ctypes.c_uint32),
                ("view", c_float4x4),
                ("proj", c_float4x4),
                ("azimuth_deg", ctypes.c_float),
                ("elevation_deg", ctypes.c_float),
                ("has_model", ctypes.c_uint32),
                ("model", c_float4x4),
                ("scene_depth", ctypes.POINTER(ctypes.c_float)),
                ("filter", ctypes.c_uint32),
                ("sample_distance", ctypes.c_float),
                ("reuse_gradients", ctypes.c_uint32),
                ("gradient_store", ctypes.c_uint32),
                ("step", ctypes.c_float),
                ("jitter_off", ctypes.c_uint32),
                ("jitter_seed", ctypes.c_uint32),
                ("preset", ctypes.c_uint32),
                ("tf_size", ctypes.c_uint32),
                ("tf_rgba", ctypes.POINTER(ctypes.c_float)),
                ("has_window", ctypes.c_uint32),
                ("window_low", ctypes.c_float),
                ("window_high", ctypes.c_float),
                ("opacity_scale", ctypes.c_float),
                ("classify", ctypes.c_uint32),
                ("shading_off", ctypes.c_uint32),
                ("has_material", ctypes.c_uint32),
                ("ambient", ctypes.c_float),
                ("diffuse", ctypes.c_float),
                ("specular", ctypes.c_float),
                ("shininess", ctypes.c_float),
                ("light_count", ctypes.c_uint32),
                ("lights", Light * MAX_LIGHTS),
                ("early_termination", ctypes.c_float),
                ("depth_threshold", ctypes.c_float),
                ("no_skip", ctypes.c_uint32),
                ("preint_size", ctypes.c_uint32),
                ("gradient_opacity", ctypes.c_uint32),
                ("gradient_ref", ctypes.c_float),
                ("gradient_exp", ctypes.c_float),
                ("iso_value", ctypes.c_float),
                ("iso_thickness", ctypes.c_float),
                ("shading_model", ctypes.c_uint32),
                ("light_shapes", ctypes.POINTER(LightShape)),
                ("ambient_occlusion", ctypes.c_float),
                ("occlusion_strength", ctypes.c_float),
                ("anisotropy", ctypes.c_float),
                ("illumination_size", ctypes.c_uint32),
                ("technique", ctypes.c_uint32),
                ("mode", ctypes.c_uint32),
                ("cutaway", ctypes.POINTER(Cutaway)),
                ("scene_shadows", ctypes.POINTER(SceneShadows)),
                ("matcap", ctypes.POINTER(Matcap)),
                ("reserved", ctypes.c_uint32 * RENDER_PARAMS_RESERVED),  # must stay 0
                ("labels", ctypes.POINTER(LabelStyle)),  # appended
                ("overlay_count", ctypes.c_uint32),      # appended
                ("progressive", ctypes.c_uint32),        # appended
                ("overlays", ctypes.POINTER(OverlayStyle)),
                ("minip_floor_on", ctypes.c_uint32),     # appended: MinIP's floor
                ("minip_floor", ctypes.c_float),
                ("color_source", ctypes.c_uint32),       # appended: colour volumes
                ("color_space", ctypes.c_uint32),        # VXL_COLOR_SPACE_* (COLOR_SPACES)
                ("environment", ctypes.POINTER(Environment)),  # appended: the World's light
                ("path_samples", ctypes.c_uint32),       # appended: the path shading model
                ("path_sample_offset", ctypes.c_uint32),
                ("path_bounces", ctypes.c_uint32),
                ("path_seed", ctypes.c_uint32),
                ("channel_count", ctypes.c_uint32),      # appended: multi-channel volumes
                ("channel_blend", ctypes.c_uint32),
                ("channels", ctypes.POINTER(ChannelStyle))]


class RenderStats(ctypes.Structure):
    _fields_ = [("struct_size", ctypes.c_uint32),
                ("sample_bound", ctypes.c_uint32),
                ("samples", ctypes.c_uint64),
                ("max_ray_samples", ctypes.c_uint32),
                ("rays", ctypes.c_uint32),
                ("effective_step", ctypes.c_float),
                ("bricks_total", ctypes.c_uint32),
                ("bricks_occupied", ctypes.c_uint32),
                ("brick_size", ctypes.c_uint32),
                ("storage", ctypes.c_uint32),
                ("resident_bytes", ctypes.c_uint64),
                ("page_brick", ctypes.c_uint32),
                ("pages_total", ctypes.c_uint32),
                ("pages_resident", ctypes.c_uint32),
                ("pages_constant", ctypes.c_uint32),
                ("lod_level", ctypes.c_uint32),
                ("lod_wanted_bytes", ctypes.c_uint64),
                ("decode_ms", ctypes.c_double),
                ("illumination_size", ctypes.c_uint32),
                ("illumination_rebuilt", ctypes.c_uint32),
                ("refine_pending", ctypes.c_uint32),     # appended
                ("stream_level", ctypes.c_uint32),
                ("bytes_read", ctypes.c_uint64),
                ("load_ms", ctypes.c_double),
                ("channel_bytes", ctypes.c_uint64)]       # appended: multi-channel volumes' GL memory


def _sized(struct_type):
    s = struct_type()
    s.struct_size = ctypes.sizeof(struct_type)
    return s


# ---------------------------------------------------------------- errors

class VoxlightError(RuntimeError):
    """A library call failed; .code is the VXL_ERR_* value, str() the message."""

    def __init__(self, message, code=0, name=""):
        super().__init__(message)
        self.code = code
        self.name = name


class LibraryUnavailable(VoxlightError):
    """libvoxlight.so is missing, fails to load or has another ABI."""


class LibraryObject:
    """Base of the objects that hold a library handle (Volume, Renderer):
    close() frees it, and so do garbage collection and the end of a with
    block."""

    def close(self):
        raise NotImplementedError

    def __del__(self):
        try:
            self.close()
        except Exception:
            pass

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


# --------------------------------------------------------------- helpers

def _fptr(arr):
    return arr.ctypes.data_as(ctypes.POINTER(ctypes.c_float))


def style_table(dst, tf, what):
    """dst.tf_size and dst.tf_rgba (an overlay's or a channel's style) from
    an (n, 4) straight-RGBA table; returns the float32 copy they point at
    (the caller keeps it as long as dst), None for no table."""
    if tf is None:
        return None
    tf = np.ascontiguousarray(tf, dtype=np.float32).reshape(-1, 4)
    if len(tf) < 2:
        raise ValueError("%s's tf_rgba needs at least 2 entries" % what)
    dst.tf_size = len(tf)
    dst.tf_rgba = _fptr(tf)
    return tf


def style_digest(dst):
    """A style struct's bytes for params_digest, its table pointer left
    out (it differs per build; the table itself is hashed)."""
    plain = type(dst).from_buffer_copy(dst)
    plain.tf_rgba = None
    return np.frombuffer(bytes(plain), np.uint8)


def _matrix_cm(m, ctype=ctypes.c_float):
    """4x4 math matrix (m[row][col]) -> 16 column-major values."""
    a = np.asarray(m, dtype=np.float64).reshape(4, 4)
    return (ctype * 16)(*a.T.ravel().tolist())


def matrix_from_cm(values):
    """16 column-major values -> numpy 4x4 math matrix."""
    return np.array(list(values), dtype=np.float64).reshape(4, 4).T
