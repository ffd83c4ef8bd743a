"""The volume in the scene's light, on the Blender side:

* receive_shadows: the scene's opaque meshes (objects whose Shadow ray
  visibility is on) go to the library as params.scene_shadows, so they
  shadow the volume (occluders());
* cast_shadows, F12: per light group a "Voxlight Shadow <group>" image
  (1 - the transmittance from each visible scene point to the group's
  lights, vxl_scene_transmittance on the F12 z-buffer) that the compositor
  chain multiplies the group's light by (prepare_render(), write_render();
  the plan is core/shadow_plan.py, the nodes compositor.py);
* cast_shadows, viewport: a multiply layer drawn under the volumes
  (viewport_layer(), scene_shadows_viewport.py).

Light groups the add-on makes are recorded on each light and taken back by
revert() when no volume casts shadows any more.
"""

import functools
import hashlib

import bpy
import numpy as np
from bpy.app.handlers import persistent

from . import app_handlers, compositor, id_writes, params
from .core import facing, light_shares
from .core import lights as _lights
from .core import native, scene_geometry, shadow_plan

_SOLID = {"MESH", "CURVE", "SURFACE", "FONT", "META"}

# Bumped by depsgraph_update_post whenever an object's geometry changed
# (edit mode, modifiers, ...): part of the occluders' key, so the key (and
# the library's shadow maps) change only when a mesh, a transform or the
# set of meshes changes, without hashing the vertices.
_geometry_version = 0
_cache = {"key": None, "value": None}

note = ""  # how the last F12 applied the volume's shadows, for the panel ("" = exactly)


# ---------------------------------------------------------------- occluders

def _casts_shadow(inst, for_render):
    orig = inst.object.original
    if for_render and orig.hide_render:
        return False
    if not for_render and not getattr(inst, "is_instance", False) and not orig.visible_get():
        return False
    return getattr(orig, "visible_shadow", True)  # Object › Visibility › Shadow (3.0+)


def _instances(depsgraph, for_render):
    return [(inst.object, np.array(inst.matrix_world, np.float64))
            for inst in depsgraph.object_instances
            if inst.object.type in _SOLID and _casts_shadow(inst, for_render)]


def occluder_key(depsgraph, for_render=True):
    """uint64 key of the occluders: which objects, their matrices, the
    geometry version and (F12, where animation may deform meshes without an
    update) the frame."""
    h = hashlib.blake2b(digest_size=8)
    h.update(repr((_geometry_version, for_render,
                   depsgraph.scene.frame_current if for_render else 0)).encode())
    for ob, mw in _instances(depsgraph, for_render):
        h.update(("%s\0%s\0" % (ob.original.name, ob.data.name if ob.data else "")).encode())
        h.update(mw.tobytes())
    return int.from_bytes(h.digest(), "little") or 1


def occluders(depsgraph, for_render=True):
    """(vertices (n, 3) float32 world, triangles (m, 3) uint32, key) of the
    scene's shadow-casting solids, or None when there are none. Rebuilt
    only when the key changes."""
    key = occluder_key(depsgraph, for_render)
    if _cache["key"] == key:
        return _cache["value"]
    verts, tris, base = [], [], 0
    for ob, mw in _instances(depsgraph, for_render):
        arrays = scene_geometry.mesh_arrays(ob, mw)
        if arrays is None:
            continue
        co, t = arrays
        verts.append(co.astype(np.float32))
        tris.append(t + base)
        base += len(co)
    value = None
    if verts:
        value = (np.ascontiguousarray(np.concatenate(verts)),
                 np.ascontiguousarray(np.concatenate(tris), np.uint32), key)
    _cache["key"], _cache["value"] = key, value
    return value


def receives(props):
    """Whether a volume is shadowed by the meshes: its switch, and a model
    with shadows (Phong has none to cut)."""
    return bool(props.receive_shadows) and props.shading_model != "phong"


_viewport = {"value": None}  # the viewport's occluders of the current draw


def refresh_viewport(depsgraph, objs):
    """Viewport draw: the occluders for the volumes in `objs` that receive
    shadows (recomputed only when their key changes), for for_viewport()."""
    _viewport["value"] = occluders(depsgraph, for_render=False) \
        if any(receives(o.voxlight) for o in objs) else None


def for_viewport(ob):
    """params.build's scene_shadows for volume `ob` in this draw."""
    return _viewport["value"] if receives(ob.voxlight) else None


@persistent
def _on_depsgraph_update(scene, depsgraph=None, *args):
    global _geometry_version
    if depsgraph is None:
        return
    for update in depsgraph.updates:
        ident = update.id
        if not update.is_updated_geometry:
            continue
        if isinstance(ident, bpy.types.Object) and ident.type in _SOLID or \
                isinstance(ident, (bpy.types.Mesh, bpy.types.Curve, bpy.types.MetaBall)):
            _geometry_version += 1
            return


# ------------------------------------------------------------------- lights

def named_lights(depsgraph, for_render):
    """[(light object name, its light group, lights.SceneLight)] in the
    order and number lights.collect gives (strongest first, at most 8)."""
    out = []
    for inst in depsgraph.object_instances:
        ob = inst.object
        if ob.type != "LIGHT" or not _lights._shown(inst, for_render):
            continue
        if ob.data.type not in ("SUN", "POINT", "SPOT", "AREA"):
            continue
        orig = ob.original
        out.append((orig.name, getattr(orig, "lightgroup", ""),
                    _lights.scene_light(ob.data.type, np.array(inst.matrix_world), ob.data)))
    out.sort(key=lambda n: -n[2].intensity * max(n[2].color))
    return out[:native.MAX_LIGHTS]


def _weight(light):
    return float(light.intensity) * float(max(light.color))


# --------------------------------------------------------------------- F12

def _casting_volumes(scene):
    return [o for o in scene.objects
            if o.voxlight.is_volume and not o.hide_render and o.voxlight.cast_shadows]


def _render_layer(scene):
    """The view layer whose passes the compositor's Render Layers reads."""
    from . import compat
    tree = compat.compositor_tree(scene, create=False)
    rls = [n for n in tree.nodes if n.bl_idname == "CompositorNodeRLayers"] if tree else []
    name = rls[0].layer if rls else ""
    return scene.view_layers.get(name) or scene.view_layers[0]


def _plan_lights(scene):
    return [shadow_plan.Light(o.name, getattr(o, "lightgroup", ""),
                              str(o.get(shadow_plan.ASSIGNED_PROP, "")))
            for o in scene.objects if o.type == "LIGHT" and not o.hide_render]


def _restore_passes(scene):
    """Turn back off the direct diffuse and glossy passes an earlier
    version of the add-on turned on for EEVEE (recorded on the scene):
    only switches it turned on are turned off."""
    key = "voxlight_shadow_passes"
    for item in list(scene.get(key, [])):
        layer, _s, sw = item.partition("/")
        vl = scene.view_layers.get(layer)
        if vl is not None and hasattr(vl, sw):
            setattr(vl, sw, False)
    if key in scene:
        del scene[key]


def revert(scene):
    """Take back everything the shadows set up: the compositor chain, the
    light groups the add-on gave lights (unless the user changed them since)
    and made, and passes an earlier version turned on."""
    compositor.remove_shadow_chain(scene)
    _revert_lights(scene)


def _revert_lights(scene):
    """revert() but for the compositor chain: the light groups and passes."""
    lights = [shadow_plan.Light(o.name, getattr(o, "lightgroup", ""),
                                str(o.get(shadow_plan.ASSIGNED_PROP, "")))
              for o in scene.objects if o.type == "LIGHT"]
    for vl in scene.view_layers:
        groups = getattr(vl, "lightgroups", None)
        if groups is None:
            continue
        _reset, remove = shadow_plan.revert(lights, [g.name for g in groups])
        for name in remove:
            _remove_lightgroup(scene, vl, name)
    reset, _remove = shadow_plan.revert(lights)
    for name in reset:
        scene.objects[name].lightgroup = ""
    for o in scene.objects:
        if o.type == "LIGHT" and shadow_plan.ASSIGNED_PROP in o:
            del o[shadow_plan.ASSIGNED_PROP]
    _restore_passes(scene)


def _remove_lightgroup(scene, view_layer, name):
    """Remove one light group: the collection's remove() where it has one
    (4.x+), else (3.x) the operator on the view layer's active group. An
    operator must not run on Blender's render thread, where render_init
    and render_pre run for an F12 in the GUI: it rebuilt the depsgraph
    beside the render's and crashed Blender 3.4 ("Operation already
    exists", then SIGSEGV). There the removal waits for the main thread,
    after the render; a light group left for one render changes nothing in
    its image (Combined still holds every light)."""
    groups = view_layer.lightgroups
    g = groups.get(name)
    if g is None:
        return
    if hasattr(groups, "remove"):
        groups.remove(g)
        return
    if not id_writes.on_main_thread():
        bpy.app.timers.register(functools.partial(_remove_lightgroup_later, scene.name, view_layer.name, name),
                                first_interval=0.0)
        return
    view_layer.active_lightgroup_index = [x.name for x in groups].index(name)
    with bpy.context.temp_override(scene=scene, view_layer=view_layer):
        bpy.ops.scene.view_layer_remove_lightgroup()


def _remove_lightgroup_later(scene_name, layer_name, name):
    """Timer on the main thread: _remove_lightgroup once no render runs
    (returns the seconds to the next try, or None when done)."""
    if bpy.app.is_job_running("RENDER"):
        return 0.5
    scene = bpy.data.scenes.get(scene_name)
    vl = scene.view_layers.get(layer_name) if scene is not None else None
    if vl is not None and getattr(vl, "lightgroups", None) is not None:
        try:
            _remove_lightgroup(scene, vl, name)
        except AttributeError as e:
            if not id_writes.refused(e):
                raise
            return 0.5  # Blender still refuses writes: the job is ending
    return None


_plan = {}  # scene name -> (mode, {group: [light names]}) of the render being made


def prepare_render(scene, width, height, clear=True):
    """Light groups (or passes), the shadow images (cleared to no shadow
    when `clear`: the start of a frame) and the compositor chain, when a
    volume casts shadows; otherwise revert(). Writes only what differs
    (render_setup.py). Sets `note` for the fallback."""
    global note
    note = ""
    _plan.pop(scene.name, None)
    if not _casting_volumes(scene) or scene.voxlight.render_separate_layer \
            or not scene.voxlight.use_scene_lights:
        revert(scene)
        if scene.voxlight.render_separate_layer and _casting_volumes(scene):
            note = "Separate Layer: the volume casts no shadows in renders"
        return
    vl = _render_layer(scene)
    mode, why = shadow_plan.choose_mode(scene.render.engine, hasattr(vl, "lightgroups"))
    if mode == shadow_plan.MODE_LIGHT_GROUPS:
        _restore_passes(scene)
        plan = shadow_plan.plan_groups(_plan_lights(scene), [g.name for g in vl.lightgroups])
        for g in plan.create:
            vl.lightgroups.add(name=g)
        for name, g in plan.assign.items():
            ob = scene.objects[name]
            id_writes.assign(ob, "lightgroup", g)
            if ob.get(shadow_plan.ASSIGNED_PROP) != g:
                ob[shadow_plan.ASSIGNED_PROP] = g
        groups = plan.groups
        images = [shadow_plan.image_name(g) for g in groups]
    else:
        _revert_lights(scene)  # the chain stays: ensure_shadow_chain keeps it if it is this plan's
        groups = {}
        images = [shadow_plan.KEY_IMAGE]
        note = why
    for name in images:
        if clear:
            compositor.write_shadow_image(name, width, height, None)
        else:
            compositor.ensure_shadow_image(name, width, height)
    problem = compositor.ensure_shadow_chain(scene, shadow_plan.node_plan(mode, list(groups)))
    if problem:
        note = "No volume shadows in the render: " + problem
        return
    _plan[scene.name] = (mode, groups)
    if note and clear:  # once per frame, not on every set-up ahead of one
        print("Voxlight: %s" % note)


def transmittances(frame, depth, width, height):
    """{light index: (height, width) transmittance through every casting
    volume}, from the volumes `frame` lists (offline.render's frame_info).
    1 where the visible surface turns its lit side away from the light
    (core/facing.py): no light it could block reaches there."""
    out = {}
    for entry, kwargs in frame["casters"]:
        p = native.make_params(width=width, height=height, scene_depth=depth,
                               **params.scalar_only(kwargs))
        for i in range(len(kwargs["lights"])):
            t = entry.renderer.scene_transmittance(p, i)
            out[i] = t if i not in out else out[i] * t
    surface = frame.get("surface")
    if surface is not None and surface[0] is not None and out:
        tris, ids, view, proj = surface
        for i, light in enumerate(l for _n, _g, l in frame["named_lights"]):
            if i in out:
                out[i] = np.where(facing.faces_light(tris, ids, depth, view, proj, light.position),
                                  out[i], 1.0).astype(np.float32)
    return out


def world_light(scene):
    """The world's radiance as one number (the mean of its colour times
    strength): its Background node's when the colour is not linked, else
    the world's viewport colour (a texture's mean is not known here)."""
    world = scene.world
    if world is None:
        return 0.0
    tree = world.node_tree if getattr(world, "use_nodes", True) else None
    bg = None
    if tree is not None:
        bg = next((n for n in tree.nodes if n.bl_idname == "ShaderNodeBackground"), None)
    if bg is not None and not bg.inputs["Color"].is_linked and not bg.inputs["Strength"].is_linked:
        c = bg.inputs["Color"].default_value
        return float(np.mean(c[:3])) * float(bg.inputs["Strength"].default_value)
    return float(np.mean(world.color[:3]))


def _direct_shadow(scene, frame, trans, width, height):
    """F = sum_l w_l (1 - T_l), each light's shadow weighted by its share
    of every pixel's light (core/light_shares.py), or None (no shadow)."""
    if not trans:
        return None
    surface = frame.get("surface")
    depth = frame["depth"]
    if surface is None or surface[0] is None:
        return None
    tris, ids, view, proj = surface
    positions = facing.pixel_positions(depth, view, proj)
    normals = facing.surface_normals(tris, ids, depth, view, proj)
    lights = [l for _n, _g, l in frame["named_lights"]]
    w = light_shares.shares(lights, positions, normals, world_light(scene))
    return light_shares.shadow_amount(w, trans)


def write_render(scene, frame, width, height):
    """frame_change_post of an F12 render: fill the shadow images of the
    plan prepare_render made from the frame's z-buffer and lights."""
    planned = _plan.get(scene.name)
    if planned is None:
        return
    mode, groups = planned
    named = frame["named_lights"]
    trans = transmittances(frame, frame["depth"], width, height) if named else {}
    index = {name: i for i, (name, _g, _l) in enumerate(named)}
    weight = {name: _weight(l) for name, _g, l in named}
    if mode == shadow_plan.MODE_DIRECT:
        amount = _direct_shadow(scene, frame, trans, width, height)
        compositor.write_shadow_image(shadow_plan.KEY_IMAGE, width, height, amount)
        return
    for g, members in groups.items():
        members = [m for m in members if m in index and index[m] in trans]
        t = None
        for m, share in shadow_plan.group_weights(members, weight).items():
            part = share * trans[index[m]]
            t = part if t is None else t + part
        compositor.write_shadow_image(shadow_plan.image_name(g), width, height,
                                      None if t is None else 1.0 - t)


def clear_render(scene):
    """The frame failed or shows nothing: every shadow image to no shadow."""
    planned = _plan.get(scene.name)
    if planned is None:
        return
    mode, groups = planned
    names = [shadow_plan.KEY_IMAGE] if mode == shadow_plan.MODE_DIRECT else \
        [shadow_plan.image_name(g) for g in groups]
    for name in names:
        img = bpy.data.images.get(name)
        if img is not None:
            compositor.write_shadow_image(name, img.size[0], img.size[1], None)


def register():
    app_handlers.add(((bpy.app.handlers.depsgraph_update_post, _on_depsgraph_update),))


def unregister():
    app_handlers.remove(((bpy.app.handlers.depsgraph_update_post, _on_depsgraph_update),))
    _cache["key"] = _cache["value"] = None
