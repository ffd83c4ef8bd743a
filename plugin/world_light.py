"""The scene's World as the volume's environment light, on the Blender side:
what core/world_light.py reads of the World, with the image's downsampled
pixels cached per image (reading a 4k HDRI's pixels takes longer than a
frame), and a depsgraph handler that drops the cache and redraws the
viewport when the World, its node tree or an image changes."""

import bpy
from bpy.app.handlers import persistent

from . import app_handlers
from .core import world_light

_images = {}  # image name -> its downsampled map


def _cached_rgb(image):
    # A reload or a paint stroke is an image update (the handler below drops
    # the cache); is_dirty catches a script's first pixel edit too.
    key = (image.name_full, tuple(image.size), image.filepath_raw, image.is_dirty)
    hit = _images.get(image.name_full)
    if hit is not None and hit[0] == key:
        return hit[1]
    rgb = world_light.image_rgb(image)
    if rgb is not None:
        rgb = world_light.downsample(rgb)
    _images[image.name_full] = (key, rgb)
    return rgb


def scene_environment(scene):
    """The scene World's light (core/world_light.Environment) or None:
    "World Light" off, or "Scene Lights" off (the headlight alone, as before
    the World lit volumes)."""
    if not (scene.voxlight.use_scene_lights and scene.voxlight.use_world_light):
        return None
    return world_light.world_environment(scene.world, _cached_rgb)


@persistent
def _on_depsgraph_update(scene, depsgraph=None, *args):
    if depsgraph is None:
        return
    if depsgraph.id_type_updated("IMAGE"):
        _images.clear()
    if depsgraph.id_type_updated("WORLD") or depsgraph.id_type_updated("IMAGE"):
        from .properties import tag_redraw
        tag_redraw()


def register():
    app_handlers.add(((bpy.app.handlers.depsgraph_update_post, _on_depsgraph_update),))


def unregister():
    app_handlers.remove(((bpy.app.handlers.depsgraph_update_post, _on_depsgraph_update),))
    _images.clear()
