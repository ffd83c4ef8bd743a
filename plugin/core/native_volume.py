"""Volumes held by libvoxlight: loaded from a file, made from a numpy array
or generated (phantoms), with their information and histogram; the series
of a DICOM folder; the label lookup table of a segmentation.

Part of the ctypes binding; plugin/core/native.py re-exports it."""

import ctypes
import os

import numpy as np

from .native_abi import (OPACITY_SOURCES, PROGRESS_CALLBACK, DicomSeries, GridInfo, GridParams, LabelEntry,
                         LibraryObject, LoadOptions, PhantomDesc, VolumeDesc, VolumeInfo, VoxlightError, matrix_from_cm,
                         _DTYPES, _fptr, _sized)
from .native_library import load_library


ERR_CANCELLED = 10  # VXL_ERR_CANCELLED: a progress callback asked to stop


def _progress_callback(progress, raised):
    """progress(fraction, stage) as the library's callback: nonzero (cancel)
    when it returns something true, or when it raises; the exception goes
    into `raised` for the caller to raise once the library has returned
    (an exception cannot cross the C frames)."""
    def call(_user, fraction, stage):
        if raised:
            return 1
        try:
            return 1 if progress(float(fraction), stage.decode("utf-8", "replace") if stage else "") else 0
        except BaseException as e:  # noqa: B902 - KeyboardInterrupt too: it must not be lost in C
            raised.append(e)
            return 1
    return PROGRESS_CALLBACK(call)


class Volume(LibraryObject):
    """A volume held by the library (loaded from a file or from numpy)."""

    def __init__(self, lib, handle, keepalive=None):
        self.lib = lib
        self._handle = handle
        self._keepalive = keepalive  # numpy data the library may point at
        self.info = self._read_info()

    @classmethod
    def load(cls, path, max_dim=0, memory_budget=0, voxel_size=None, lib=None, frame=0, series=None,
             streaming="auto", cache_dir=None, progress=None):
        """voxel_size (x, y, z) mm is for inputs without geometry (TIFF/PNG
        stacks); None or 0 = 1 mm. Files with geometry ignore it.
        frame: the volume of a 4D file (only it is read); series: for a
        DICOM folder of several series, an index (int or its string) or a
        SeriesInstanceUID, as list_dicom_series() gives them.
        streaming is "auto", "off" or "on" (vxl_streaming_name, or
        VXL_STREAMING_*): whether the voxels are read on demand instead of
        whole; cache_dir is where the bricked cache of a .nii.gz goes (None:
        beside the file). progress(fraction, stage) is called on this thread
        during the first pass over a file; a true return cancels the load,
        which then raises VoxlightError with code ERR_CANCELLED and leaves no
        partial cache. An exception raised by progress cancels the load too
        and is raised again here."""
        lib = lib or load_library()
        opt = _sized(LoadOptions)
        opt.max_dim = max_dim
        opt.memory_budget_bytes = memory_budget
        if voxel_size is not None:
            opt.voxel_size[:] = [float(x) for x in voxel_size]
        opt.frame = int(frame)
        if series is not None and str(series) != "":
            opt.series = str(series).encode()
        opt.streaming = streaming if isinstance(streaming, int) else lib.index("streaming", streaming)
        if cache_dir:
            opt.cache_dir = os.fsencode(cache_dir)
        raised = []
        if progress is not None:
            # opt holds the only C pointer to the callback, and opt lives
            # until this function returns, after the library's last call.
            opt.progress = _progress_callback(progress, raised)
        h = ctypes.c_void_p()
        code = lib.cdll.vxl_volume_load(os.fsencode(path), ctypes.byref(opt), ctypes.byref(h))
        if raised:
            if code == 0:
                lib.cdll.vxl_volume_destroy(h)
            raise raised[0]
        # The library's message already names the file.
        lib.check(code)
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
            "dtype": self.lib.name("dtype", info.dtype) or str(info.dtype),
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
            # read on demand, its resolution levels, CPU bytes held, bytes read so far
            "streamed": bool(info.streamed),
            "level_count": max(1, info.level_count),
            "resident_bytes": info.resident_bytes,
            "bytes_read": info.bytes_read,
            # what the reader decided rather than read ("PixelSpacing missing: 1 mm assumed"); "" if nothing
            "notes": info.notes.decode("utf-8", "replace"),
            # 1 grey; 3 RGB, 4 RGBA: a colour volume, whose scalar is its opacity source
            "components": max(1, int(info.components)),
            "opacity_source": OPACITY_SOURCES[info.opacity_source]
            if info.opacity_source < len(OPACITY_SOURCES) else str(info.opacity_source),
            # 0: one scalar; 2..8: a multi-channel volume whose scalar is
            # channel scalar_channel, each channel with its own data range
            "channel_count": int(info.channel_count),
            "scalar_channel": int(info.scalar_channel),
            "channel_min": [float(v) for v in info.channel_min[:info.channel_count]],
            "channel_max": [float(v) for v in info.channel_max[:info.channel_count]],
            # what the file says about each channel (OME metadata); None where it says nothing
            "channel_names": [bytes(info.channel_names[c].value).decode("utf-8", "replace")
                              for c in range(info.channel_count)],
            "channel_colors": [tuple(float(v) for v in info.channel_colors[c])
                               if info.channel_color_known[c] else None for c in range(info.channel_count)],
            "channel_windows": [(float(info.channel_window_low[c]), float(info.channel_window_high[c]))
                                if info.channel_window_known[c] else None for c in range(info.channel_count)],
            "channel_active": [bool(info.channel_active[c]) for c in range(info.channel_count)],
        }

    def histogram(self, bins=32, lo=None, hi=None, channel=None):
        """Voxel counts (NaN voxels excluded) in `bins` equal bins over
        [lo, hi], by default the finite data range; any loaded format.
        channel: that channel of a multi-channel volume instead of the
        scalar, over its own range by default."""
        if channel is None:
            lo = self.info["value_min"] if lo is None else lo
            hi = self.info["value_max"] if hi is None else hi
        else:
            count = self.info["channel_count"]
            c = int(channel)
            lo = (self.info["channel_min"][c] if 0 <= c < count else 0.0) if lo is None else lo
            hi = (self.info["channel_max"][c] if 0 <= c < count else 1.0) if hi is None else hi
        if not hi > lo:
            hi = lo + 1.0
        counts = (ctypes.c_uint64 * bins)()
        if channel is None:
            self.lib.check(self.lib.cdll.vxl_volume_histogram(self.handle, bins, lo, hi, counts))
        else:
            self.lib.check(self.lib.cdll.vxl_volume_channel_histogram(self.handle, int(channel), bins,
                                                                      lo, hi, counts))
        return np.frombuffer(counts, np.uint64).astype(np.int64)

    def classified_grid(self, params, dims=(0, 0, 0), fill=True):
        """The volume classified as params classifies it, as a medium on a
        grid of dims cells (0 on an axis: the volume's own count):
        vxl_classified_grid, docs/physical_model.md. Returns (info dict,
        density (z, y, x) float32 extinction per world unit, rgb (z, y, x, 3)
        float32 linear colour); with fill False only the info, and None for
        both arrays, so a caller can check the size first."""
        g = _sized(GridParams)
        g.dims[:] = [int(d) for d in dims]
        info = _sized(GridInfo)
        self.lib.check(self.lib.cdll.vxl_classified_grid(self.handle, ctypes.byref(params), ctypes.byref(g),
                                                         ctypes.byref(info), None, None), what="classified grid")
        shape = tuple(int(d) for d in reversed(info.dims))
        density = rgb = None
        if fill:
            density = np.empty(shape, np.float32)
            rgb = np.empty(shape + (3,), np.float32)
            self.lib.check(self.lib.cdll.vxl_classified_grid(self.handle, ctypes.byref(params), ctypes.byref(g),
                                                             ctypes.byref(info), _fptr(density), _fptr(rgb)),
                           what="classified grid")
        return {"dims": tuple(int(d) for d in info.dims),
                "index_to_world": matrix_from_cm(info.index_to_world),
                "voxel_length": info.voxel_length,
                "max_density": info.max_density}, density, rgb

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


def load_label_table(path, lib=None):
    """The labels of a lookup file (FreeSurfer LUT, ITK-SNAP label
    description, 3D Slicer .ctbl, MRIcron .lut/.txt; docs/labels.md) as
    dicts (id, name, color: straight RGBA 0..1, visible: bool), sorted by
    id. Raises VoxlightError with the library's message on a bad file."""
    lib = lib or load_library()
    n = ctypes.c_uint32()
    lib.check(lib.cdll.vxl_label_table_load(os.fsencode(path), None, 0, ctypes.byref(n)))
    arr = (LabelEntry * max(1, n.value))()
    arr[0].struct_size = ctypes.sizeof(LabelEntry)
    lib.check(lib.cdll.vxl_label_table_load(os.fsencode(path), arr, n.value, ctypes.byref(n)))
    return [{"id": e.id, "name": e.name.decode("utf-8", "replace"), "color": tuple(e.color),
             "visible": bool(e.visible)}
            for e in arr[:n.value]]


def voxel_box_corners(dims):
    """The 8 corners of the volume box in voxel space ([-0.5, dim-0.5])."""
    lo = np.full(3, -0.5)
    hi = np.asarray(dims, np.float64) - 0.5
    return np.array([[(hi if (c >> a) & 1 else lo)[a] for a in range(3)] for c in range(8)])
