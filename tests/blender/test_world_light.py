"""The World lights the volume in F12 (blender -b): an HDRI-only World (an
Environment Texture bright on one side, no lamps) lights the side of a ball
facing its bright part, a Mapping node's Z rotation of 180 degrees moves the
light to the other side, a black World leaves the ball dark (no headlight
stands in), and "World Light" off brings back the headlight.

The camera is on -Y looking along +Y, so world +X is the image's right.

blender -b --factory-startup --python-exit-code 1 --python tests/blender/test_world_light.py
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
W = H = 64


def _sky():
    """A float image bright (radiance 4) around +X in Blender's equirectangular
    mapping (the centre column looks along +X), black elsewhere."""
    w, h = 64, 32
    img = bpy.data.images.get("VoxlightTestSky") or bpy.data.images.new("VoxlightTestSky", w, h,
                                                                           float_buffer=True)
    u_ = (np.arange(w) + 0.5) / w
    v_ = (np.arange(h) + 0.5) / h
    az = math.pi * (1 - 2 * u_)[None, :]
    el = math.pi * (v_ - 0.5)[:, None]
    on = np.cos(el) * np.cos(az) > 0.7
    px = np.zeros((h, w, 4), np.float32)
    px[..., :3] = np.where(on, 4.0, 0.0)[..., None]
    px[..., 3] = 1.0
    img.pixels.foreach_set(px.ravel())
    img.update()
    return img


def _world(scene, image=None, colour=(0, 0, 0, 1), strength=1.0):
    """The scene's World: a Background fed by an Environment Texture (through a
    Mapping node) when image is given, else a colour."""
    world = bpy.data.worlds.new("VoxlightTestWorld")
    if bpy.app.version < (5, 0, 0):
        world.use_nodes = True
    nt = world.node_tree
    nt.nodes.clear()
    out = nt.nodes.new("ShaderNodeOutputWorld")
    bg = nt.nodes.new("ShaderNodeBackground")
    nt.links.new(bg.outputs["Background"], out.inputs["Surface"])
    bg.inputs["Color"].default_value = colour
    bg.inputs["Strength"].default_value = strength
    if image is not None:
        tex = nt.nodes.new("ShaderNodeTexEnvironment")
        tex.image = image
        mapping = nt.nodes.new("ShaderNodeMapping")
        coords = nt.nodes.new("ShaderNodeTexCoord")
        nt.links.new(coords.outputs["Generated"], mapping.inputs["Vector"])
        nt.links.new(mapping.outputs["Vector"], tex.inputs["Vector"])
        nt.links.new(tex.outputs["Color"], bg.inputs["Color"])
    scene.world = world
    return world


def _scene():
    scene = u.reset_scene()
    scene.voxlight.use_world_light = True
    scene.render.engine = "CYCLES"
    scene.cycles.samples = 1
    scene.cycles.use_denoising = False
    scene.render.film_transparent = True
    scene.view_settings.view_transform = "Standard"
    scene.render.resolution_x, scene.render.resolution_y = W, H
    ob = u.import_volume(u.ball_file())
    ob.voxlight.jitter = False
    ob.voxlight.specular = 0.0
    cam = u.add_camera((0.0, -3.0, 0.0))
    cam.data.type = "ORTHO"
    model = vx.params.model_matrix(ob)
    cam.data.ortho_scale = 1.3 * 32 * float(np.linalg.norm(model[:3, 0]))  # the 32-voxel box, and a margin
    cam.location = tuple(model[:3, 3] + model[:3, :3] @ np.full(3, 15.5) + np.array([0.0, -3.0, 0.0]))
    return scene, ob


def _f12(scene, name):
    scene.render.filepath = os.path.join(u.TMP, name + ".png")
    bpy.ops.render.render(write_still=True)
    return u.load_png(scene.render.filepath)


def _halves(img):
    """Mean colour of the covered pixels of the left and right halves."""
    out = []
    for part in (img[:, :W // 2], img[:, W // 2:]):
        cover = part[..., 3] > 0.5
        assert cover.sum() > 30, "the ball covers both halves"
        out.append(float(part[..., :3].mean(axis=2)[cover].mean()))
    return out


@test
def an_hdri_only_world_lights_the_ball_from_its_bright_side():
    scene, ob = _scene()
    world = _world(scene, _sky())
    left, right = _halves(_f12(scene, "hdri"))
    print("hdri: left %.3f right %.3f" % (left, right))
    assert right > 1.3 * left and right > 0.1, (left, right)  # +X is on the right
    world.node_tree.nodes["Mapping"].inputs["Rotation"].default_value[2] = math.pi
    r_left, r_right = _halves(_f12(scene, "hdri_turned"))
    print("turned: left %.3f right %.3f" % (r_left, r_right))
    assert r_left > 1.3 * r_right, (r_left, r_right)


@test
def a_black_world_gives_no_light_and_world_light_off_brings_the_headlight_back():
    scene, ob = _scene()
    _world(scene, colour=(0.0, 0.0, 0.0, 1.0))
    dark = _halves(_f12(scene, "black"))
    _world(scene, colour=(1.0, 1.0, 1.0, 1.0), strength=1.0)
    lit = _halves(_f12(scene, "white"))
    print("black world %s, white world %s" % (dark, lit))
    assert min(lit) > 0.15 and max(dark) < 0.5 * min(lit), (dark, lit)
    scene.voxlight.use_world_light = False
    head = _halves(_f12(scene, "headlight"))
    print("world light off (headlight): %s" % (head,))
    assert min(head) > 0.3, head


@test
def the_light_follows_the_world_and_its_image():
    """What the viewport and F12 pass is read from the World as it is now:
    its strength, the Mapping rotation, and another image's pixels."""
    scene, ob = _scene()
    img = _sky()
    world = _world(scene, img, strength=2.0)
    dg = bpy.context.evaluated_depsgraph_get()
    env = vx.params.scene_lights(scene, dg).environment
    assert env is not None and env.strength == 2.0 and env.rgb.shape == (32, 64, 3), env
    bright = float(env.rgb.max())
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.5
    world.node_tree.nodes["Mapping"].inputs["Rotation"].default_value[2] = math.radians(30.0)
    bpy.context.view_layer.update()
    env = vx.params.scene_lights(scene, dg).environment
    assert env.strength == 0.5 and abs(env.rotation_deg - 30.0) < 1e-4, env[1:]
    grey = bpy.data.images.new("VoxlightTestGrey", 16, 8, float_buffer=True)
    grey.pixels.foreach_set(np.full(16 * 8 * 4, 0.25, np.float32))
    world.node_tree.nodes["Environment Texture"].image = grey  # another image: another map
    bpy.context.view_layer.update()
    env = vx.params.scene_lights(scene, bpy.context.evaluated_depsgraph_get()).environment
    assert abs(float(env.rgb.max()) - 0.25) < 1e-6 and bright > 1.0, (env.rgb.max(), bright)
    scene.voxlight.use_scene_lights = False  # the World follows Scene Lights
    assert vx.params.scene_lights(scene, dg).environment is None


u.run("test_world_light")
