"""Scripting API, re-exported as voxlight.render_volume."""

import os

import bpy
import numpy as np

from . import offline
from .core import native


def render_volume(obj, camera=None, resolution=None, filepath=None, occlusion=True,
                  scene=None):
    """Render one Voxlight volume object and return premultiplied RGBA as a
    numpy float32 array of shape (height, width, 4), row 0 = bottom (the
    order of Blender's Image.pixels).

    camera: a camera object; default the scene camera, or the library's
    default camera framing the volume when the scene has none.
    resolution: (width, height); default the scene's render size
    (resolution percentage applied). Pixel aspect comes from the scene.
    filepath: also write the image (.png straight alpha, .exr premultiplied).
    occlusion: stop rays at the scene's meshes (rasterised in numpy).
    """
    if obj is None or not obj.voxlight.is_volume:
        raise ValueError("render_volume needs a Voxlight volume object")
    scene = scene or bpy.context.scene
    camera = camera if camera is not None else scene.camera
    if camera is not None and camera.type != "CAMERA":
        raise ValueError("%s is not a camera" % camera.name)
    w, h = resolution if resolution is not None else offline.render_size(scene)
    depsgraph = bpy.context.evaluated_depsgraph_get()
    result = offline.render(scene, depsgraph, camera, int(w), int(h), only={obj},
                            occlusion=occlusion, for_render=False,
                            backend=scene.voxlight.backend)
    if result is None:
        raise ValueError("%s is not in the evaluated scene (hidden or excluded?)" % obj.name)
    rgba = np.ascontiguousarray(result[0], np.float32)
    if filepath:
        native.load_library().write_image(bpy.path.abspath(os.fspath(filepath)), rgba,
                                          result[1])
    return rgba
