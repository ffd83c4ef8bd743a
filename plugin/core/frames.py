"""Time series (4D volumes: fMRI runs, cardiac phases) in the add-on: which
volume frame a scene frame shows, and an LRU cache of loaded frames bounded
by bytes, so stepping back and forth through a sequence does not re-read the
file while memory stays within a budget. No bpy: tested in plain Python
(tests/python/test_frames.py).

The library reads one frame per load (vxl_load_options.frame: a seek in .nii,
a stream through .nii.gz), so opening a 300-volume run costs one volume; the
cache holds each frame as a native.Volume (its CPU copy, info["storage_bytes"]
bytes) until evicted."""

import collections
import threading

# Modes of Object.voxlight.frame_mode.
FOLLOW_TIMELINE = "TIMELINE"  # volume frame = scene frame - offset, clamped
FIXED = "FIXED"               # always volume frame `fixed_frame`

DEFAULT_BUDGET = 1 << 30  # 1 GiB of cached frames


def volume_frame(scene_frame, frame_count, mode=FOLLOW_TIMELINE, offset=1, fixed=0):
    """The volume frame (0-based) shown at `scene_frame`. Following the
    timeline, scene frame `offset` shows volume frame 0 (Blender's timeline
    starts at 1, hence the default), and frames before or after the series
    hold its first or last volume rather than wrapping, so an animation
    longer than the series does not jump back."""
    n = max(1, int(frame_count))
    f = int(fixed) if mode == FIXED else int(scene_frame) - int(offset)
    return min(max(f, 0), n - 1)


class FrameCache:
    """Least-recently-used frames, at most `budget_bytes` in all. The frame
    just requested is always kept even if it alone exceeds the budget (it is
    what is being shown); everything older is evicted first. Thread-safe:
    the viewport worker and the main thread may both ask."""

    def __init__(self, budget_bytes=DEFAULT_BUDGET):
        self.budget_bytes = int(budget_bytes)
        self._items = collections.OrderedDict()  # key -> (volume, bytes)
        self._lock = threading.Lock()
        self.bytes = 0
        self.hits = 0
        self.misses = 0
        self.evictions = 0

    def get(self, key, load):
        """The cached value for key, or load() -> volume (with
        .info["storage_bytes"]) stored under it."""
        with self._lock:
            item = self._items.get(key)
            if item is not None:
                self._items.move_to_end(key)
                self.hits += 1
                return item[0]
        vol = load()  # outside the lock: reading a frame can take a while
        size = int(vol.info.get("storage_bytes", 0))
        with self._lock:
            self.misses += 1
            old = self._items.pop(key, None)
            if old is not None:  # loaded twice concurrently: keep one
                self.bytes -= old[1]
                _close(old[0])
            self._items[key] = (vol, size)
            self.bytes += size
            self._evict(keep=key)
        return vol

    def _evict(self, keep):
        while self.bytes > self.budget_bytes and len(self._items) > 1:
            key = next(iter(self._items))
            if key == keep:
                break
            vol, size = self._items.pop(key)
            self.bytes -= size
            self.evictions += 1
            _close(vol)

    def set_budget(self, budget_bytes):
        with self._lock:
            self.budget_bytes = int(budget_bytes)
            if self._items:
                self._evict(keep=next(reversed(self._items)))

    def keys(self):
        with self._lock:
            return list(self._items)

    def drop(self, match):
        """Evict every key for which match(key) is true (a file reloaded)."""
        with self._lock:
            for key in [k for k in self._items if match(k)]:
                vol, size = self._items.pop(key)
                self.bytes -= size
                _close(vol)

    def clear(self):
        self.drop(lambda k: True)


def _close(vol):
    close = getattr(vol, "close", None)
    if close is not None:
        close()
