"""ctypes binding of libvoxlight (csrc/include/voxlight.h).

No `import bpy` here on purpose: this module is tested with plain Python
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
"""

import ctypes
import errno
import fcntl
import hashlib
import os
import shutil
import tempfile
import time

import numpy as np

ABI_VERSION = 1
LIBRARY_NAME = "libvoxlight.so"
# The reader processes the library starts, found next to the library itself
# (csrc/reader_spawn.c, csrc/reader_stream.h): voxlight-read-oiio (TIFF/PNG
# stacks and OpenVDB) and voxlight-read-dicom; every voxlight-read-* file is
# shipped and copied with the library.
HELPER_PREFIX = "voxlight-read-"
VDB_HELPER_NAME = "voxlight-read-oiio"  # the one that reads .vdb files
OLD_VDB_HELPER_NAME = "voxlight-vdb-read"  # its name in older builds

# The names this binding was written against (VXL_FILTER_* / VXL_PRESET_*
# order). The library is the authority: Library.filter_names() reads
# vxl_filter_name() up to the first NULL, so a filter added to the library
# shows up in the add-on without editing this file; these tuples are only
# the fallback when no library can be loaded (the UI still registers).
FILTERS = ("central", "forward3", "sobel8", "sobel14", "sobel26", "precomputed", "cubic",
           "cubic-smooth")
PRESETS = ("auto", "gray", "bone", "hot", "mri", "ct")
BACKENDS = ("auto", "osmesa", "egl")
STORAGES = ("auto", "dense", "bricked", "sparse", "compressed")  # VXL_STORAGE_*
MAX_LIGHTS = 8
# VXL_CLASSIFY_* and VXL_GOPACITY_* order.
CLASSIFY_MODES = ("post", "pre", "preint")
GRADIENT_OPACITY_MODES = ("off", "boundary", "iso")

_DTYPES = {
    np.dtype(np.uint8): 1, np.dtype(np.int8): 2,
    np.dtype(np.uint16): 3, np.dtype(np.int16): 4,
    np.dtype(np.uint32): 5, np.dtype(np.int32): 6,
    np.dtype(np.float32): 7, np.dtype(np.float64): 8,
}
DTYPE_NAMES = {1: "uint8", 2: "int8", 3: "uint16", 4: "int16",
               5: "uint32", 6: "int32", 7: "float32", 8: "float64"}

c_float4x4 = ctypes.c_float * 16
c_double4x4 = ctypes.c_double * 16


# --------------------------------------------------------------- structs
# Field order and types copied from voxlight.h; only fixed-width types.

class LoadOptions(ctypes.Structure):
    _fields_ = [("struct_size", ctypes.c_uint32),
                ("max_dim", ctypes.c_uint32),
                ("memory_budget_bytes", ctypes.c_uint64),
                ("voxel_size", ctypes.c_double * 3),
                ("frame", ctypes.c_uint32),      # 4D inputs: which volume
                ("reserved0", ctypes.c_uint32),
                ("series", ctypes.c_char_p)]     # DICOM: index or SeriesInstanceUID


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
                ("scl_inter", ctypes.c_double)]


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
                ("frame", ctypes.c_uint32)]


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
                ("page_brick", ctypes.c_uint32)]


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
                ("reserved", ctypes.c_uint32 * 1)]


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
                ("decode_ms", ctypes.c_double)]


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


# --------------------------------------------------------------- loading

def candidate_paths(explicit=None):
    """Where the library is looked for, in order. The add-on ships the .so
    next to this file; the source-tree fallback (../build) serves developers
    running from a checkout."""
    here = os.path.dirname(os.path.abspath(__file__))
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
        "vxl_filter_name": (ctypes.c_char_p, [ctypes.c_uint32]),
        "vxl_filter_from_name": (ctypes.c_int, [ctypes.c_char_p, P(ctypes.c_uint32)]),
        "vxl_preset_name": (ctypes.c_char_p, [ctypes.c_uint32]),
        "vxl_preset_from_name": (ctypes.c_int, [ctypes.c_char_p, P(ctypes.c_uint32)]),
        "vxl_volume_load": (ctypes.c_int, [ctypes.c_char_p, P(LoadOptions), P(vp)]),
        "vxl_volume_create": (ctypes.c_int, [P(VolumeDesc), P(LoadOptions), P(vp)]),
        "vxl_volume_get_info": (ctypes.c_int, [vp, P(VolumeInfo)]),
        "vxl_volume_histogram": (ctypes.c_int, [vp, ctypes.c_uint32, ctypes.c_double,
                                                ctypes.c_double, P(ctypes.c_uint64)]),
        "vxl_volume_destroy": (None, [vp]),
        "vxl_dicom_list_series": (ctypes.c_int, [ctypes.c_char_p, P(DicomSeries), ctypes.c_uint32,
                                                 P(ctypes.c_uint32)]),
        "vxl_phantom_name": (ctypes.c_char_p, [ctypes.c_uint32]),
        "vxl_phantom_create": (ctypes.c_int, [P(PhantomDesc), P(vp)]),
        "vxl_renderer_create": (ctypes.c_int, [P(RendererOptions), P(vp)]),
        "vxl_renderer_destroy": (None, [vp]),
        "vxl_renderer_error": (ctypes.c_char_p, [vp]),
        "vxl_renderer_get_info": (ctypes.c_int, [vp, P(RendererInfo)]),
        "vxl_renderer_set_volume": (ctypes.c_int, [vp, vp]),
        "vxl_render": (ctypes.c_int, [vp, P(RenderParams), P(ctypes.c_float),
                                      P(ctypes.c_float)]),
        "vxl_renderer_get_stats": (ctypes.c_int, [vp, P(RenderStats)]),
        "vxl_default_camera": (ctypes.c_int, [vp, P(RenderParams), P(ctypes.c_float),
                                              P(ctypes.c_float)]),
        "vxl_probe_gradients": (ctypes.c_int, [vp, P(RenderParams), P(ctypes.c_float),
                                               ctypes.c_uint32, P(ctypes.c_float)]),
        "vxl_write_image": (ctypes.c_int, [ctypes.c_char_p, P(ctypes.c_float),
                                           P(ctypes.c_float), ctypes.c_uint32,
                                           ctypes.c_uint32]),
    }
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

    def filter_index(self, name):
        out = ctypes.c_uint32()
        self.check(self.cdll.vxl_filter_from_name(name.encode(), ctypes.byref(out)))
        return out.value

    def _names(self, fn):
        out = []
        for i in range(256):  # the library returns NULL past its last entry
            n = fn(i)
            if not n:
                break
            out.append(n.decode())
        return tuple(out)

    def filter_names(self):
        """Every gradient filter the library has, in VXL_FILTER_* order."""
        return self._names(self.cdll.vxl_filter_name)

    def preset_names(self):
        return self._names(self.cdll.vxl_preset_name)

    def preset_index(self, name):
        out = ctypes.c_uint32()
        self.check(self.cdll.vxl_preset_from_name(name.encode(), ctypes.byref(out)))
        return out.value

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


# ------------------------------------------------- private library copies
#
# Installing an add-on over itself writes the new files where the old ones
# are; if libvoxlight.so were mapped from there, the running Blender would
# crash at its next call into it. So the library is loaded from a copy in a
# cache folder named by the content's hash, together with the reader helpers
# it starts from its own folder (found with dladdr, csrc/reader_spawn.c). An
# updated add-on has another hash, hence a new folder and a fresh dlopen
# (dlopen of the old path would hand back the old, already loaded library).
# Each process holds a shared flock on the folder it uses; a folder nobody
# holds is stale and removed by the next load.

_LOCK_NAME = ".in-use"
_held_locks = {}  # folder -> open lock file, kept for the life of the process


def helper_names(folder):
    """The helper executables shipped next to the library in folder."""
    try:
        names = os.listdir(folder)
    except OSError:
        return []
    return sorted(n for n in names
                  if (n.startswith(HELPER_PREFIX) or n == OLD_VDB_HELPER_NAME)
                  and os.path.isfile(os.path.join(folder, n)))


# Set by the add-on when Blender gives it a folder of its own (an
# extension's user folder, 4.2+; compat.private_data_dir).
CACHE_DIR = None


def cache_roots():
    """Where private copies may go, best first: VOXLIGHT_CACHE_DIR, the
    add-on's own folder (CACHE_DIR), the XDG cache folder, then the
    temporary folder."""
    roots = []
    for d in (os.environ.get("VOXLIGHT_CACHE_DIR"), CACHE_DIR):
        if d:
            roots.append(d)
    xdg = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    roots.append(os.path.join(xdg, "voxlight", "lib"))
    roots.append(os.path.join(tempfile.gettempdir(), "voxlight-%d" % os.getuid(), "lib"))
    return roots


def _content_key(files):
    h = hashlib.sha256()
    for f in files:
        h.update(os.path.basename(f).encode() + b"\0")
        with open(f, "rb") as fh:
            for block in iter(lambda: fh.read(1 << 20), b""):
                h.update(block)
        h.update(b"\0")
    return h.hexdigest()[:24]


def _hold(folder):
    """Take a shared lock on folder's lock file; False when the folder went
    away meanwhile (a cleaner removed it)."""
    if folder in _held_locks:
        return True
    lock = os.path.join(folder, _LOCK_NAME)
    try:
        fd = os.open(lock, os.O_RDONLY)
    except OSError:
        return False
    try:
        fcntl.flock(fd, fcntl.LOCK_SH)
        st, held = os.stat(lock), os.fstat(fd)
        if (st.st_dev, st.st_ino) != (held.st_dev, held.st_ino):
            raise OSError(errno.ESTALE, "%s was replaced" % lock)
    except OSError:
        os.close(fd)
        return False
    _held_locks[folder] = fd
    return True


def _complete(folder, files):
    return all(os.path.isfile(os.path.join(folder, os.path.basename(f))) and
               os.path.getsize(os.path.join(folder, os.path.basename(f))) == os.path.getsize(f)
               for f in files)


def _make_copy(root, key, files):
    """root/key holding a copy of files (made atomically by renaming a
    finished folder into place); returns the folder."""
    folder = os.path.join(root, key)
    if os.path.isdir(folder) and _complete(folder, files) and _hold(folder):
        return folder
    os.makedirs(root, exist_ok=True)
    stage = tempfile.mkdtemp(prefix=".stage-", dir=root)
    try:
        for i, f in enumerate(files):
            dest = os.path.join(stage, os.path.basename(f))
            shutil.copyfile(f, dest)
            os.chmod(dest, 0o644 if i == 0 else 0o755)  # files[0] is the library
        open(os.path.join(stage, _LOCK_NAME), "w").close()
        try:
            os.rename(stage, folder)
        except OSError:
            # Another process put it in place first, or a broken copy is in
            # the way: use this process's own copy under another name.
            if os.path.isdir(folder) and _complete(folder, files) and _hold(folder):
                shutil.rmtree(stage, ignore_errors=True)
                return folder
            folder = "%s-%d" % (folder, os.getpid())
            shutil.rmtree(folder, ignore_errors=True)
            os.rename(stage, folder)
    except BaseException:
        shutil.rmtree(stage, ignore_errors=True)
        raise
    if not _hold(folder):
        raise OSError(errno.ENOENT, "%s vanished" % folder)
    return folder


def clean_stale_copies(root):
    """Remove copies no process holds (their flock is free). Safe while
    other Blenders run: a held folder is never touched."""
    try:
        names = os.listdir(root)
    except OSError:
        return
    for name in names:
        folder = os.path.join(root, name)
        if folder in _held_locks or not os.path.isdir(folder):
            continue
        if name.startswith(".stage-"):
            # A copy being made now, or left by a crash: only old ones go.
            try:
                if time.time() - os.path.getmtime(folder) > 3600:
                    shutil.rmtree(folder, ignore_errors=True)
            except OSError:
                pass
            continue
        try:
            fd = os.open(os.path.join(folder, _LOCK_NAME), os.O_RDONLY)
        except OSError:
            continue  # not ours (no lock file): leave it
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            os.close(fd)
            continue  # in use by a running process
        try:
            # Unlink the lock file last, so that a loader that opened it
            # before the removal sees it gone (_hold compares inodes).
            for entry in os.listdir(folder):
                if entry != _LOCK_NAME:
                    os.unlink(os.path.join(folder, entry))
            os.unlink(os.path.join(folder, _LOCK_NAME))
            os.rmdir(folder)
        except OSError:
            pass
        finally:
            os.close(fd)


def private_copy(path):
    """The path of a private copy of the library at path, with the helpers
    that sit next to it, or None when no cache folder is writable (the
    library is then loaded in place)."""
    src = os.path.dirname(os.path.abspath(path))
    files = [os.path.abspath(path)] + [os.path.join(src, n) for n in helper_names(src)]
    try:
        key = _content_key(files)
    except OSError:
        return None
    for root in cache_roots():
        try:
            folder = _make_copy(root, key, files)
        except OSError:
            continue
        clean_stale_copies(root)
        return os.path.join(folder, os.path.basename(path))
    return None


def restore_execute_bit(path):
    """Blender installs an add-on zip with zipfile.extractall, which drops
    file modes, so the shipped helper arrives without its execute bit: give
    it back (execute where it is readable). Returns whether path is now
    executable; a missing or read-only helper is left to the library, whose
    error names it when a .vdb is loaded."""
    try:
        mode = os.stat(path).st_mode
        if not os.access(path, os.X_OK):
            os.chmod(path, mode | ((mode & 0o444) >> 2))
    except OSError:
        return False
    return os.access(path, os.X_OK)


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


# --------------------------------------------------------------- helpers

def _fptr(arr):
    return arr.ctypes.data_as(ctypes.POINTER(ctypes.c_float))


def _matrix_cm(m, ctype=ctypes.c_float):
    """4x4 math matrix (m[row][col]) -> 16 column-major values."""
    a = np.asarray(m, dtype=np.float64).reshape(4, 4)
    return (ctype * 16)(*a.T.ravel().tolist())


def matrix_from_cm(values):
    """16 column-major values -> numpy 4x4 math matrix."""
    return np.array(list(values), dtype=np.float64).reshape(4, 4).T


# ---------------------------------------------------------------- volume

class Volume:
    """A volume held by the library (loaded from a file or from numpy)."""

    def __init__(self, lib, handle, keepalive=None):
        self.lib = lib
        self._handle = handle
        self._keepalive = keepalive  # numpy data the library may point at
        self.info = self._read_info()

    @classmethod
    def load(cls, path, max_dim=0, memory_budget=0, voxel_size=None, lib=None, frame=0, series=None):
        """voxel_size (x, y, z) mm is for inputs without geometry (TIFF/PNG
        stacks); None or 0 = 1 mm. Files with geometry ignore it.
        frame: the volume of a 4D file (only it is read); series: for a
        DICOM folder of several series, an index (int or its string) or a
        SeriesInstanceUID, as list_dicom_series() gives them."""
        lib = lib or load_library()
        opt = _sized(LoadOptions)
        opt.max_dim = max_dim
        opt.memory_budget_bytes = memory_budget
        if voxel_size is not None:
            opt.voxel_size[:] = [float(x) for x in voxel_size]
        opt.frame = int(frame)
        if series is not None and str(series) != "":
            opt.series = str(series).encode()
        h = ctypes.c_void_p()
        # The library's message already names the file.
        lib.check(lib.cdll.vxl_volume_load(os.fsencode(path), ctypes.byref(opt), ctypes.byref(h)))
        return cls(lib, h)

    @classmethod
    def phantom(cls, spec, lib=None):
        """A generated analytic phantom from "phantom:NAME[:WxHxD]" (the
        CLI's syntax), e.g. "phantom:large-sparse" (2500x1500x400)."""
        lib = lib or load_library()
        parts = spec.split(":")
        if parts[0] != "phantom" or len(parts) not in (2, 3):
            raise VoxlightError("not a phantom spec: %r (phantom:NAME[:WxHxD])" % spec)
        names = {}
        k = 1
        while lib.cdll.vxl_phantom_name(k):
            names[lib.cdll.vxl_phantom_name(k).decode()] = k
            k += 1
        if parts[1] not in names:
            raise VoxlightError("unknown phantom %r (%s)" % (parts[1], ", ".join(names)))
        d = _sized(PhantomDesc)
        d.kind = names[parts[1]]
        if len(parts) == 3:
            try:
                dims = [int(n) for n in parts[2].split("x")]
            except ValueError:
                dims = []
            if len(dims) != 3 or min(dims) < 2:
                raise VoxlightError("bad phantom size %r: use WxHxD" % parts[2])
            d.dims[:] = dims
        h = ctypes.c_void_p()
        lib.check(lib.cdll.vxl_phantom_create(ctypes.byref(d), ctypes.byref(h)), what="phantom")
        return cls(lib, h)

    @classmethod
    def from_array(cls, array, spacing=None, affine=None, scl_slope=0.0, scl_inter=0.0,
                   max_dim=0, memory_budget=0, lib=None):
        """array[i, j, k] (NIfTI/nibabel index order), any numeric dtype."""
        lib = lib or load_library()
        a = np.asarray(array)
        if a.ndim != 3:
            raise ValueError("volume array must be 3-D, got shape %s" % (a.shape,))
        if a.dtype == np.bool_:
            a = a.astype(np.uint8)
        elif a.dtype not in _DTYPES:
            a = a.astype(np.float32 if a.dtype.kind == "f" else np.float64)
        a = np.asfortranarray(a)  # x fastest, as the library expects
        desc = _sized(VolumeDesc)
        desc.dtype = _DTYPES[a.dtype]
        desc.dims[:] = [int(n) for n in a.shape]
        desc.data = a.ctypes.data
        if spacing is not None:
            desc.spacing[:] = [float(s) for s in spacing]
        if affine is not None:
            desc.has_affine = 1
            desc.affine[:] = np.asarray(affine, np.float64).reshape(4, 4).T.ravel().tolist()
        desc.scl_slope = scl_slope
        desc.scl_inter = scl_inter
        opt = _sized(LoadOptions)
        opt.max_dim = max_dim
        opt.memory_budget_bytes = memory_budget
        h = ctypes.c_void_p()
        lib.check(lib.cdll.vxl_volume_create(ctypes.byref(desc), ctypes.byref(opt),
                                             ctypes.byref(h)), what="volume from array")
        return cls(lib, h, keepalive=a)

    def _read_info(self):
        info = _sized(VolumeInfo)
        self.lib.check(self.lib.cdll.vxl_volume_get_info(self._handle, ctypes.byref(info)))
        return {
            "dtype": DTYPE_NAMES.get(info.dtype, str(info.dtype)),
            "dims": tuple(int(d) for d in info.dims),
            "nifti_version": info.nifti_version,
            "spacing": tuple(info.spacing),
            "affine": matrix_from_cm(info.affine),
            "value_min": info.value_min,
            "value_max": info.value_max,
            "nan_count": info.nan_count,
            "inf_count": info.inf_count,
            "storage_bytes": info.storage_bytes,
            "texture_bits": info.texture_bits,
            "affine_source": ("none", "qform", "sform")[info.affine_source]
            if info.affine_source < 3 else str(info.affine_source),
            "frame_count": max(1, info.frame_count),
            "frame": info.frame,
        }

    def histogram(self, bins=32, lo=None, hi=None):
        """Voxel counts (NaN voxels excluded) in `bins` equal bins over
        [lo, hi], by default the finite data range; any loaded format."""
        lo = self.info["value_min"] if lo is None else lo
        hi = self.info["value_max"] if hi is None else hi
        if not hi > lo:
            hi = lo + 1.0
        counts = (ctypes.c_uint64 * bins)()
        self.lib.check(self.lib.cdll.vxl_volume_histogram(self.handle, bins, lo, hi, counts))
        return np.frombuffer(counts, np.uint64).astype(np.int64)

    @property
    def handle(self):
        if not self._handle:
            raise VoxlightError("volume is closed")
        return self._handle

    def close(self):
        if self._handle:
            self.lib.cdll.vxl_volume_destroy(self._handle)
            self._handle = None
            self._keepalive = None

    def __del__(self):
        try:
            self.close()
        except Exception:
            pass

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def list_dicom_series(path, lib=None):
    """The series of a DICOM folder, DICOMDIR or file (its folder) as dicts
    (uid, modality, description, slice_count, dims, loadable, problem,
    gantry_tilt_deg, frame_count), in the order whose index Volume.load(series=) takes.
    [] for inputs that are not DICOM."""
    lib = lib or load_library()
    n = ctypes.c_uint32()
    if lib.cdll.vxl_dicom_list_series(os.fsencode(path), None, 0, ctypes.byref(n)) != 0:
        return []
    arr = (DicomSeries * max(1, n.value))()
    arr[0].struct_size = ctypes.sizeof(DicomSeries)
    lib.check(lib.cdll.vxl_dicom_list_series(os.fsencode(path), arr, n.value, ctypes.byref(n)))
    text = lambda b: b.decode("utf-8", "replace")  # noqa: E731
    return [{"uid": text(s.uid), "modality": text(s.modality), "description": text(s.description),
             "slice_count": s.slice_count, "dims": tuple(s.dims), "loadable": bool(s.loadable),
             "problem": text(s.problem), "gantry_tilt_deg": s.gantry_tilt_deg,
             "frame_count": s.frame_count}
            for s in arr[:n.value]]


def voxel_box_corners(dims):
    """The 8 corners of the volume box in voxel space ([-0.5, dim-0.5])."""
    lo = np.full(3, -0.5)
    hi = np.asarray(dims, np.float64) - 0.5
    return np.array([[(hi if (c >> a) & 1 else lo)[a] for a in range(3)] for c in range(8)])


# ----------------------------------------------------------- render params

def make_params(width=0, height=0, view=None, proj=None, model=None, scene_depth=None,
                filter="central", sample_distance=1.0, reuse_gradients=False,
                gradient_16f=False, step=0.5, jitter=True, jitter_seed=0,
                preset="auto", window=None, opacity_scale=1.0, shading=True,
                material=None, lights=(), azimuth=0.0, elevation=0.0,
                early_termination=0.0, depth_threshold=0.0, no_skip=False,
                tf_rgba=None, classify="post", gradient_opacity="off", gradient_ref=0.0,
                gradient_exp=0.0, iso_value=0.0, iso_thickness=0.0, preint_size=0,
                lib=None):
    """Build a RenderParams. Keyword names are the Blender panel's. `lights`
    is a sequence of (position4, color3, intensity); `material` is
    (ambient, diffuse, specular, shininess) or None for the defaults;
    `window` is (low, high) or None for the preset's default. `tf_rgba` is
    an (n, 4) straight-RGBA table (alpha = opacity per voxel of path) that
    replaces the preset; `window` maps its [0, 1] onto data values.
    `classify` is one of CLASSIFY_MODES, `gradient_opacity` one of
    GRADIENT_OPACITY_MODES (or their VXL_* numbers)."""
    lib = lib or load_library()
    p = _sized(RenderParams)
    p.width, p.height = int(width), int(height)
    if view is not None or proj is not None:
        if view is None or proj is None:
            raise ValueError("view and proj must be given together")
        p.has_camera = 1
        p.view = _matrix_cm(view)
        p.proj = _matrix_cm(proj)
    p.azimuth_deg, p.elevation_deg = azimuth, elevation
    if model is not None:
        p.has_model = 1
        p.model = _matrix_cm(model)
    p._keep = []
    if scene_depth is not None:
        w, h = p.width or 512, p.height or 512
        d = np.ascontiguousarray(scene_depth, dtype=np.float32)
        if d.size != w * h:
            raise ValueError("scene_depth has %d values, image has %dx%d" % (d.size, w, h))
        p._keep.append(d)
        p.scene_depth = _fptr(d)
        p._scene_depth = d
    p.filter = filter if isinstance(filter, int) else lib.filter_index(filter)
    p.sample_distance = sample_distance
    p.reuse_gradients = 1 if reuse_gradients else 0
    p.gradient_store = 1 if gradient_16f else 0
    p.step = step
    p.jitter_off = 0 if jitter else 1
    p.jitter_seed = jitter_seed
    p.preset = preset if isinstance(preset, int) else lib.preset_index(preset)
    if window is not None:
        p.has_window = 1
        p.window_low, p.window_high = float(window[0]), float(window[1])
    if tf_rgba is not None:
        tf = np.ascontiguousarray(tf_rgba, dtype=np.float32).reshape(-1, 4)
        if len(tf) < 2:
            raise ValueError("tf_rgba needs at least 2 entries")
        p._keep.append(tf)
        p._tf = tf
        p.tf_size = len(tf)
        p.tf_rgba = _fptr(tf)
    p.classify = classify if isinstance(classify, int) else CLASSIFY_MODES.index(classify)
    p.gradient_opacity = (gradient_opacity if isinstance(gradient_opacity, int)
                          else GRADIENT_OPACITY_MODES.index(gradient_opacity))
    p.gradient_ref = gradient_ref
    p.gradient_exp = gradient_exp
    p.iso_value = iso_value
    p.iso_thickness = iso_thickness
    p.preint_size = preint_size
    p.opacity_scale = opacity_scale
    p.shading_off = 0 if shading else 1
    if material is not None:
        p.has_material = 1
        p.ambient, p.diffuse, p.specular, p.shininess = [float(v) for v in material]
    lights = list(lights)
    if len(lights) > MAX_LIGHTS:
        raise ValueError("at most %d lights" % MAX_LIGHTS)
    p.light_count = len(lights)
    for i, (pos, col, inten) in enumerate(lights):
        p.lights[i].position[:] = [float(v) for v in pos]
        p.lights[i].color[:] = [float(v) for v in col]
        p.lights[i].intensity = float(inten)
    p.early_termination = early_termination
    p.depth_threshold = depth_threshold
    p.no_skip = 1 if no_skip else 0
    return p


# ---------------------------------------------------- frame keys and tiles

def params_digest(params, *extra):
    """A digest of everything a render depends on: every field of the
    params struct (pointers excluded) plus the contents of the arrays it
    points at (scene depth), plus `extra` (the volume's identity). Equal
    digests mean the library would be given identical inputs."""
    c = RenderParams.from_buffer_copy(params)
    c.scene_depth = None
    c.tf_rgba = None
    h = hashlib.blake2b(bytes(c), digest_size=16)
    for a in getattr(params, "_keep", ()):
        a = np.ascontiguousarray(a)
        h.update(str((a.dtype.str, a.shape)).encode())
        h.update(memoryview(a).cast("B"))
    for e in extra:
        h.update(e if isinstance(e, bytes) else repr(e).encode())
    return h.hexdigest()


# The library jitters ray starts with a hash of (pixel x, pixel y, seed)
# (shaders/raycast.frag: x*1973 + y*9277 + seed*26699 mod 2^32). A tile's
# pixels are numbered from its own corner, so tile_params adds the tile's
# offset through the seed: the tiled image then has the very same jitter as
# the whole one. tests/python/test_native.py checks the equality; if the
# shader's hash changes, update these constants (or, better, give the library
# a tile-origin parameter, see plugin/README.md).
_JITTER_X, _JITTER_Y, _JITTER_SEED = 1973, 9277, 26699
_JITTER_SEED_INV = pow(_JITTER_SEED, -1, 1 << 32)


def tile_params(params, x0, y0, x1, y1):
    """Params that render the pixel rectangle [x0, x1) x [y0, y1) (row 0 =
    bottom) of the image `params` describes, as an image of its own: the
    projection is narrowed to the rectangle, the scene depth is cropped and
    the jitter keeps the whole image's pattern. Needs an explicit camera."""
    W, H = params.width or 512, params.height or 512
    if not params.has_camera:
        raise ValueError("tiles need an explicit camera (view and proj)")
    if not (0 <= x0 < x1 <= W and 0 <= y0 < y1 <= H):
        raise ValueError("tile %r outside the %dx%d image" % ((x0, y0, x1, y1), W, H))
    t = RenderParams.from_buffer_copy(params)
    t._keep = []
    tf = getattr(params, "_tf", None)
    if params.tf_rgba and tf is None:
        raise ValueError("params.tf_rgba was not set by make_params")
    if tf is not None:  # the copy points at the same table: keep it alive
        t._keep.append(tf)
        t._tf = tf
    t.width, t.height = x1 - x0, y1 - y0
    a, b = 2.0 * x0 / W - 1.0, 2.0 * x1 / W - 1.0
    c, d = 2.0 * y0 / H - 1.0, 2.0 * y1 / H - 1.0
    m = np.eye(4)
    m[0, 0], m[0, 3] = 2.0 / (b - a), -(a + b) / (b - a)
    m[1, 1], m[1, 3] = 2.0 / (d - c), -(c + d) / (d - c)
    t.proj = _matrix_cm(m @ matrix_from_cm(params.proj))
    off = (x0 * _JITTER_X + y0 * _JITTER_Y) * _JITTER_SEED_INV
    t.jitter_seed = (params.jitter_seed + off) & 0xFFFFFFFF
    depth = getattr(params, "_scene_depth", None)
    if params.scene_depth and depth is None:
        raise ValueError("params.scene_depth was not set by make_params")
    if depth is not None:
        sub = np.ascontiguousarray(depth.reshape(H, W)[y0:y1, x0:x1])
        t._keep.append(sub)
        t._scene_depth = sub
        t.scene_depth = _fptr(sub)
    return t


def _empty_stats():
    return {"samples": 0, "rays": 0, "max_ray_samples": 0, "sample_bound": 0,
            "effective_step": 0.0, "bricks_total": 0, "bricks_occupied": 0,
            "brick_size": 0, "calls": 0, "seconds": 0.0, "storage_name": "", "resident_bytes": 0,
            "pages_total": 0, "pages_resident": 0, "pages_constant": 0, "lod_level": 0,
            "lod_wanted_bytes": 0, "decode_ms": 0.0}


def _merge_stats(acc, s):
    acc["samples"] += s["samples"]
    acc["rays"] += s["rays"]
    acc["max_ray_samples"] = max(acc["max_ray_samples"], s["max_ray_samples"])
    acc["sample_bound"] = max(acc["sample_bound"], s["sample_bound"])
    for k in ("effective_step", "bricks_total", "bricks_occupied", "brick_size", "storage_name",
              "resident_bytes", "pages_total", "pages_resident", "pages_constant", "lod_level",
              "lod_wanted_bytes", "decode_ms"):
        acc[k] = s[k]
    return acc


# -------------------------------------------------------------- renderer

class Renderer:
    """One library renderer: its own GL context on its own thread, holding
    one volume. Safe to call from any Python thread."""

    def __init__(self, backend="auto", memory_budget=0, shader_dir=None, lib=None,
                 storage="auto", page_brick=0):
        self.lib = lib or load_library()
        opt = _sized(RendererOptions)
        opt.backend = BACKENDS.index(backend) if isinstance(backend, str) else int(backend)
        opt.memory_budget_bytes = memory_budget
        opt.storage = STORAGES.index(storage) if isinstance(storage, str) else int(storage)
        opt.page_brick = page_brick
        opt.shader_dir = os.fsencode(shader_dir) if shader_dir else None
        h = ctypes.c_void_p()
        self.lib.check(self.lib.cdll.vxl_renderer_create(ctypes.byref(opt), ctypes.byref(h)),
                       what="renderer")
        self._handle = h
        self.volume_info = None
        # Called with no arguments after every vxl_render (counts library calls).
        self.on_render = None

    @property
    def handle(self):
        if not self._handle:
            raise VoxlightError("renderer is closed")
        return self._handle

    def _check(self, code, what=""):
        self.lib.check(code, self._handle, what)

    def info(self):
        i = _sized(RendererInfo)
        self._check(self.lib.cdll.vxl_renderer_get_info(self.handle, ctypes.byref(i)))
        return {"backend": i.backend, "backend_name": i.backend_name.decode(),
                "gl_renderer": i.gl_renderer.decode(), "gl_version": i.gl_version.decode(),
                "max_3d_texture_size": i.max_3d_texture_size}

    def set_volume(self, volume):
        self._check(self.lib.cdll.vxl_renderer_set_volume(self.handle, volume.handle),
                    "set volume")
        self.volume_info = dict(volume.info)

    def render(self, params=None, want_depth=True, **kwargs):
        """Render; returns (rgba[h, w, 4], depth[h, w] or None), float32,
        row 0 = bottom, premultiplied RGBA."""
        if params is None:
            params = make_params(lib=self.lib, **kwargs)
        w, h = params.width or 512, params.height or 512
        rgba = np.empty((h, w, 4), np.float32)
        depth = np.empty((h, w), np.float32) if want_depth else None
        self._check(self.lib.cdll.vxl_render(self.handle, ctypes.byref(params), _fptr(rgba),
                                             _fptr(depth) if want_depth else None), "render")
        if self.on_render is not None:
            self.on_render()
        return rgba, depth

    def stats(self):
        """What the last render did (vxl_renderer_get_stats) as a dict."""
        st = _sized(RenderStats)
        self._check(self.lib.cdll.vxl_renderer_get_stats(self.handle, ctypes.byref(st)), "stats")
        d = {k: getattr(st, k) for k, _t in RenderStats._fields_ if k != "struct_size"}
        d["storage_name"] = STORAGES[d["storage"]] if d["storage"] < len(STORAGES) else "?"
        return d

    def render_tiled(self, params, rect=None, rows=None, target_seconds=0.05,
                     should_stop=None):
        """Render the image `params` describes as horizontal bands of the
        pixel rectangle `rect` = (x0, y0, x1, y1) (default: the whole
        image); pixels outside it are empty (alpha 0, depth +inf), which is
        exact when rect holds the volume's screen footprint.

        Each band is one library call, sized to take about target_seconds
        (or `rows` rows), and should_stop() is asked before every band: a
        caller on another thread abandons a stale frame within one band,
        and the renderer (whose calls serialize) is free again. Returns
        (rgba, depth, stats), or None when stopped. Equals render() up to
        float rounding of the narrowed projections (the jitter pattern is
        the same)."""
        W, H = params.width or 512, params.height or 512
        rgba = np.zeros((H, W, 4), np.float32)
        depth = np.full((H, W), np.inf, np.float32)
        acc = _empty_stats()
        x0, y0, x1, y1 = rect if rect is not None else (0, 0, W, H)
        x0, y0, x1, y1 = max(0, x0), max(0, y0), min(W, x1), min(H, y1)
        if x1 <= x0 or y1 <= y0:
            return rgba, depth, acc
        n = int(rows) if rows else max(1, 16384 // (x1 - x0))  # first band ~16k pixels
        y = y0
        t_start = time.perf_counter()
        while y < y1:
            if should_stop is not None and should_stop():
                return None
            n = max(1, min(n, y1 - y))
            tp = tile_params(params, x0, y, x1, y + n)
            t = time.perf_counter()
            c, d = self.render(tp)
            dt = time.perf_counter() - t
            rgba[y:y + n, x0:x1] = c
            depth[y:y + n, x0:x1] = d
            _merge_stats(acc, self.stats())
            acc["calls"] += 1
            y += n
            if not rows:  # aim at target_seconds, growing at most 2x per band
                n = int(max(1, min(2 * n, y1 - y0, target_seconds * n / max(dt, 1e-4))))
        acc["seconds"] = time.perf_counter() - t_start
        return rgba, depth, acc

    def default_camera(self, params=None, **kwargs):
        """(view, proj) as numpy 4x4 math matrices."""
        if params is None:
            params = make_params(lib=self.lib, **kwargs)
        view = (ctypes.c_float * 16)()
        proj = (ctypes.c_float * 16)()
        self._check(self.lib.cdll.vxl_default_camera(self.handle, ctypes.byref(params),
                                                     view, proj), "default camera")
        return matrix_from_cm(view), matrix_from_cm(proj)

    def probe_gradients(self, points, params=None, **kwargs):
        """Gradient of the selected filter at voxel-space points (n, 3)."""
        if params is None:
            params = make_params(lib=self.lib, **kwargs)
        pts = np.ascontiguousarray(points, dtype=np.float32).reshape(-1, 3)
        out = np.empty_like(pts)
        self._check(self.lib.cdll.vxl_probe_gradients(self.handle, ctypes.byref(params),
                                                      _fptr(pts), len(pts), _fptr(out)),
                    "probe gradients")
        return out

    def close(self):
        if self._handle:
            self.lib.cdll.vxl_renderer_destroy(self._handle)
            self._handle = None

    def __del__(self):
        try:
            self.close()
        except Exception:
            pass

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
