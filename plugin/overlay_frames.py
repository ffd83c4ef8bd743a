"""Overlays in the frames the viewport and F12 render.

For the visible volume objects of one draw, fuse() says which are bases and
which overlays each base draws (core/overlay_runtime.plan over
overlay_props.listed); the overlays are then not drawn on their own. Before
a base renders, prepare() puts its overlays' files on its entry's renderer
(re-uploading only a slot whose source changed) and builds make_params'
`overlays`: per overlay its slot, its own transfer function, window,
preset and opacity (its own Object.voxlight, evaluated, so animation
counts), its blend, shading and interpolation (overlay_props) and its model
= its world matrix times its voxel -> local matrix, built as the base's is
(params.model_matrix). The viewport keeps the result per base object for
its frames (current()), together with the overlays' boxes, so the pixels a
frame renders cover the overlays too (screen_rect, planar_range)."""

import bpy
import numpy as np

from . import label_props, params
from .core import frames, overlay_runtime, volume_space
from .overlay_props import listed

_current = {}    # base object name -> Prepared (viewport frames)
problems = {}    # base object name -> [message, ...] of its last prepare (panel)


class Prepared:
    """What one base draws with: make_params' overlay dicts and the
    overlays' (model, dims) boxes."""

    def __init__(self, overlays=(), boxes=()):
        self.overlays = list(overlays)
        self.boxes = list(boxes)


def fuse(objects, evaluated=None):
    """[(base, [overlay, ...]), ...] for `objects` (visible volume objects,
    original or evaluated). evaluated(original) -> the object to hand back
    (default: the one given); the plan itself is made on the originals."""
    objs = list(objects)
    by_original = {o.original: o for o in objs}
    plan = overlay_runtime.plan(list(by_original), listed)
    back = evaluated or (lambda o: by_original[o])
    return [(back(b), [back(o) for o in ovs]) for b, ovs in plan]


def why_not(props):
    """Why a base cannot draw overlays now ("" when it can): the library
    fuses them in the DVR mode only, not with labels drawn as surfaces."""
    if props.render_mode != "dvr":
        return "overlays are drawn in the DVR render mode only"
    labels = label_props.look_kwargs(props).get("labels")
    if labels is not None and labels[0] == "surface":
        return "overlays are not drawn with labels in Surface mode"
    return ""


def _style(slot, ov, model):
    look = params.look_kwargs(ov.voxlight)
    s = ov.voxlight_overlays
    return dict(slot=slot, blend=s.blend, interpolation=s.interpolation, preset=look["preset"],
                tf_rgba=look["tf_rgba"], window=look["window"],
                opacity_scale=look["opacity_scale"] * s.opacity,
                shading=bool(s.shading and look["shading"]), model=model)


def prepare(entry, base, overlays, scene_frame, models=None):
    """Puts the overlays (evaluated objects; models: their voxel -> world
    matrices, default from their own matrix_world) of `base` on its entry and
    returns a Prepared. A base that cannot draw overlays, and overlays whose
    file fails to load or whose opacity is 0, are left out (problems[base])."""
    overlays = list(overlays)
    name = base.name
    notes = []
    if overlays and why_not(base.voxlight):
        notes.append(why_not(base.voxlight))
        overlays = []
    if not overlays:
        problems[name] = notes
        _current[name] = Prepared()
        return _current[name]
    if models is None:
        models = [params.model_matrix(o) for o in overlays]
    sources = []
    for o in overlays:
        p = o.voxlight
        path = bpy.path.abspath(p.filepath)  # as runtime.entry_for's callers (phantom: stays)
        frame = frames.volume_frame(scene_frame, p.frame_count, p.frame_mode, p.frame_offset, p.fixed_frame)
        sources.append((path, p.series, frame))
    errors = overlay_runtime.show(entry, sources)
    dicts, boxes = [], []
    for slot, (o, model, err) in enumerate(zip(overlays, models, errors)):
        if err:
            notes.append("%s: %s" % (o.name, err))
            continue
        style = _style(slot, o, np.asarray(model, np.float64))
        if not style["opacity_scale"] > 0:  # hidden (0 would mean "1" to the library)
            continue
        dicts.append(style)
        boxes.append((np.asarray(model, np.float64), tuple(o.voxlight.dims)))
    problems[name] = notes
    _current[name] = Prepared(dicts, boxes)
    return _current[name]


def current(name):
    """The Prepared of the base object named `name` from its last prepare."""
    return _current.get(name) or Prepared()


def outside_frustum(model, dims, prepared, view, proj):
    """Whether the base's box and every overlay's lie outside the frustum."""
    boxes = [(model, dims)] + list(prepared.boxes)
    return all(volume_space.outside_frustum(m, d, view, proj) for m, d in boxes)


def screen_rect(model, dims, prepared, view, proj, w, h):
    """The pixels whose rays can meet the base or one of its overlays."""
    rects = [volume_space.screen_rect(m, d, view, proj, w, h)
             for m, d in [(model, dims)] + list(prepared.boxes)]
    rects = [r for r in rects if r is not None]
    if not rects:
        return None
    return (min(r[0] for r in rects), min(r[1] for r in rects),
            max(r[2] for r in rects), max(r[3] for r in rects))


def planar_range(model, dims, prepared, view):
    ranges = [volume_space.planar_range(m, d, view) for m, d in [(model, dims)] + list(prepared.boxes)]
    return min(r[0] for r in ranges), max(r[1] for r in ranges)


def forget():
    """After a file load: no stale objects' results."""
    _current.clear()
    problems.clear()



# ------------------------------------------------------------ F12 (offline)

def _instance_model(ob, mw):
    return np.asarray(mw, np.float64) @ np.array(ob.voxlight.voxel_to_local, np.float64).reshape(4, 4).T


def fuse_instances(everything, vols):
    """F12: `everything` and `vols` are (evaluated object, world matrix)
    lists, all volume instances and those asked for. Returns (vols less the
    overlays drawn inside a base, {base original: [(overlay, matrix)]}). An
    object asked for whose base is not is drawn on its own."""
    mws = {ob.original: (ob, mw) for ob, mw in everything}
    plan = overlay_runtime.plan(list(mws), listed)
    fused = {b: [mws[o] for o in ovs] for b, ovs in plan}
    wanted = {ob.original for ob, _mw in vols}
    inside = {o for b, ovs in plan if b in wanted for o in ovs}
    out = [(ob, mw) for ob, mw in vols if ob.original not in inside]
    return out, {b: ovs for b, ovs in fused.items() if b in wanted}


def instances_outside(overlays, view, proj):
    return all(volume_space.outside_frustum(_instance_model(o, mw), tuple(o.voxlight.dims), view, proj)
               for o, mw in overlays)


def render_kwargs(entry, base, overlays, scene_frame):
    """F12's make_params keyword arguments for the overlays of `base`:
    (overlay, world matrix) pairs from fuse_instances."""
    overlays = list(overlays)
    got = prepare(entry, base, [o for o, _mw in overlays], scene_frame,
                  models=[_instance_model(o, mw) for o, mw in overlays])
    return {"overlays": got.overlays} if got.overlays else {}
