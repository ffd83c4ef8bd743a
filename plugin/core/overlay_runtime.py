"""Overlay volumes on a renderer, and which volume objects are
drawn fused into which. No bpy here (tests/python/test_overlay_runtime.py).

A base volume object draws up to MAX_OVERLAYS other volume objects in its
own ray march: their files go into the overlay slots of the base's entry
renderer (vxl_renderer_set_overlay) before the base renders, and the frame's
params list them (params.overlays). The entry remembers what each slot
holds (entry.overlay_key, part of entry.identity), so a slot is re-uploaded
only when its source (file, series, modification time, volume frame)
changes, and a cached frame with other overlays is never reused. A file
that cannot be loaded is remembered per modification time and reported;
the base then draws without that overlay rather than failing.

plan() decides, for the visible volume objects of one draw, which are bases
and which are drawn inside a base (and so not separately, or they would
show twice)."""

import os

from . import native
from .runtime import _mtime, is_phantom

_failures = {}   # (absolute path, series, frame) -> (mtime, message)


def source_key(path, series="", frame=0):
    """What a slot holds: (path, series, volume frame, mtime)."""
    if not is_phantom(path):
        path = os.path.abspath(path)
    return (path, series or "", int(frame), None if is_phantom(path) else _mtime(path))


def failure(path, series="", frame=0):
    """The message of the last failed load of that source, or "" (also ""
    once the file changed since)."""
    key = source_key(path, series, frame)
    f = _failures.get(key[:3])
    return f[1] if f is not None and f[0] == key[3] else ""


def _load(key, lib):
    path, series, frame, _mt = key
    if is_phantom(path):
        return native.Volume.phantom(path, lib=lib)
    return native.Volume.load(path, frame=frame, series=series or None, lib=lib)


def show(entry, sources, lib=None):
    """Puts `sources` (one (path, series, volume frame) per slot, or None
    for an empty slot; at most MAX_OVERLAYS) on the entry's renderer,
    uploading only the slots whose source changed. Returns one message per
    slot: "" when the slot now holds its source (or is meant empty), else
    why not (that slot is then empty and must not be drawn)."""
    sources = list(sources)[:native.MAX_OVERLAYS]
    sources += [None] * (native.MAX_OVERLAYS - len(sources))
    have = list(getattr(entry, "overlay_key", None) or (None,) * native.MAX_OVERLAYS)
    errors = []
    for slot, src in enumerate(sources):
        want = source_key(*src) if src is not None else None
        err = failure(*src) if src is not None else ""
        if err:
            want = None
        if want != have[slot]:
            if want is not None:
                try:
                    vol = _load(want, lib)
                    try:
                        entry.renderer.set_overlay(slot, vol)
                    finally:
                        vol.close()  # the renderer keeps its own copy
                    _failures.pop(want[:3], None)
                except (native.VoxlightError, OSError) as e:
                    err = str(e)
                    _failures[want[:3]] = (want[3], err)
                    want = None
            if want is None and have[slot] is not None:
                entry.renderer.set_overlay(slot, None)
            have[slot] = want
        errors.append(err)
    entry.overlay_key = tuple(have) if any(k is not None for k in have) else None
    return errors


def plan(objects, listed):
    """Which of `objects` (the visible volume objects of a draw, in order)
    are drawn as bases, and with which of the others fused in.

    listed(obj) gives the objects obj wants as overlays, in slot order.
    An object listed by a base that draws is drawn inside it, not on its
    own; only visible objects (those in `objects`) are fused. An object
    listed by another that is itself drawn inside a third (a chain), or by
    one it lists itself (a cycle), is drawn on its own: every object shows
    exactly once. Returns [(base, [overlays...]), ...] in the order of
    `objects`, each with at most MAX_OVERLAYS overlays."""
    objects = list(objects)
    present = set(objects)
    wants = {o: [x for x in listed(o) if x in present and x is not o] for o in objects}
    inside = set()
    for o in objects:
        inside.update(wants[o])
    # Objects nobody lists are bases. A listed one is fused into the first
    # base that lists it; one whose listers are all fused themselves is a base.
    out, taken, bases = [], set(), [o for o in objects if o not in inside]
    for o in objects:
        if o in inside and not any(o in wants[b] for b in bases if b is not o):
            bases.append(o)
    order = {o: i for i, o in enumerate(objects)}
    for b in sorted(bases, key=order.get):
        mine = [x for x in wants[b] if x not in taken and x not in bases][:native.MAX_OVERLAYS]
        taken.update(mine)
        out.append((b, mine))
    # Listed only by bases that had no room left: drawn on their own.
    for o in objects:
        if o in inside and o not in taken and o not in bases:
            out.append((o, []))
    out.sort(key=lambda bo: order[bo[0]])
    return out
