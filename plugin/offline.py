"""Rendering volumes through a scene camera without the GPU module: used by
F12/animation renders (render_hooks.py) and the scripting API (api.py).
Blender gives Python no render depth, so occlusion comes from rasterising
the scene's meshes in numpy (zbuffer.py) and passing that as scene_depth.
"""

import bpy
import numpy as np

from . import params
from .core import native, runtime, scene_geometry, volume_space, zbuffer


def render_size(scene):
    r = scene.render
    w = max(1, int(r.resolution_x * r.resolution_percentage / 100))
    h = max(1, int(r.resolution_y * r.resolution_percentage / 100))
    return w, h


def camera_matrices(camera, depsgraph, width, height, scene=None):
    """(view, proj) numpy matrices of a camera object for an image of
    width x height, honouring the scene's pixel aspect."""
    aspx = aspy = 1.0
    if scene is not None:
        aspx, aspy = scene.render.pixel_aspect_x, scene.render.pixel_aspect_y
    cam = camera.evaluated_get(depsgraph)
    loc, rot, _scale = cam.matrix_world.decompose()
    # Camera scale must not scale view distances: Blender's renderers ignore it too.
    cam_world = np.eye(4)
    cam_world[:3, :3] = np.array(rot.to_matrix())
    cam_world[:3, 3] = np.array(loc)
    view = np.linalg.inv(cam_world)
    proj = np.array(cam.calc_matrix_camera(depsgraph, x=width, y=height,
                                           scale_x=aspx, scale_y=aspy))
    return view, proj


def volume_instances(depsgraph, only=None, for_render=True):
    """(evaluated object, world matrix) of every Voxlight volume in the
    evaluated scene (animated properties and matrices included)."""
    out = []
    for inst in depsgraph.object_instances:
        ob = inst.object
        if ob.type not in volume_space.VOLUME_TYPES or not ob.voxlight.is_volume:
            continue
        if only is not None and ob.original not in only:
            continue
        if for_render and ob.original.hide_render:
            continue
        out.append((ob, np.array(inst.matrix_world, np.float64)))
    return out


def composite_layers(layers):
    """Front-to-back 'over' of several premultiplied (rgba, depth) layers,
    ordered per pixel by their depth."""
    if len(layers) == 1:
        return layers[0]
    rgba = np.stack([l[0] for l in layers])
    depth = np.stack([l[1] for l in layers])
    order = np.argsort(depth, axis=0)
    rgba = np.take_along_axis(rgba, order[..., None], axis=0)
    out = np.zeros_like(rgba[0])
    for layer in rgba:
        out += layer * (1.0 - out[..., 3:4])
    return out, depth.min(axis=0)


def render(scene, depsgraph, camera, width, height, only=None, occlusion=True,
           for_render=True, backend="auto"):
    """Premultiplied RGBA (height, width, 4) and depth of the scene's
    volumes (or of the objects in `only`). camera None = the library's
    default camera framing the volume. Returns None when there is nothing."""
    vols = volume_instances(depsgraph, only, for_render)
    if not vols:
        return None
    view = proj = None
    if camera is not None:
        view, proj = camera_matrices(camera, depsgraph, width, height, scene)
        # Volumes outside the camera's frustum cost nothing: no library call
        # (and no z-buffer when none is left).
        vols = [(ob, mw) for ob, mw in vols if not volume_space.outside_frustum(
            mw @ np.array(ob.voxlight.voxel_to_local, np.float64).reshape(4, 4).T,
            tuple(ob.voxlight.dims), view, proj)]
        if not vols:
            return (np.zeros((height, width, 4), np.float32),
                    np.full((height, width), np.inf, np.float32))
    zbuf = None
    if occlusion and camera is not None:
        zbuf = zbuffer.rasterize(scene_geometry.triangles(depsgraph, for_render),
                                 view, proj, width, height)
    lights = params.scene_lights(scene, depsgraph, for_render)
    layers = []
    for ob, mw in vols:
        opts = dict(runtime.options_of(scene.voxlight), backend=backend)
        entry = runtime.entry_for(bpy.path.abspath(ob.voxlight.filepath), ob.voxlight,
                                  scene.frame_current, **opts)
        v2l = np.array(ob.voxlight.voxel_to_local, np.float64).reshape(4, 4).T
        p = native.make_params(width=width, height=height, view=view, proj=proj,
                               model=mw @ v2l, scene_depth=zbuf, lights=lights,
                               **params.look_kwargs(ob.voxlight))
        layers.append(runtime.render(entry, p))
    return composite_layers(layers)
