"""The label volume on a renderer. A volume object with a label
map has its label file put on its entry's renderer
(vxl_renderer_set_labels) before the entry renders; the entry remembers
which (entry.label_key, part of entry.identity, so frames with other labels
never reuse a cached one). A label file that cannot be loaded is
remembered per modification time and reported by the panel; the volume then
renders without labels rather than failing. No bpy here."""

import os

from . import native

_failures = {}   # absolute path -> (mtime, message)


def _mtime(path):
    try:
        return os.stat(path).st_mtime
    except OSError:
        return None


def failure(path):
    """The message of the last failed load of `path`, or "" (also "" once
    the file changed since)."""
    if not path:
        return ""
    f = _failures.get(os.path.abspath(path))
    return f[1] if f is not None and f[0] == _mtime(path) else ""


def usable(path):
    """Whether frames should ask for labels from `path`."""
    return bool(path) and not failure(path)


def show(entry, path, lib=None):
    """Puts the labels of `path` ("" = none) on the entry's renderer unless
    they are there already. Returns "" or the failure's message."""
    want = None
    if path:
        path = os.path.abspath(path)
        want = (path, _mtime(path))
    if getattr(entry, "label_key", None) == want:
        return ""
    if want is not None and failure(path):
        want = None
        if getattr(entry, "label_key", None) is None:
            return failure(path)
    error = ""
    if want is not None:
        try:
            vol = native.Volume.load(path, lib=lib)
            try:
                entry.renderer.set_labels(vol)
            finally:
                vol.close()
            _failures.pop(path, None)
        except (native.VoxlightError, OSError) as e:
            error = str(e)
            _failures[path] = (want[1], error)
            want = None
    if want is None and getattr(entry, "label_key", None) is not None:
        entry.renderer.set_labels(None)
    entry.label_key = want
    return error


def shows_nothing(labels, present=None):
    """Whether make_params' labels=(mode, [(id, rgba, visible, material), ...])
    draw nothing at all: in surface and mask mode only listed, visible labels
    with some opacity are drawn, and only those among `present` (the label
    image's distinct ids; None: unknown, any may be). The library's shadow
    volumes do not see labels, so such a volume must cast no shadow on the
    scene either: its shadow would be that of everything it hides."""
    if not labels or labels[0] not in ("surface", "mask"):
        return False
    present = None if present is None else set(present)
    return not any(visible and rgba[3] > 0.0 and (present is None or i in present)
                   for i, rgba, visible, *_rest in labels[1])
