"""The add-on's live library objects: one native Renderer per volume file,
shared by every object, viewport and render that shows that file, and per
renderer one background thread (Worker) for the viewport's full-resolution
frames.

Kept apart from bpy data because the handles are not saveable; they are
rebuilt lazily from Object.voxlight.filepath after a file is reopened. No
bpy here: the worker is tested in plain Python (tests/python).

Counters (read by the tests and the panel):
  render_count    frames rendered (viewport, F12, API); a frame rendered in
                  bands counts once, a cancelled frame not at all;
  call_count      vxl_render calls (each band of a banded frame counts);
  cancelled_count viewport frames abandoned or skipped as stale.
"""

import atexit
import os
import threading
import time

from . import budget_split, frames, label_import, label_runtime, native, tf_fit
from .native_volume import ERR_CANCELLED

_lock = threading.Lock()

# How long closing a renderer waits for the render band in flight: a band
# takes about Worker.target_seconds, so a call still running after this has
# hung, and the wait ends with a message instead of freezing Blender.
CLOSE_WAIT_S = 30.0
render_count = 0
call_count = 0
cancelled_count = 0


def _count(frames=0, calls=0, cancelled=0):
    global render_count, call_count, cancelled_count
    with _lock:
        render_count += frames
        call_count += calls
        cancelled_count += cancelled


def _count_call():
    _count(calls=1)


class Job:
    """One full-resolution frame for one owner (a viewport region and
    object). The main thread sets `cancelled` when the frame has become
    stale; the worker then drops it before its next band."""

    def __init__(self, owner, key, params, rect=None):
        self.owner = owner
        self.key = key
        self.params = params
        self.rect = rect
        self.cancelled = False
        self.done = False
        self.result = None   # (rgba, depth, stats) when finished
        self.error = None    # the exception when the library failed
        self.submitted = time.monotonic()
        self.full = False    # the viewport's last refine step (full resolution), not the half
        # Other work than a banded frame (the viewport's scene shadows): called
        # on the worker as run(should_stop); its return value is the result.
        self.run = None

    @property
    def pending(self):
        return not self.done


class Worker:
    """A thread that renders Jobs for one renderer, newest first per owner.

    submit() replaces the owner's queued job (the old one is skipped
    without being started) and cancels the owner's running job; a running
    job checks its flag between bands (native.Renderer.render_tiled), so it
    lets go of the renderer within one band (~target_seconds). The library
    serializes calls per renderer, so a synchronous render on the main
    thread waits at most that long."""

    def __init__(self, entry, target_seconds=0.05):
        self.entry = entry
        self.target_seconds = target_seconds
        self._cond = threading.Condition()
        self._queue = {}   # owner -> Job
        self._running = None
        self._stop = False
        self._thread = threading.Thread(target=self._run, name="voxlight-worker", daemon=True)
        self._thread.start()

    def submit(self, job):
        with self._cond:
            if self._stop:
                raise native.VoxlightError("renderer is closed")
            old = self._queue.pop(job.owner, None)
            if old is not None:
                self._finish(old, cancelled=True)
            run = self._running
            if run is not None and run.owner == job.owner:
                run.cancelled = True
            self._queue[job.owner] = job
            self._cond.notify()
        return job

    def cancel(self, job):
        """Drop `job` (queued or running). Safe to call on a finished job."""
        with self._cond:
            job.cancelled = True
            if self._queue.get(job.owner) is job:
                del self._queue[job.owner]
                self._finish(job, cancelled=True)

    def busy(self):
        with self._cond:
            return bool(self._queue) or self._running is not None

    def _finish(self, job, cancelled=False):
        if cancelled:
            job.cancelled = True
            _count(cancelled=1)
        job.done = True

    def _run(self):
        while True:
            with self._cond:
                while not self._queue and not self._stop:
                    self._cond.wait()
                if self._stop:
                    return
                owner = next(iter(self._queue))
                job = self._queue.pop(owner)
                self._running = job
            result = error = None
            if not job.cancelled:
                try:
                    stop = lambda: job.cancelled or self._stop  # noqa: E731
                    result = job.run(stop) if job.run is not None else drawing_channels(
                        self.entry, job.params, lambda p: self.entry.renderer.render_tiled(
                            p, rect=job.rect, target_seconds=self.target_seconds,
                            should_stop=stop))
                except Exception as e:  # reported by the main thread
                    error = e
            with self._cond:
                self._running = None
                job.error = error
                if job.cancelled:  # went stale during its last band
                    result = None
                if result is not None and job.run is not None:
                    job.result = result
                    self._finish(job)
                elif result is not None:
                    job.result = result
                    self.entry.last_frame = dict(result[2], width=job.params.width,
                                                 height=job.params.height, kind="refined")
                    _count(frames=1)
                    self._finish(job)
                else:
                    self._finish(job, cancelled=error is None)

    def close(self, timeout=None):
        """Stop the thread; waits for the band in flight (if any), at most
        `timeout` seconds (CLOSE_WAIT_S by default). Returns True once the
        thread has ended; False when a job is still inside the library: its
        renderer must then stay open, since the call in flight uses it."""
        with self._cond:
            self._stop = True
            for job in self._queue.values():
                self._finish(job, cancelled=True)
            self._queue.clear()
            if self._running is not None:
                self._running.cancelled = True
            self._cond.notify_all()
        if self._thread is threading.current_thread():
            return True
        self._thread.join(CLOSE_WAIT_S if timeout is None else timeout)
        return not self._thread.is_alive()


# Frames of 4D volumes, shared by every entry (frames.py).
frame_cache = frames.FrameCache()

# how files are opened, from the add-on preferences (preferences.py
# keeps this current): VXL_STREAMING_* by name, and where bricked caches go
# ("" = beside the file).
stream_settings = {"streaming": "auto", "cache_dir": ""}


def load_kwargs(memory_budget=0):
    """Volume.load's memory and streaming arguments for a total budget
    (bytes, 0 = the library's default): the volume's share of it
    (budget_split) and the preferences' streaming mode and cache folder."""
    return {"memory_budget": budget_split.volume_share(memory_budget),
            "streaming": stream_settings.get("streaming") or "auto",
            "cache_dir": stream_settings.get("cache_dir") or None}


def options_of(settings):
    """Renderer options from the scene's Voxlight settings (duck-typed, so
    this module stays free of bpy)."""
    return {"backend": getattr(settings, "backend", "auto"),
            "storage": getattr(settings, "storage", "auto"),
            "memory_budget": int(getattr(settings, "memory_budget_mib", 0)) << 20}


class VolumeEntry:
    def __init__(self, path, renderer, info, series="", options=None):
        self.options = options or {}   # storage and budget the renderer was made with
        self.path = path
        self.series = series     # DICOM: the chosen series ("" = the only one)
        self.renderer = renderer
        self.info = info
        self.mtime = _mtime(path)
        self.frame = info.get("frame", 0)            # the volume frame on the GL side
        self.pending_frame = None  # 4D: the loaded frame, cached by adopt()
        self.frame_count = info.get("frame_count", 1)
        self.last_frame = None   # stats of the last frame rendered (panel)
        self.channel_refusal = ""  # why the library refused the last frame's channels
        self.load_kwargs = load_kwargs(self.options.get("memory_budget", 0))  # other frames alike
        self._worker = None
        renderer.on_render = _count_call

    @property
    def identity(self):
        """Part of every frame key: which data this renderer holds."""
        return (self.path, self.series, self.mtime, id(self), self.frame,
                getattr(self, "label_key", None),  # label_runtime
                getattr(self, "overlay_key", None))  # overlay_runtime

    def _frame_key(self, frame):
        return (self.path, self.series, self.mtime, frame)

    def show_frame(self, frame):
        """Puts volume frame `frame` (clamped to the series) on the GL side
        unless it is already there; the frame comes from frame_cache, read
        from the file on a miss. Returns True when the data changed."""
        frame = min(max(int(frame), 0), self.frame_count - 1)
        if frame == self.frame:
            return False
        vol = frame_cache.get(self._frame_key(frame),
                              lambda: native.Volume.load(self.path, frame=frame, series=self.series or None,
                                                         **self.load_kwargs))
        self.renderer.set_volume(vol)
        self.frame = frame
        return True

    @property
    def worker(self):
        if self._worker is None:
            self._worker = Worker(self)
        return self._worker

    def busy(self):
        return self._worker is not None and self._worker.busy()

    def close(self, timeout=None):
        """Close the worker and the renderer. Returns "" when done, else why
        the renderer was left open: a render in flight did not let go within
        the bound (Worker.close), and destroying the renderer under it would
        crash Blender; a hang waits no longer than the bound."""
        if self._worker is not None:
            if not self._worker.close(timeout):
                return ("the Voxlight renderer of %s is still busy after %.0f s: a render in flight did not "
                        "stop; it is left open (its memory is freed when Blender quits)"
                        % (os.path.basename(self.path), CLOSE_WAIT_S if timeout is None else timeout))
            self._worker = None
        if self.pending_frame is not None:  # opened but never adopted
            self.pending_frame.close()
            self.pending_frame = None
        self.renderer.close()
        return ""


_entries = {}   # (absolute path, DICOM series) -> VolumeEntry
_failures = {}  # (absolute path, series) -> (mtime, message): do not retry a broken file every redraw


def is_phantom(path):
    """"phantom:NAME[:WxHxD]" names a generated volume instead of a file."""
    return str(path).startswith("phantom:")


def _key(path):
    return path if is_phantom(path) else os.path.abspath(path)


def _mtime(path):
    try:
        return os.stat(path).st_mtime
    except OSError:
        return None


def _load_file(path, lib, stop, load_progress, **kw):
    """Volume.load with the library's progress reported to
    load_progress(fraction, stage) and cancelled when stop() says so (the
    library then keeps no partial cache); None when cancelled."""
    def report(fraction, stage):
        if load_progress is not None:
            load_progress(fraction, stage)
        return stop()
    try:
        return native.Volume.load(path, lib=lib, progress=report, **kw)
    except native.VoxlightError as e:
        if e.code == ERR_CANCELLED and stop():
            return None
        raise


def open_volume(path, backend="auto", progress=None, voxel_size=None, cancelled=None, series="", frame=0,
                storage="auto", memory_budget=0, load_progress=None):
    """Load `path` (frame `frame` of a 4D file; series `series` of a DICOM
    folder; "phantom:NAME[:WxHxD]" a generated volume) into a fresh renderer
    with the given storage and memory budget, not registered yet (safe on a
    worker thread: it touches no shared state). Raises native.VoxlightError.
    progress(fraction) is called between the slow steps; cancelled() is asked
    between them too, and when it says yes everything made so far is closed
    and None returned. voxel_size (mm) is for inputs without geometry; it only
    changes info["affine"], which the importer bakes into the object, so later
    reloads need not repeat it.
    memory_budget bounds the volume and its renderer together
    (budget_split); the file is opened as stream_settings say, and the
    library's first pass over it (a .nii.gz cached brick by brick) reports
    load_progress(fraction, stage) and stops when cancelled() says so."""
    path = _key(path)
    series = series or ""
    stop = cancelled or (lambda: False)
    lib = native.load_library()
    if is_phantom(path):
        vol = native.Volume.phantom(path, lib=lib)
    else:
        vol = _load_file(path, lib, stop, load_progress, voxel_size=voxel_size, frame=frame,
                         series=series or None, **load_kwargs(memory_budget))
        if vol is None:
            return None
    keep = vol.info.get("frame_count", 1) > 1  # 4D: adopt() puts the frame shown into the cache
    renderer = entry = None
    try:
        if stop():
            return None
        if progress:
            progress(0.4)
        renderer = native.Renderer(backend=backend, lib=lib, storage=storage,
                                   memory_budget=budget_split.renderer_share(memory_budget,
                                                                             vol.info.get("streamed")))
        if progress:
            progress(0.6)
        if stop():
            return None
        renderer.set_volume(vol)
        # For the panel (32 bins, saved with the object) and for fitting presets
        # to the data (tf_fit); the library counts them for every format.
        info = dict(vol.info, histogram=vol.histogram(32),
                    histogram_fine=vol.histogram(tf_fit.HISTOGRAM_BINS),
                    distinct_ids=label_import.distinct_ids(vol.info, vol.histogram),
                    # each channel's own, for its row in the Channels panel
                    channel_histograms=[vol.histogram(32, channel=c)
                                        for c in range(vol.info.get("channel_count", 0))])
        if stop():
            return None
        entry = VolumeEntry(path, renderer, info, series, {"storage": storage, "memory_budget": memory_budget})
        renderer = None
        if keep:
            entry.pending_frame = vol
    finally:
        if entry is None or not keep:
            vol.close()  # the renderer holds its own copy on the GL side
        if renderer is not None:  # failed or cancelled before the entry took it
            renderer.close()
    if progress:
        progress(0.9)
    return entry


def adopt(entry):
    """Registers an entry from open_volume as the live one for its path and
    series; a 4D entry's first frame goes into the shared frame cache."""
    key = (entry.path, entry.series)
    frame_cache.drop(lambda k: k[0] == entry.path and k[1] == entry.series)  # a reload rereads
    vol, entry.pending_frame = entry.pending_frame, None
    if vol is not None:
        frame_cache.get(entry._frame_key(entry.frame), lambda: vol)
    old = _entries.pop(key, None)
    if old is not None and old is not entry:
        old.close()
    _entries[key] = entry
    _failures.pop(key, None)
    return entry


def load_volume(path, backend="auto", progress=None, voxel_size=None, series="", frame=0, storage="auto",
                memory_budget=0):
    """open_volume + adopt: load `path` and make it the live entry."""
    return adopt(open_volume(path, backend, progress, voxel_size, series=series, frame=frame, storage=storage,
                             memory_budget=memory_budget))


def get_entry(path, backend="auto", series="", storage="auto", memory_budget=0):
    """The live entry for `path` (and DICOM series), loading it on first use,
    when the file changed on disk or when the storage options changed.
    Raises native.VoxlightError (remembered per mtime and options)."""
    path = _key(path)
    key = (path, series or "")
    entry = _entries.get(key)
    mtime = _mtime(path)
    wanted = {"storage": storage, "memory_budget": memory_budget}
    if entry is not None and entry.mtime == mtime and entry.options == wanted:
        return entry
    failed = _failures.get(key)
    if failed is not None and failed[0] == (mtime, wanted):
        raise native.VoxlightError(failed[1])
    try:
        return load_volume(path, backend, series=series, storage=storage, memory_budget=memory_budget)
    except native.VoxlightError as e:
        _failures[key] = ((mtime, wanted), str(e))
        raise


def entry_for(path, props, scene_frame, backend="auto", storage="auto", memory_budget=0):
    """The entry of a volume object (props: Object.voxlight, read by name so
    no bpy is needed) showing the volume frame that `scene_frame` maps to."""
    entry = get_entry(path, backend, props.series, storage, memory_budget)
    entry.show_frame(frames.volume_frame(scene_frame, entry.frame_count, props.frame_mode,
                                         props.frame_offset, props.fixed_frame))
    # the object's label map (Object.voxlight_labels, label_props.py).
    labels = getattr(getattr(props, "id_data", None), "voxlight_labels", None)
    label_runtime.show(entry, getattr(labels, "active_path", "") if labels is not None else "")
    return entry


def find_entry(path, series=""):
    """The live entry for `path` (and series) or None; never loads."""
    return _entries.get((_key(path), series or ""))


def last_failure(path, series=""):
    f = _failures.get((_key(path), series or ""))
    return f[1] if f else ""


def drawing_channels(entry, params, draw):
    """draw(params), for a frame that may draw a multi-channel volume's
    channels. The add-on checks its settings before a frame
    (channel_plan.conflict), but the library has the last word (a budget
    its pools do not fit, a setting the add-on's rules missed). A frame whose
    channels the library refuses is drawn again with the scalar alone, and
    the refusal is kept for the panel (channel_refusal): a frame, never an
    error or a black image."""
    if not params.channel_count:
        return draw(params)
    try:
        out = draw(params)
    except native.VoxlightError as e:
        entry.channel_refusal = str(e)
        params.channel_count = 0
        params.channels = None
        return draw(params)
    entry.channel_refusal = ""
    return out


def channel_refusal(entry):
    """Why the library refused the channels of entry's last frame ("")."""
    return getattr(entry, "channel_refusal", "") if entry is not None else ""


def render(entry, params, kind="render"):
    """A synchronous frame: one library call, counted."""
    t = time.perf_counter()
    rgba, depth = drawing_channels(entry, params, entry.renderer.render)
    stats = entry.renderer.stats()
    entry.last_frame = dict(stats, width=params.width, height=params.height, kind=kind,
                            calls=1, seconds=time.perf_counter() - t)
    _count(frames=1)
    return rgba, depth


def render_rect(entry, params, rect, kind="interactive"):
    """A synchronous frame of which only the pixel rectangle `rect` (the
    volume's footprint) is rendered, in one library call; counted."""
    res = drawing_channels(entry, params, lambda p: entry.renderer.render_tiled(
        p, rect=rect, rows=params.height or 512))
    entry.last_frame = dict(res[2], width=params.width, height=params.height, kind=kind)
    _count(frames=1)
    return res


def busy():
    """True while any worker has a frame queued or in flight."""
    return any(e.busy() for e in _entries.values())


def release_all():
    """Close every renderer and its worker (unregister, exit). Returns the
    messages of those left open (VolumeEntry.close), for the caller to show."""
    left = [m for m in (entry.close() for entry in _entries.values()) if m]
    _entries.clear()
    _failures.clear()
    frame_cache.clear()
    return left


atexit.register(release_all)
