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

from . import native

_lock = threading.Lock()
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
                    result = self.entry.renderer.render_tiled(
                        job.params, rect=job.rect, target_seconds=self.target_seconds,
                        should_stop=lambda: job.cancelled or self._stop)
                except Exception as e:  # reported by the main thread
                    error = e
            with self._cond:
                self._running = None
                job.error = error
                if job.cancelled:  # went stale during its last band
                    result = None
                if result is not None:
                    job.result = result
                    self.entry.last_frame = dict(result[2], width=job.params.width,
                                                 height=job.params.height, kind="refined")
                    _count(frames=1)
                    self._finish(job)
                else:
                    self._finish(job, cancelled=error is None)

    def close(self):
        """Stop the thread; waits for the band in flight (if any)."""
        with self._cond:
            self._stop = True
            for job in self._queue.values():
                self._finish(job, cancelled=True)
            self._queue.clear()
            if self._running is not None:
                self._running.cancelled = True
            self._cond.notify_all()
        if self._thread is not threading.current_thread():
            self._thread.join()


def options_of(settings):
    """Renderer options from the scene's Voxlight settings (duck-typed, so
    this module stays free of bpy)."""
    return {"backend": getattr(settings, "backend", "auto"),
            "storage": getattr(settings, "storage", "auto"),
            "memory_budget": int(getattr(settings, "memory_budget_mib", 0)) << 20}


class VolumeEntry:
    def __init__(self, path, renderer, info, options=None):
        self.options = options or {}
        self.path = path
        self.renderer = renderer
        self.info = info
        self.mtime = _mtime(path)
        self.last_frame = None   # stats of the last frame rendered (panel)
        self._worker = None
        renderer.on_render = _count_call

    @property
    def identity(self):
        """Part of every frame key: which data this renderer holds."""
        return (self.path, self.mtime, id(self))

    @property
    def worker(self):
        if self._worker is None:
            self._worker = Worker(self)
        return self._worker

    def busy(self):
        return self._worker is not None and self._worker.busy()

    def close(self):
        if self._worker is not None:
            self._worker.close()
            self._worker = None
        self.renderer.close()


_entries = {}   # absolute path -> VolumeEntry
_failures = {}  # absolute path -> (mtime, message): do not retry a broken file every redraw


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


def load_volume(path, backend="auto", progress=None, storage="auto", memory_budget=0):
    """Load `path` into a fresh renderer. Raises native.VoxlightError.
    progress(fraction) is called between the slow steps."""
    path = _key(path)
    lib = native.load_library()
    vol = native.Volume.phantom(path, lib=lib) if is_phantom(path) else native.Volume.load(path, lib=lib)
    if progress:
        progress(0.4)
    try:
        renderer = native.Renderer(backend=backend, lib=lib, storage=storage,
                                   memory_budget=memory_budget)
        if progress:
            progress(0.6)
        try:
            renderer.set_volume(vol)
        except Exception:
            renderer.close()
            raise
        info = dict(vol.info, histogram=vol.histogram(32))  # for the panel, from any format
    finally:
        vol.close()  # the renderer holds its own copy on the GL side
    if progress:
        progress(0.9)
    entry = VolumeEntry(path, renderer, info,
                        {"storage": storage, "memory_budget": memory_budget})
    old = _entries.pop(path, None)
    if old is not None:
        old.close()
    _entries[path] = entry
    _failures.pop(path, None)
    return entry


def get_entry(path, backend="auto", storage="auto", memory_budget=0):
    """The live entry for `path`, loading it on first use or when the file
    changed on disk. Raises native.VoxlightError (remembered per mtime)."""
    path = _key(path)
    entry = _entries.get(path)
    mtime = _mtime(path)
    wanted = {"storage": storage, "memory_budget": memory_budget}
    if entry is not None and entry.mtime == mtime and entry.options == wanted:
        return entry
    failed = _failures.get(path)
    if failed is not None and failed[0] == (mtime, wanted):
        raise native.VoxlightError(failed[1])
    try:
        return load_volume(path, backend, storage=storage, memory_budget=memory_budget)
    except native.VoxlightError as e:
        _failures[path] = ((mtime, wanted), str(e))
        raise


def find_entry(path):
    """The live entry for `path` or None; never loads."""
    return _entries.get(_key(path))


def last_failure(path):
    f = _failures.get(_key(path))
    return f[1] if f else ""


def render(entry, params, kind="render"):
    """A synchronous frame: one library call, counted."""
    t = time.perf_counter()
    rgba, depth = entry.renderer.render(params)
    stats = entry.renderer.stats()
    entry.last_frame = dict(stats, width=params.width, height=params.height, kind=kind,
                            calls=1, seconds=time.perf_counter() - t)
    _count(frames=1)
    return rgba, depth


def render_rect(entry, params, rect, kind="interactive"):
    """A synchronous frame of which only the pixel rectangle `rect` (the
    volume's footprint) is rendered, in one library call; counted."""
    res = entry.renderer.render_tiled(params, rect=rect, rows=params.height or 512)
    entry.last_frame = dict(res[2], width=params.width, height=params.height, kind=kind)
    _count(frames=1)
    return res


def busy():
    """True while any worker has a frame queued or in flight."""
    return any(e.busy() for e in _entries.values())


def release_all():
    """Close every renderer and its worker (unregister, exit)."""
    for entry in _entries.values():
        entry.close()
    _entries.clear()
    _failures.clear()


atexit.register(release_all)
