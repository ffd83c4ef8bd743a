"""Rendering volumes through a scene camera without the GPU module: used by
F12/animation renders (render_hooks.py) and the scripting API (api.py).
Blender gives Python no render depth, so occlusion comes from rasterising
the scene's meshes in numpy (zbuffer.py) and passing that as scene_depth.
"""

import bpy
import numpy as np

from . import label_props, overlay_frames, params, scene_shadows, world_light
from .core import label_runtime, native, runtime, scene_geometry, volume_space, zbuffer


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
           for_render=True, backend="auto", frame_info=None):
    """Premultiplied RGBA (height, width, 4) and depth of the scene's
    volumes (or of the objects in `only`). camera None = the library's
    default camera framing the volume. Returns None when there is nothing.
    frame_info (a dict, F12's scene shadows): filled with the scene's
    z-buffer ("depth"), what it saw ("surface": triangles, the triangle
    index per pixel, view, proj), its lights with their names ("named_lights") and,
    per volume that casts shadows (in the frame or not), its entry and
    make_params keyword arguments ("casters")."""
    vols = volume_instances(depsgraph, only, for_render)
    if not vols:
        return None
    # overlays are drawn inside their base, not on their own.
    vols, fused = overlay_frames.fuse_instances(volume_instances(depsgraph, None, for_render), vols)
    view = proj = None
    named = scene_shadows.named_lights(depsgraph, for_render) \
        if scene.voxlight.use_scene_lights else []
    lights = [l for _n, _g, l in named]
    environment = world_light.scene_environment(scene)  # the World's light, None without one
    casters = [(ob, mw) for ob, mw in vols if ob.voxlight.cast_shadows]
    if camera is not None:
        view, proj = camera_matrices(camera, depsgraph, width, height, scene)
        # Volumes outside the camera's frustum cost nothing: no library call
        # (and no z-buffer when none is left).
        vols = [(ob, mw) for ob, mw in vols if not volume_space.outside_frustum(
            mw @ np.array(ob.voxlight.voxel_to_local, np.float64).reshape(4, 4).T,
            tuple(ob.voxlight.dims), view, proj) or not overlay_frames.instances_outside(
            fused.get(ob.original, ()), view, proj)]
    # A volume outside the frame may still shadow what is in it.
    want_shadows = bool(frame_info is not None and camera is not None and casters and lights)
    zbuf = ids = tris = None
    if camera is not None and (occlusion and vols or want_shadows):
        tris = scene_geometry.triangles(depsgraph, for_render)
        ids = np.full((height, width), -1, np.int64) if want_shadows else None
        zbuf = zbuffer.rasterize(tris, view, proj, width, height, ids=ids)
    opts = dict(runtime.options_of(scene.voxlight), backend=backend)

    def volume_kwargs(ob, mw):
        entry = runtime.entry_for(bpy.path.abspath(ob.voxlight.filepath), ob.voxlight,
                                  scene.frame_current, **opts)
        v2l = np.array(ob.voxlight.voxel_to_local, np.float64).reshape(4, 4).T
        look = params.look_kwargs(ob.voxlight)
        return entry, dict(view=view, proj=proj, model=mw @ v2l, lights=lights,
                           environment=params.environment_for(look, environment), **look)

    if frame_info is not None:
        frame_info.update(depth=zbuf, named_lights=named if want_shadows else [],
                          surface=(tris, ids, view, proj) if want_shadows else None,
                          casters=[(entry, kw) for entry, kw, ob in (
                              volume_kwargs(ob, mw) + (ob,) for ob, mw in casters)
                              if not label_runtime.shows_nothing(
                                  kw.get("labels"), label_props.own_label_ids(ob, entry))]
                          if want_shadows else [])
    if not vols:
        return (np.zeros((height, width, 4), np.float32),
                np.full((height, width), np.inf, np.float32))
    shadows = None
    if any(scene_shadows.receives(ob.voxlight) for ob, _mw in vols):
        shadows = scene_shadows.occluders(depsgraph, for_render)
    layers = []
    for ob, mw in vols:
        entry, kw = volume_kwargs(ob, mw)
        kw.update(overlay_frames.render_kwargs(entry, ob, fused.get(ob.original, ()), scene.frame_current))
        if shadows is not None and scene_shadows.receives(ob.voxlight):
            kw["scene_shadows"] = shadows
        p = native.make_params(width=width, height=height,
                               scene_depth=zbuf if occlusion else None, **kw)
        layers.append(runtime.render(entry, p))
    return composite_layers(layers)
