"""Putting the add-on's functions into bpy.app.handlers lists and taking
them out again. A function is recognised by its name and module as well as
by identity: a reload (disable and enable, Reload Scripts) makes new
function objects, and the old ones must go too, or both would run."""


def ours(h, fn):
    """h is fn, or fn of an earlier load of the same module."""
    return h is fn or (getattr(h, "__name__", ""), getattr(h, "__module__", "")) == \
        (fn.__name__, fn.__module__)


def add(pairs):
    """pairs: ((handler list, function), ...); each added once."""
    for lst, fn in pairs:
        if not any(ours(h, fn) for h in lst):
            lst.append(fn)


def remove(pairs):
    for lst, fn in pairs:
        for h in [h for h in lst if ours(h, fn)]:
            lst.remove(h)
