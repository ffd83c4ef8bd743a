"""Makes each scene ready for F12 on the main thread, before any render
starts: the compositor's Alpha Over and image nodes, the volume image at
render size, the light groups and shadow chain (scene_shadows.py), or, with
no volume to render, the Alpha Over muted and the shadows taken back.

Why ahead of time: an F12 in the GUI runs render_init and render_pre on the
render job's thread, where Blender refuses attribute writes to data whenever
a Python panel draws at that moment (id_writes.py). Every step of prepare()
writes only what differs, so on a ready scene the render thread's call
writes nothing; what a script changes just before it starts a render (no
main-thread tick between) is still written there, retried.

prepare() runs shortly after each depsgraph update (a timer coalesces a
drag's many updates, and waits while a render runs: its nodes are in use),
after a file loads, and from the render handlers (render_hooks.py).
"""

import bpy
from bpy.app.handlers import persistent

from . import app_handlers, compat, compositor, id_writes, offline, scene_shadows

DELAY_S = 0.2       # coalesces the updates of a drag into one prepare()
RENDER_WAIT_S = 0.5

_pending = set()    # names of scenes to prepare on the next timer


def volumes_present(scene):
    return any(o.voxlight.is_volume and not o.hide_render for o in scene.objects)


def wanted(scene):
    """Whether an F12 of `scene` lays a volume over the render."""
    return bool(scene.voxlight.render_enabled and scene.camera is not None
                and volumes_present(scene))


def prepare(scene, clear=False):
    """Idempotent: the nodes, images, light groups and shadow chain the
    next render of `scene` needs, or the add-on's part muted and taken back
    when it shows no volume. clear=True also empties the images (the start
    of a frame: nothing of the previous one may show)."""
    if not wanted(scene):
        if clear:
            compositor.clear_passes(scene)
            scene_shadows.clear_render(scene)
        compositor.mute(scene)
        scene_shadows.revert(scene)
        return
    w, h = offline.render_size(scene)
    if scene.voxlight.render_separate_layer:
        compositor.ensure_pass_nodes(scene, w, h)
    else:
        compositor.ensure_nodes(scene, compositor.ensure_image(w, h))
    if clear:
        compositor.clear_passes(scene)
    scene_shadows.prepare_render(scene, w, h, clear=clear)


def _tracked(scene):
    """Scenes worth a prepare(): with volumes, or with the add-on's nodes
    (to mute them once the volumes are gone)."""
    if volumes_present(scene):
        return True
    tree = compat.compositor_tree(scene, create=False)
    return tree is not None and compositor.NODE_OVER in tree.nodes


def _run_pending():
    if bpy.app.is_job_running("RENDER"):
        return RENDER_WAIT_S
    names = sorted(_pending)
    _pending.clear()
    for name in names:
        scene = bpy.data.scenes.get(name)
        if scene is None or not _tracked(scene):
            continue
        try:
            prepare(scene)
        except AttributeError as e:
            if not id_writes.refused(e):
                raise
            # Blender still refuses writes (a render thread's engine is
            # being made): again on the next tick.
            _pending.add(name)
    return DELAY_S if _pending else None


def schedule(scene):
    """prepare(scene) on the main thread shortly (only the main thread
    may register timers)."""
    if not id_writes.on_main_thread():
        return
    _pending.add(scene.name)
    if not bpy.app.timers.is_registered(_run_pending):
        bpy.app.timers.register(_run_pending, first_interval=DELAY_S)


@persistent
def _on_depsgraph_update(scene, depsgraph=None, *args):
    schedule(scene)


@persistent
def _on_load_post(*args):
    for scene in bpy.data.scenes:
        schedule(scene)


_handlers = ((bpy.app.handlers.depsgraph_update_post, _on_depsgraph_update),
             (bpy.app.handlers.load_post, _on_load_post))


def register():
    app_handlers.add(_handlers)


def unregister():
    app_handlers.remove(_handlers)
    _pending.clear()
    if bpy.app.timers.is_registered(_run_pending):
        bpy.app.timers.unregister(_run_pending)
