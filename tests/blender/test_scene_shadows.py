"""In Blender: the volume casts shadows on the scene's meshes in F12
(through the compositor: each light group's light times the transmittance)
and receives the shadows of meshes between it and a light.

The scene: an opaque ball floating 1 unit above a white floor, a Sun, an
orthographic camera looking down at 30 degrees from -Y, so the floor under
the ball shows beside it. The shadow's place on the floor is worked out
from the Sun's direction and the ball's centre, never hard-coded.

blender -b --factory-startup --python-exit-code 1 --python tests/blender/test_scene_shadows.py
"""

import math
import os
import sys

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import _util as u  # noqa: E402
from _util import test  # noqa: E402

vx = u.install_addon()
W, H = 96, 72
HEIGHT = 1.0   # the ball's centre above the floor
SP = vx.core.shadow_plan


def _scene(sun_tilt=0.0):
    """Floor, ball, Sun tilted by `sun_tilt` radians about Y (0 = straight
    down), camera; Cycles with a few samples."""
    scene = u.reset_scene()
    scene.render.engine = "CYCLES"
    scene.cycles.samples = 4
    scene.cycles.use_denoising = False  # Debian's Cycles has no OIDN
    scene.render.film_transparent = False
    scene.view_settings.view_transform = "Standard"
    scene.render.resolution_x, scene.render.resolution_y = W, H
    floor = u.add_plane((8.0, 8.0), (0.0, 0.0, 0.0), name="Floor", color=(0.8, 0.8, 0.8))
    bsdf = floor.data.materials[0].node_tree.nodes["Principled BSDF"]
    if "Emission Strength" in bsdf.inputs:
        bsdf.inputs["Emission Strength"].default_value = 0.0
    else:
        (bsdf.inputs.get("Emission Color") or bsdf.inputs["Emission"]).default_value = (0, 0, 0, 1)
    bpy.context.scene.cursor.location = (0.0, 0.0, HEIGHT)
    ob = u.import_volume(u.ball_file())   # 64 mm = 0.64 units across, centred at the cursor
    p = ob.voxlight
    p.jitter = False
    p.opacity_scale = 8.0
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy = 3.0
    sun.data.angle = 0.0
    sun.rotation_euler = (0.0, sun_tilt, 0.0)
    scene.collection.objects.link(sun)
    cam = u.add_camera((0.0, -6.0 * math.cos(math.radians(30)), 6.0 * math.sin(math.radians(30))),
                       target=(0.0, 0.0, 0.3))
    cam.data.type = "ORTHO"
    cam.data.ortho_scale = 4.0
    bpy.context.view_layer.update()
    return scene, ob, sun


def _centre(ob):
    model = vx.params.model_matrix(ob)
    n = np.array(ob.voxlight.dims, np.float64)
    return (model @ np.array([*((n - 1) / 2.0), 1.0]))[:3]


def _shadow_centre(ob, sun):
    """Where the ball's centre falls on the floor (z = 0) along the Sun's
    light, which travels along the Sun's local -Z."""
    d = -np.array(sun.matrix_world, np.float64)[:3, 2]
    c = _centre(ob)
    return c - (c[2] / d[2]) * d


def _pixel(scene, world):
    dg = bpy.context.evaluated_depsgraph_get()
    view, proj = vx.offline.camera_matrices(scene.camera, dg, W, H, scene)
    clip = proj @ view @ np.array([*world, 1.0])
    return (clip[0] / clip[3] + 1) * W / 2, (clip[1] / clip[3] + 1) * H / 2


def _f12(scene, name):
    scene.render.filepath = os.path.join(u.TMP, name + ".png")
    bpy.ops.render.render(write_still=True)
    return u.load_png(scene.render.filepath)


def _light(img, scene, world, radius_px=4.0):
    """Mean linear brightness of a disc of the image around a world point."""
    cx, cy = _pixel(scene, world)
    ys, xs = np.mgrid[0:H, 0:W]
    disc = (xs + 0.5 - cx) ** 2 + (ys + 0.5 - cy) ** 2 < radius_px ** 2
    assert disc.sum() > 20, (cx, cy)
    c = np.clip(img[disc][:, :3], 0.0, 1.0)
    return float(np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4).mean())


def _darkening(img, scene, ob, sun):
    """Brightness in the shadow's centre over that of the floor 1.2 units
    beside it (in the light)."""
    at = _shadow_centre(ob, sun)
    lit = _light(img, scene, at + np.array([1.2, 0.0, 0.0]))
    assert lit > 0.05, lit
    return _light(img, scene, at) / lit


def _ball_hides(scene, ob, world):
    """Whether the ball covers a floor point in the image."""
    (bx, by), (px, py) = _pixel(scene, _centre(ob)), _pixel(scene, world)
    r = 0.32 * W / scene.camera.data.ortho_scale
    return math.hypot(bx - px, by - py) < r + 5.0


@test
def the_volume_shadows_the_floor_in_f12_and_not_when_cast_shadows_is_off():
    scene, ob, sun = _scene()
    assert ob.voxlight.cast_shadows and ob.voxlight.receive_shadows  # on by default
    assert not _ball_hides(scene, ob, _shadow_centre(ob, sun))
    user = bpy.data.objects.new("Fill", bpy.data.lights.new("Fill", "POINT"))
    user.data.energy = 1.0
    user.location = (3.0, 3.0, 3.0)
    scene.collection.objects.link(user)
    scene.view_layers[0].lightgroups.add(name="mine")
    user.lightgroup = "mine"
    on = _darkening(_f12(scene, "cast_on"), scene, ob, sun)
    groups = [g.name for g in scene.view_layers[0].lightgroups]
    assert sun.lightgroup == "Voxlight_Sun" and "Voxlight_Sun" in groups, (sun.lightgroup, groups)
    assert user.lightgroup == "mine"  # the user's group stays, shadowed as it is
    ob.voxlight.cast_shadows = False
    off = _darkening(_f12(scene, "cast_off"), scene, ob, sun)
    print("shadow/lit: cast on %.3f, off %.3f" % (on, off), flush=True)
    assert on < 0.5, on
    assert 0.85 < off < 1.15, off
    # Off, everything the add-on set up is taken back; the user's group is not.
    groups = [g.name for g in scene.view_layers[0].lightgroups]
    assert sun.lightgroup == "" and SP.ASSIGNED_PROP not in sun, sun.lightgroup
    assert groups == ["mine"] and user.lightgroup == "mine", groups
    tree = vx.compat.compositor_tree(scene)
    assert not [n for n in tree.nodes if n.name.startswith(SP.NODE_PREFIX)]


@test
def rotating_the_sun_moves_the_shadow_where_the_geometry_says():
    scene, ob, sun = _scene(sun_tilt=math.radians(35))
    before = _shadow_centre(ob, sun)
    sun.rotation_euler = (0.0, math.radians(-35), 0.0)
    bpy.context.view_layer.update()
    after = _shadow_centre(ob, sun)
    assert abs(after[0] - before[0]) > 1.0, (before, after)  # the shadows do not overlap
    for point in (before, after):
        assert not _ball_hides(scene, ob, point)
    img = _f12(scene, "sun_moved")
    shadow = _light(img, scene, after)
    old = _light(img, scene, before)
    print("new place %.3f, old place %.3f" % (shadow, old), flush=True)
    assert shadow < 0.5 * old, (shadow, old)


@test
def without_light_groups_the_direct_light_is_shadowed_by_the_key_light():
    """The fallback for engines without light group passes (EEVEE), run in
    Cycles: the image times 1 - each light's share times its shadow, with
    no render pass (the direct-light passes' rounding striped it)."""
    scene, ob, sun = _scene()
    layer = scene.view_layers[0]
    choose = SP.choose_mode
    SP.choose_mode = lambda engine, has_groups: (SP.MODE_DIRECT, "no light groups here")
    try:
        on = _darkening(_f12(scene, "direct_on"), scene, ob, sun)
        assert vx.scene_shadows.note == "no light groups here"
        assert not layer.use_pass_diffuse_direct and not layer.use_pass_glossy_color
        assert sun.lightgroup == ""
        assert not [g for g in layer.lightgroups if g.name.startswith(SP.GROUP_PREFIX)]
        ob.voxlight.cast_shadows = False
        off = _darkening(_f12(scene, "direct_off"), scene, ob, sun)
    finally:
        SP.choose_mode = choose
    print("direct light only: shadow/lit on %.3f, off %.3f" % (on, off), flush=True)
    assert on < 0.5, on
    assert 0.85 < off < 1.15, off
    assert not layer.use_pass_diffuse_direct and not layer.use_pass_glossy_color


def _plate(hide_shadow=False):
    plate = u.add_plane((2.0, 2.0), (0.0, 0.0, HEIGHT + 0.8), name="Plate")
    if hide_shadow:
        plate.visible_shadow = False
    bpy.context.view_layer.update()
    return plate


def _volume_light(ob):
    img = vx.render_volume(ob, resolution=(64, 64))
    assert img[..., 3].max() > 0.5
    return float(img[..., :3].sum())


@test
def a_plate_between_the_sun_and_the_volume_shadows_it_when_receive_shadows_is_on():
    scene, ob, sun = _scene()
    ob.voxlight.occlusion_strength = 0.0
    ob.voxlight.ambient = 0.1
    open_sky = _volume_light(ob)
    plate = _plate()
    under_plate = _volume_light(ob)
    ob.voxlight.receive_shadows = False
    not_receiving = _volume_light(ob)
    ob.voxlight.receive_shadows = True
    plate.visible_shadow = False   # Blender's Shadow visibility off: no occluder
    bpy.context.view_layer.update()
    hidden = _volume_light(ob)
    print("volume light: open %.1f, under the plate %.1f, receive off %.1f, plate's shadow "
          "off %.1f" % (open_sky, under_plate, not_receiving, hidden), flush=True)
    assert under_plate < 0.6 * open_sky, (under_plate, open_sky)
    assert abs(not_receiving - open_sky) < 0.02 * open_sky
    assert abs(hidden - open_sky) < 0.02 * open_sky


@test
def occluder_key_changes_only_with_the_meshes():
    scene, ob, sun = _scene()
    dg = bpy.context.evaluated_depsgraph_get()
    key = vx.scene_shadows.occluder_key(dg, False)
    sun.rotation_euler = (0.3, 0.0, 0.0)   # a light is not an occluder
    ob.voxlight.opacity_scale = 2.0
    bpy.context.view_layer.update()
    assert vx.scene_shadows.occluder_key(bpy.context.evaluated_depsgraph_get(), False) == key
    verts, tris, k = vx.scene_shadows.occluders(bpy.context.evaluated_depsgraph_get(), False)
    assert k == key and len(tris) == 2 and abs(verts[:, 2]).max() < 1e-6  # the floor
    bpy.data.objects["Floor"].location.z = 0.1
    bpy.context.view_layer.update()
    assert vx.scene_shadows.occluder_key(bpy.context.evaluated_depsgraph_get(), False) != key


@test
def the_panel_switches_are_animatable():
    rna = bpy.types.Object.bl_rna.properties["voxlight"].fixed_type.properties
    scene, ob, _sun = _scene()
    for name in ("cast_shadows", "receive_shadows"):
        assert rna[name].default is True and rna[name].is_animatable, name
        assert ob.voxlight.keyframe_insert(name, frame=1)


u.run("test_scene_shadows")
