"""F12, animation and `blender -b` renders: the handlers below render the
scene's volumes with the scene camera at the render resolution (render_pre
arms, the pipeline's own frame_change_post renders), write them into a
float Image, and the compositor (compositor.py) lays that image over the
engine's output before the user's own compositing nodes (or, with "Volume
as Separate Layer", fills one image per pass for the user to wire). Works in background mode, where gpu drawing and draw
handlers are unavailable, because the library renders on its own context.
"""

import bpy
import numpy as np
from bpy.app.handlers import persistent

from . import app_handlers, compositor, id_writes, offline, render_setup, scene_shadows
from .core import native

last_error = ""


_pending = False  # a render job is between render_pre and its compositing


def _prepare(scene, clear):
    """render_setup.prepare on this (often the render job's) thread, retried
    while Blender refuses writes (id_writes.py). False, with last_error
    set, when it cannot: the render then stays as the engine made it."""
    global last_error
    try:
        id_writes.retrying(render_setup.prepare, scene, clear)
        return True
    except AttributeError as e:
        if not id_writes.refused(e):
            raise
        last_error = "Blender refused to set up the compositor for the volume: %s" % e
        print("Voxlight: render failed: %s" % last_error)
        _show_nothing(scene)
        return False


def _show_nothing(scene, shadows=False):
    """No volume to lay over the render; shadows=False: no volume shadows
    either (a failed frame), else the shadow images written stay. Only
    pixels change (see compositor.py for why not the nodes)."""
    compositor.clear_passes(scene)
    if not shadows:
        scene_shadows.clear_render(scene)


@persistent
def on_render_init(scene, *args):
    """Nodes must exist before the pipeline decides whether to composite."""
    if render_setup.wanted(scene):
        _prepare(scene, clear=False)


@persistent
def on_render_pre(scene, *args):
    """Before the frame is evaluated: the nodes ready (render_setup.py),
    and images that hold nothing, so a frame that writes no pixels (hidden,
    empty, out of view, failed) leaves the render exactly as it is, and
    nothing of the previous frame shows."""
    global _pending
    _pending = False
    ready = _prepare(scene, clear=True)  # with no volume: empties the images, mutes the Alpha Over
    _pending = ready and render_setup.wanted(scene)


@persistent
def on_frame_change_post(scene, depsgraph=None, *args):
    """The volume is rendered here, not in render_pre: right after
    render_pre the pipeline evaluates its own depsgraph for the frame being
    rendered (render visibility, animation at that frame) and announces it
    through frame_change_post. The view-layer depsgraph that render_pre
    could use lags one frame behind in animation renders."""
    global _pending
    if not _pending or depsgraph is None or depsgraph.mode != "RENDER":
        return
    _pending = False
    render_frame(scene, depsgraph)


def render_frame(scene, depsgraph):
    """Render the volumes of `depsgraph`'s frame into the images that
    on_render_pre prepared. Writes pixels only (see compositor.py)."""
    global last_error
    s = scene.voxlight
    w, h = offline.render_size(scene)
    camera = scene.camera
    frame = {}
    try:
        result = offline.render(scene, depsgraph, camera, w, h,
                                occlusion=s.render_occlusion, backend=s.backend, frame_info=frame)
        if frame:
            scene_shadows.write_render(scene, frame, w, h)
    except native.VoxlightError as e:
        last_error = str(e)
        print("Voxlight: render failed: %s" % e)
        _show_nothing(scene)
        return
    last_error = ""
    if result is None or not result[0][..., 3].any():  # nothing, or all outside the frame
        _show_nothing(scene, shadows=bool(frame))
        return
    rgba, depth = result
    if s.render_separate_layer:
        compositor.write_passes(scene, rgba, depth)
        return
    img = compositor.ensure_image(w, h)
    img.pixels.foreach_set(np.ascontiguousarray(rgba, np.float32).ravel())
    img.update()


@persistent
def on_render_end(scene, *args):
    global _pending
    _pending = False


_handlers = ((bpy.app.handlers.render_init, on_render_init),
             (bpy.app.handlers.render_pre, on_render_pre),
             (bpy.app.handlers.frame_change_post, on_frame_change_post),
             (bpy.app.handlers.render_post, on_render_end),
             (bpy.app.handlers.render_cancel, on_render_end))


def register():
    app_handlers.add(_handlers)


def unregister():
    app_handlers.remove(_handlers)
