"""The add-on's live library objects: one native Renderer per volume file,
shared by every object, viewport and render that shows that file.

Kept apart from bpy data because the handles are not saveable; they are
rebuilt lazily from Object.voxlight.filepath after a file is reopened.
"""

import os

from . import native


class VolumeEntry:
    def __init__(self, path, renderer, info):
        self.path = path
        self.renderer = renderer
        self.info = info
        self.mtime = _mtime(path)


_entries = {}   # absolute path -> VolumeEntry
_failures = {}  # absolute path -> (mtime, message): do not retry a broken file every redraw
render_count = 0  # incremented per library render; tests use it to count re-renders


def _mtime(path):
    try:
        return os.stat(path).st_mtime
    except OSError:
        return None


def load_volume(path, backend="auto", progress=None):
    """Load `path` into a fresh renderer. Raises native.VoxlightError.
    progress(fraction) is called between the slow steps."""
    path = os.path.abspath(path)
    lib = native.load_library()
    vol = native.Volume.load(path, lib=lib)
    if progress:
        progress(0.4)
    try:
        renderer = native.Renderer(backend=backend, lib=lib)
        if progress:
            progress(0.6)
        try:
            renderer.set_volume(vol)
        except Exception:
            renderer.close()
            raise
        info = vol.info
    finally:
        vol.close()  # the renderer holds its own copy on the GL side
    if progress:
        progress(0.9)
    entry = VolumeEntry(path, renderer, info)
    old = _entries.pop(path, None)
    if old is not None:
        old.renderer.close()
    _entries[path] = entry
    _failures.pop(path, None)
    return entry


def get_entry(path, backend="auto"):
    """The live entry for `path`, loading it on first use or when the file
    changed on disk. Raises native.VoxlightError (remembered per mtime)."""
    path = os.path.abspath(path)
    entry = _entries.get(path)
    mtime = _mtime(path)
    if entry is not None and entry.mtime == mtime:
        return entry
    failed = _failures.get(path)
    if failed is not None and failed[0] == mtime:
        raise native.VoxlightError(failed[1])
    try:
        return load_volume(path, backend)
    except native.VoxlightError as e:
        _failures[path] = (mtime, str(e))
        raise


def last_failure(path):
    f = _failures.get(os.path.abspath(path))
    return f[1] if f else ""


def render(entry, params):
    """All library renders go through here so they can be counted."""
    global render_count
    render_count += 1
    return entry.renderer.render(params)


def release_all():
    """Close every renderer (unregister, new file)."""
    for entry in _entries.values():
        entry.renderer.close()
    _entries.clear()
    _failures.clear()
