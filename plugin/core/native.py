"""ctypes binding of libvoxlight (csrc/include/voxlight.h and voxlight_dev.h).

No `import bpy` here on purpose: the binding is tested with plain Python
(tests/python) and is the only place that knows the C ABI. Everything that
crosses the boundary is a numpy array or a plain Python value.

Conventions kept from the header:
  * matrices are passed in as 4x4 "math" matrices (m[row][col], the way
    numpy and mathutils index them) and transposed here into the
    column-major floats the library wants;
  * images are (height, width, ...) arrays with row 0 = bottom, the same
    order as Blender's Image.pixels;
  * volumes from numpy are indexed array[i, j, k] like NIfTI/nibabel, so
    the memory handed to the library is x-fastest (Fortran order).

The binding is split by job; this module gathers their names, so the rest
of the add-on and the tests say `native.X`:
  native_abi           constants, structs, errors, pointer and matrix conversions
  native_private_copy  private copies of the library, the DLLs it needs and its reader helpers
  native_library       finding, loading and checking the library (Library)
  native_volume        Volume, list_dicom_series
  native_tiles         tile_params, params_digest
  native_renderer      make_params, Renderer
  native_cutaway       cutaway, MatCap and slice structs from plain data
  native_overlays      overlay styles (params.overlays) from plain data
  native_channels      channel styles (params.channels) from plain data
"""

import sys
import types

from . import (native_abi, native_cutaway, native_library, native_private_copy, native_renderer,
               native_tiles, native_volume)
from .native_abi import (ABI_VERSION, BACKENDS, CHANNEL_BLENDS, CLASSIFY_MODES, MAX_CHANNELS, ENUM_FALLBACKS, FILTERS,  # noqa: F401
                         GRADIENT_OPACITY_MODES, MAX_LIGHTS, PRESETS, RENDER_PARAMS_RESERVED,
                         STORAGES, MAX_CLIP_PLANES, MAX_CUTTERS, MODES, INTERPOLATIONS, LABEL_MODES, LABEL_BOUNDARIES, MAX_LABEL_ID, BLENDS, STREAMING_MODES, MAX_OVERLAYS, PROGRESS_CALLBACK, OverlayStyle, ClipPlane,
                         Cutaway, Cutter, LabelEntry, LabelStyle, Matcap, Environment, SceneShadows, SliceParams, GridParams, GridInfo, DicomSeries, Light, LightShape, LibraryUnavailable, LoadOptions, PhantomDesc,
                         RendererInfo, RendererOptions, RenderParams, RenderStats, SHADING_MODELS,
                         VolumeDesc, VolumeInfo, VoxlightError, c_double4x4, c_float4x4, matrix_from_cm)
from .native_library import (LIBRARY_NAME, Library, candidate_paths, filter_names,  # noqa: F401
                             library_status, load_library)
from .native_private_copy import (CACHE_DIR, HELPER_PREFIX, OLD_VDB_HELPER_NAME,  # noqa: F401
                                  VDB_HELPER_NAME, cache_roots, clean_stale_copies, companion_names,
                                  helper_names, private_copy, restore_execute_bit)
from .native_cutaway import cutaway_struct, matcap_struct, slice_struct  # noqa: F401
from .native_overlays import overlay_array  # noqa: F401
from .native_channels import channel_array  # noqa: F401
from .native_renderer import Renderer, make_params  # noqa: F401
from .native_tiles import params_digest, tile_params  # noqa: F401
from .native_volume import Volume, list_dicom_series, load_label_table, voxel_box_corners  # noqa: F401

_PARTS = (native_abi, native_private_copy, native_library, native_volume, native_tiles,
          native_renderer, native_cutaway)


class _Binding(types.ModuleType):
    """This module's type: an assignment to native.X also rebinds X in the
    part that defines or imports it, where the code that reads X looks it
    up. The add-on sets native.CACHE_DIR, and tests monkeypatch
    native.cache_roots; both must reach native_private_copy."""

    def __setattr__(self, name, value):
        for part in _PARTS:
            if name in vars(part):
                setattr(part, name, value)
        super().__setattr__(name, value)


sys.modules[__name__].__class__ = _Binding
