"""Finding, loading and checking libvoxlight: the Library object every other
part of the binding calls through, with the argument types of each entry
point and the names of the library's enumerations.

Part of the ctypes binding; plugin/core/native.py re-exports it."""

import ctypes
import os

import numpy as np

from .native_abi import (ABI_VERSION, ENUM_FALLBACKS, FILTERS, DicomSeries, LabelEntry,
                         LibraryUnavailable, LoadOptions, PhantomDesc, RendererInfo, RendererOptions, RenderParams,
                         RenderStats, SliceParams, GridInfo, GridParams, VolumeDesc, VolumeInfo, VoxlightError, _fptr)
from . import platform_rules
from .native_private_copy import helper_names, private_copy, restore_execute_bit

LIBRARY_NAME = platform_rules.current().library  # libvoxlight.so, voxlight.dll


def candidate_paths(explicit=None):
    """Where the library is looked for, in order. The add-on ships the .so
    in its top folder, the parent of this core/ folder; the source-tree
    fallback (../build from there) serves developers running from a
    checkout."""
    here = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    paths = []
    if explicit:
        paths.append(explicit)
    env = os.environ.get("VOXLIGHT_LIB")
    if env:
        paths.append(env)
    paths.append(os.path.join(here, LIBRARY_NAME))
    paths.append(os.path.join(os.path.dirname(here), "build", LIBRARY_NAME))
    return paths


def _declare(lib):
    """Argument and result types for every entry point we call; without them
    ctypes would truncate pointers to int."""
    P = ctypes.POINTER
    vp = ctypes.c_void_p
    sig = {
        "vxl_abi_version": (ctypes.c_uint32, []),
        "vxl_last_error": (ctypes.c_char_p, []),
        "vxl_error_name": (ctypes.c_char_p, [ctypes.c_int]),
        "vxl_dtype_name": (ctypes.c_char_p, [ctypes.c_uint32]),
        "vxl_volume_load": (ctypes.c_int, [ctypes.c_char_p, P(LoadOptions), P(vp)]),
        "vxl_volume_create": (ctypes.c_int, [P(VolumeDesc), P(LoadOptions), P(vp)]),
        "vxl_volume_get_info": (ctypes.c_int, [vp, P(VolumeInfo)]),
        "vxl_volume_histogram": (ctypes.c_int, [vp, ctypes.c_uint32, ctypes.c_double,
                                                ctypes.c_double, P(ctypes.c_uint64)]),
        "vxl_volume_channel_histogram": (ctypes.c_int, [vp, ctypes.c_uint32, ctypes.c_uint32,
                                                        ctypes.c_double, ctypes.c_double,
                                                        P(ctypes.c_uint64)]),
        "vxl_volume_destroy": (None, [vp]),
        "vxl_dicom_list_series": (ctypes.c_int, [ctypes.c_char_p, P(DicomSeries), ctypes.c_uint32,
                                                 P(ctypes.c_uint32)]),
        "vxl_label_table_load": (ctypes.c_int, [ctypes.c_char_p, P(LabelEntry), ctypes.c_uint32,
                                                P(ctypes.c_uint32)]),
        "vxl_phantom_name": (ctypes.c_char_p, [ctypes.c_uint32]),
        "vxl_phantom_create": (ctypes.c_int, [P(PhantomDesc), P(vp)]),
        "vxl_renderer_create": (ctypes.c_int, [P(RendererOptions), P(vp)]),
        "vxl_renderer_destroy": (None, [vp]),
        "vxl_renderer_error": (ctypes.c_char_p, [vp]),
        "vxl_renderer_get_info": (ctypes.c_int, [vp, P(RendererInfo)]),
        "vxl_renderer_set_volume": (ctypes.c_int, [vp, vp]),
        "vxl_renderer_set_labels": (ctypes.c_int, [vp, vp]),
        "vxl_renderer_set_overlay": (ctypes.c_int, [vp, ctypes.c_uint32, vp]),
        "vxl_renderer_label_uploads": (ctypes.c_int, [vp, P(ctypes.c_uint64), P(ctypes.c_uint64)]),
        "vxl_render": (ctypes.c_int, [vp, P(RenderParams), P(ctypes.c_float),
                                      P(ctypes.c_float)]),
        "vxl_renderer_get_stats": (ctypes.c_int, [vp, P(RenderStats)]),
        "vxl_scene_transmittance": (ctypes.c_int, [vp, P(RenderParams), ctypes.c_uint32,
                                                   P(ctypes.c_float)]),
        "vxl_default_camera": (ctypes.c_int, [vp, P(RenderParams), P(ctypes.c_float),
                                              P(ctypes.c_float)]),
        "vxl_probe_gradients": (ctypes.c_int, [vp, P(RenderParams), P(ctypes.c_float),
                                               ctypes.c_uint32, P(ctypes.c_float)]),
        "vxl_render_slice": (ctypes.c_int, [vp, P(RenderParams), P(SliceParams), P(ctypes.c_float)]),
        "vxl_classified_grid": (ctypes.c_int, [vp, P(RenderParams), P(GridParams), P(GridInfo),
                                               P(ctypes.c_float), P(ctypes.c_float)]),
        "vxl_write_image": (ctypes.c_int, [ctypes.c_char_p, P(ctypes.c_float),
                                           P(ctypes.c_float), ctypes.c_uint32,
                                           ctypes.c_uint32]),
    }
    for kind in ENUM_FALLBACKS:
        sig["vxl_%s_name" % kind] = (ctypes.c_char_p, [ctypes.c_uint32])
        sig["vxl_%s_from_name" % kind] = (ctypes.c_int, [ctypes.c_char_p, P(ctypes.c_uint32)])
    for name, (res, args) in sig.items():
        fn = getattr(lib, name)  # AttributeError -> reported as incompatible
        fn.restype = res
        fn.argtypes = args


class Library:
    """A loaded, ABI-checked libvoxlight. .path is the file mapped into the
    process; .source_path the one it was copied from (the same when loaded
    in place)."""

    def __init__(self, path, source_path=None):
        self.path = path
        self.source_path = source_path or path
        # Plain dlopen (RTLD_LOCAL). RTLD_DEEPBIND would crash Blender
        # (jemalloc), and the library fetches GL through get-proc-address,
        # so Blender's global libGL cannot capture its GL calls.
        try:
            self.cdll = ctypes.CDLL(path)
        except OSError as e:
            raise LibraryUnavailable("cannot load %s: %s" % (path, e)) from None
        try:
            self.cdll.vxl_abi_version.restype = ctypes.c_uint32
            self.cdll.vxl_abi_version.argtypes = []
            version = self.cdll.vxl_abi_version()
        except AttributeError:
            raise LibraryUnavailable("%s is not libvoxlight (no vxl_abi_version)" % path) from None
        if version != ABI_VERSION:
            raise LibraryUnavailable(
                "%s has ABI version %d, this add-on needs %d; install matching "
                "versions of the add-on and the library" % (path, version, ABI_VERSION))
        try:
            _declare(self.cdll)
        except AttributeError as e:
            raise LibraryUnavailable("%s lacks an entry point: %s" % (path, e)) from None
        self.abi_version = version

    # error helpers --------------------------------------------------
    def last_error(self):
        msg = self.cdll.vxl_last_error()
        return msg.decode("utf-8", "replace") if msg else ""

    def error_name(self, code):
        n = self.cdll.vxl_error_name(code)
        return n.decode() if n else "VXL_ERR_%d" % code

    def check(self, code, renderer_handle=None, what=""):
        """Raise VoxlightError carrying the library's own message."""
        if code == 0:
            return
        msg = ""
        if renderer_handle:
            m = self.cdll.vxl_renderer_error(renderer_handle)
            msg = m.decode("utf-8", "replace") if m else ""
        if not msg:
            msg = self.last_error()
        name = self.error_name(code)
        text = msg or name
        if what:
            text = "%s: %s" % (what, text)
        raise VoxlightError(text, code, name)

    # names of the enumerations (vxl_<kind>_name / vxl_<kind>_from_name;
    # kind is a key of ENUM_FALLBACKS, or "dtype" for name()) -------------
    def name(self, kind, value):
        """The library's name of `value` of enumeration `kind`, None when it
        has none."""
        n = getattr(self.cdll, "vxl_%s_name" % kind)(value)
        return n.decode() if n else None

    def names(self, kind):
        """Every name of enumeration `kind`, in VXL_* order (the library
        returns NULL past its last value)."""
        out = []
        for i in range(256):
            n = self.name(kind, i)
            if n is None:
                break
            out.append(n)
        return tuple(out)

    def index(self, kind, name):
        """The VXL_* value of `name` in enumeration `kind`; VoxlightError
        naming it when the library has no such name."""
        out = ctypes.c_uint32()
        self.check(getattr(self.cdll, "vxl_%s_from_name" % kind)(name.encode(), ctypes.byref(out)))
        return out.value

    def filter_index(self, name):
        return self.index("filter", name)

    def filter_names(self):
        """Every gradient filter the library has, in VXL_FILTER_* order."""
        return self.names("filter")

    def preset_names(self):
        return self.names("preset")

    def preset_index(self, name):
        return self.index("preset", name)

    def write_image(self, path, rgba, depth=None):
        rgba = np.ascontiguousarray(rgba, dtype=np.float32)
        h, w = rgba.shape[:2]
        if rgba.shape != (h, w, 4):
            raise ValueError("rgba must be (height, width, 4)")
        dptr = None
        if depth is not None:
            depth = np.ascontiguousarray(depth, dtype=np.float32).reshape(h, w)
            dptr = _fptr(depth)
        self.check(self.cdll.vxl_write_image(os.fsencode(path), _fptr(rgba), dptr, w, h),
                   what="write %s" % path)


_library = None
_library_error = None


def load_library(path=None, reload=False):
    """Return the Library, loading it on first use. Raises LibraryUnavailable
    with a message that names every place that was tried. The file that is
    mapped is a private copy (private_copy), so installing a new add-on over
    this one never writes over a mapped library."""
    global _library, _library_error
    if _library is not None and not reload and path is None:
        return _library
    errors = []
    for p in candidate_paths(path):
        if not os.path.isfile(p):
            errors.append("%s: not found" % p)
            continue
        for helper in helper_names(os.path.dirname(p)):
            restore_execute_bit(os.path.join(os.path.dirname(p), helper))
        copy = private_copy(p)
        try:
            try:
                lib = Library(copy or p, source_path=p)
            except LibraryUnavailable as e:
                # A cache on a noexec mount cannot be mapped: load in place.
                if not copy or not e.args[0].startswith("cannot load"):
                    raise
                copy = None
                lib = Library(p)
        except LibraryUnavailable as e:
            errors.append(str(e).replace(copy, p) if copy else str(e))
            # An explicitly named library that is broken is an error by itself;
            # falling back would hide it.
            if p == path:
                break
            continue
        _library, _library_error = lib, None
        return lib
    _library_error = "libvoxlight not usable: " + "; ".join(errors)
    raise LibraryUnavailable(_library_error)


def filter_names(lib=None):
    """The library's filter names (VXL_FILTER_* order), or FILTERS when no
    library loads."""
    try:
        return (lib or load_library()).filter_names()
    except LibraryUnavailable:
        return FILTERS


def library_status():
    """(ok, message) without raising, for UI code."""
    try:
        lib = load_library()
    except LibraryUnavailable as e:
        return False, str(e)
    return True, "libvoxlight ABI %d at %s" % (lib.abi_version, lib.source_path)
