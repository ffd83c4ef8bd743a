"""A volume's render mode, MatCap and cutaway as make_params
keyword arguments, read from its properties (cutaway_props.py) and the
objects they point at: clip planes from objects' local XY planes, the crop
box from a cube Empty, cutters from evaluated meshes in world space
(scene_geometry.mesh_arrays). The viewport and F12 both go through
params.look_kwargs, which calls look_kwargs here, so both cut alike.

On an evaluated volume (viewport draws, F12's depsgraph) the properties'
object pointers are the evaluated objects too, so a cut follows animated
Empties and modified meshes at the frame being rendered.

What cannot be used (a pointer left empty, a deleted object, a cutter that
is not a mesh, a plane scaled to nothing) is skipped and reported:
problems(obj) gives the messages, the panel shows them. Nothing here
raises on bad scene data."""

import bpy
import numpy as np

from . import cutaway_props
from .core import cutaway_space, scene_geometry

_problems = {}   # volume object name -> [message, ...] of its last look_kwargs
_matcaps = {}    # MatCap name -> (pixels (h, w, 4) float32, key) or None when unreadable


def problems(obj):
    """What the last params build of `obj` could not use, as messages."""
    return list(_problems.get(obj.name, ()))


def _gone(ob):
    """Whether `ob` (possibly an evaluated copy) is no longer in any scene."""
    orig = getattr(ob, "original", ob) or ob
    try:
        return len(orig.users_scene) == 0
    except ReferenceError:
        return True


def _clip_planes(props, out):
    planes = []
    for i, cp in enumerate(props.clip_planes):
        if not cp.enabled:
            continue
        if cp.object is None or _gone(cp.object):
            out.append("Clip plane %d: no object (pick an Empty)" % (i + 1))
            continue
        if len(planes) == cutaway_props.MAX_CLIP_PLANES:
            out.append("Clip plane %d: at most %d planes cut" % (i + 1, cutaway_props.MAX_CLIP_PLANES))
            continue
        try:
            planes.append((cutaway_space.clip_plane(cp.object.matrix_world), max(0.0, cp.thickness)))
        except ValueError as e:
            out.append("Clip plane %d (%s): %s" % (i + 1, cp.object.name, e))
    return planes


def _box_of(ob):
    """box -> world of a crop object: a cube Empty's cube, or any other
    object's local bounding box."""
    if ob.type == "EMPTY":
        return cutaway_space.crop_box(ob.matrix_world, ob.empty_display_size)
    corners = np.array([tuple(c) for c in ob.bound_box], np.float64)
    lo, hi = corners.min(0), corners.max(0)
    local = np.diag(list((hi - lo) / 2.0) + [1.0])
    local[:3, 3] = (hi + lo) / 2.0
    return cutaway_space.crop_box(np.array(ob.matrix_world, np.float64) @ local, 1.0)


def _cutters(props, out):
    cutters = []
    for i, c in enumerate(props.cutters):
        if not c.enabled:
            continue
        ob = c.object
        if ob is None or _gone(ob):
            out.append("Cutter %d: no object (pick a closed mesh)" % (i + 1))
            continue
        if ob.type != "MESH":
            out.append("Cutter %d: '%s' is not a mesh (%s)" % (i + 1, ob.name, ob.type.title()))
            continue
        if len(cutters) == cutaway_props.MAX_CUTTERS:
            out.append("Cutter %d: at most %d cutters cut" % (i + 1, cutaway_props.MAX_CUTTERS))
            continue
        arrays = scene_geometry.mesh_arrays(ob, ob.matrix_world)
        if arrays is None:
            out.append("Cutter %d: '%s' has no faces" % (i + 1, ob.name))
            continue
        cutters.append((arrays[0], arrays[1], c.remove_outside))
    return cutters


def cutaway_spec(props, out):
    """The volume's cutaway (a CutawaySpec), or None when nothing cuts;
    messages about what was skipped are appended to `out`."""
    planes = _clip_planes(props, out)
    box = None
    if props.crop_box is not None:
        if _gone(props.crop_box):
            out.append("Crop box: its object is no longer in the scene")
        else:
            try:
                box = _box_of(props.crop_box)
            except ValueError as e:
                out.append("Crop box (%s): %s" % (props.crop_box.name, e))
    cutters = _cutters(props, out)
    if not planes and box is None and not cutters:
        return None
    return cutaway_space.CutawaySpec(clip_planes=planes, crop_box=box, cutters=cutters,
                                     caps=props.caps)


_unreadable = {}  # MatCap name -> why it cannot be read


def matcap_pixels(name):
    """(pixels (h, w, 4) float32 linear, row 0 = bottom, key) of Blender's
    MatCap `name`, read once from its file; None when it cannot be read
    (matcap_problem says why). Blender 5.0 ships most MatCaps as multi-layer
    EXRs (diffuse and specular passes), whose pixels Python cannot read."""
    if name in _matcaps:
        return _matcaps[name]
    result = None
    _unreadable[name] = "its file cannot be read"
    path = cutaway_props.studio_matcap_path(name)
    if path:
        img = None
        try:
            img = bpy.data.images.load(path, check_existing=False)
            w, h = img.size
            if img.type == "MULTILAYER":
                _unreadable[name] = "it is a multi-layer EXR, which Python cannot read"
            elif w > 0 and h > 0 and len(img.pixels) == w * h * 4:
                px = np.empty(w * h * 4, np.float32)
                img.pixels.foreach_get(px)
                result = (px.reshape(h, w, 4), cutaway_props.matcap_number(name))
        except RuntimeError:
            result = None
        finally:
            if img is not None:
                bpy.data.images.remove(img)
    _matcaps[name] = result
    return result


def look_kwargs(props):
    """mode, matcap, matcap_key and cutaway for make_params; what was
    skipped is filed under the volume object's name for problems()."""
    out = []
    kw = dict(mode=props.render_mode, cutaway=cutaway_spec(props, out))
    name = props.matcap
    if name and name != cutaway_props.MATCAP_NONE:
        got = matcap_pixels(name)
        if got is None:
            out.append("MatCap %s: %s; shading with the material instead"
                       % (name, _unreadable.get(name, "it cannot be read")))
        else:
            kw["matcap"], kw["matcap_key"] = got
    owner = getattr(props, "id_data", None)
    if owner is not None:
        _problems[owner.name] = out
    return kw
