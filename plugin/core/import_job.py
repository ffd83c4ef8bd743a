"""A volume import running on a worker thread (no bpy), so Blender's UI
stays live, shows progress and can cancel with Esc.

Cancelling returns control at once and lets the worker finish its current
step in the background; the worker sees the flag between steps
(runtime.open_volume asks) and closes whatever it made, and a result that
arrives after the cancel is closed too. The library's first pass over a
file (a .nii.gz streamed into its bricked cache) reports progress
and stops at the flag, leaving no partial cache; other loads run to their
end. Nothing of a cancelled import is registered or kept.
"""

import os
import threading

from . import native, runtime

# Formats the library reads, by name ending (lower case); folders are image
# stacks, DICOM series or OME-Zarr stores (".zarr", docs/zarr.md). Used for
# the file browser filter and to name the new object after the file without
# its extension.
EXTENSIONS = (".nii.gz", ".nii", ".hdr.gz", ".img.gz", ".hdr", ".img", ".nrrd", ".nhdr", ".mha",
              ".mhd", ".tiff", ".tif", ".png", ".vdb", ".dcm", ".zarr")
FILTER_GLOB = ";".join("*" + e for e in EXTENSIONS) + ";DICOMDIR"


def display_name(path):
    """'brain' for /data/brain.nii.gz, the folder's name for a folder."""
    base = os.path.basename(path.rstrip(os.sep)) or path
    low = base.lower()
    for ext in EXTENSIONS:
        if low.endswith(ext) and len(base) > len(ext):
            return base[: -len(ext)]
    return base


def is_vdb(path):
    """OpenVDB geometry is in scene units already (Blender writes them)."""
    return path.lower().endswith(".vdb")


class ImportJob:
    """Loads `path` with runtime.open_volume on a daemon thread. Poll `done`;
    then `entry` (an unregistered runtime.VolumeEntry) or `error` (the
    library's message, which names the file) is set."""

    def __init__(self, path, voxel_size=None, start=True, series="", backend="auto", storage="auto",
                 memory_budget=0):
        self.path = path
        self.backend = backend
        self.voxel_size = voxel_size
        self.series = series
        self.storage = storage
        self.memory_budget = memory_budget
        self.progress = 0.0
        self.stage = ""  # what the library's first pass over the file is doing ("" = none)
        self.entry = None
        self.error = None
        self._cancelled = threading.Event()
        self._done = threading.Event()
        self._lock = threading.Lock()  # entry hand-over against cancel()
        self._thread = None
        if start:
            self._thread = threading.Thread(target=self.run, name="voxlight-import", daemon=True)
            self._thread.start()

    @property
    def done(self):
        return self._done.is_set()

    @property
    def cancelled(self):
        return self._cancelled.is_set()

    def _set_progress(self, f):
        self.progress = f
        self.stage = ""

    # The library's pass over the file is the load step, the first 40 % of
    # open_volume's progress (it reports 0.4 once the volume is open).
    LOAD_SHARE = 0.4

    def _set_load_progress(self, fraction, stage):
        self.progress = self.LOAD_SHARE * min(max(fraction, 0.0), 1.0)
        self.stage = stage

    def run(self):
        """The work; called on the thread, or directly for a blocking import."""
        try:
            entry = runtime.open_volume(self.path, self.backend, self._set_progress, self.voxel_size,
                                        cancelled=self._cancelled.is_set, series=self.series,
                                        storage=self.storage, memory_budget=self.memory_budget,
                                        load_progress=self._set_load_progress)
        except (native.VoxlightError, OSError) as e:
            self.error = str(e)
            entry = None
        except Exception as e:  # never let a worker die silently
            self.error = "%s: %s" % (type(e).__name__, e)
            entry = None
        with self._lock:
            if entry is not None and self._cancelled.is_set():
                entry.close()
                entry = None
            self.entry = entry
            if entry is not None:
                self.progress = 1.0
        self._done.set()

    def cancel(self):
        """Drops the import: a finished result is closed now, one still in
        flight when it arrives."""
        with self._lock:
            self._cancelled.set()
            if self.entry is not None:
                self.entry.close()
                self.entry = None

    def take(self):
        """Hands the finished entry over (the caller now owns it)."""
        with self._lock:
            entry, self.entry = self.entry, None
        return entry

    def wait(self, timeout=None):
        return self._done.wait(timeout)


def note_lines(notes):
    """The reader's notes (vxl_volume_info.notes: a sentence per decision,
    joined by "; ") one per line, for a panel whose labels do not wrap."""
    return [n.strip() for n in (notes or "").split("; ") if n.strip()]


def import_report(name, info, why):
    """The import's INFO report: what was imported, what it became and why
    (why), and what the reader decided rather than read (info["notes"]), so
    no guess the reader made goes unseen."""
    streamed = ", streamed from disk (%d levels)" % info["level_count"] if info.get("streamed") else ""
    text = "Voxlight: imported %s (%d x %d x %d, %s%s) %s" % (name, *info["dims"], info["dtype"], streamed, why)
    notes = info.get("notes", "")
    return text + (" - reader notes: %s" % notes if notes else "")
