"""Writing Blender data from code that may run on the render thread.

Blender refuses attribute writes to data-blocks ("Writing to ID classes in
this context is not allowed") while any Python panel, header or poll
function runs, and the flag that says so is one for the whole process: an
F12 in the GUI runs render_init, render_pre and frame_change_post on the
render job's thread, and a write made there fails whenever the main thread
happens to be drawing a panel at that moment (and, while Cycles' engine is
created, for a while after). Function calls (nodes.new, links.new,
pixels.foreach_set, Image.scale) are not refused, only attribute writes.

So the render thread should have nothing to write: render_setup.py makes
the scene ready on the main thread, every write below is made only when it
changes the value, and what still must be written on the render thread is
retried while Blender refuses it (each retry lets the main thread finish
its draw).
"""

import threading
import time

RETRY_S = 5.0   # a panel draws in milliseconds; a refusal this long means a stuck UI
RETRY_STEP_S = 0.01


def assign(obj, attr, value):
    """obj.attr = value, only when it differs: an unchanged value is never
    written, so code that runs again on a ready scene writes nothing."""
    if getattr(obj, attr) != value:
        setattr(obj, attr, value)


def refused(exc):
    """Whether an exception is Blender refusing a write in this context."""
    return isinstance(exc, AttributeError) and "not allowed" in str(exc)


def on_main_thread():
    return threading.current_thread() is threading.main_thread()


def retrying(fn, *args):
    """fn(*args), again while Blender refuses its writes: on the render
    thread for up to RETRY_S (fn must be safe to run again after a partial
    run: it writes only what differs). On the main thread a refusal cannot
    end while we wait, so it is raised at once."""
    deadline = time.monotonic() + RETRY_S
    while True:
        try:
            return fn(*args)
        except AttributeError as e:
            if not refused(e) or on_main_thread() or time.monotonic() > deadline:
                raise
        time.sleep(RETRY_STEP_S)
