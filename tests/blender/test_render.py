"""F12 / background renders through the render_pre hook and compositor:
a mesh in front of, behind and inside the volume, judged from the pixels of
the written image; plus animation, resolution percentage and pixel aspect.

blender -b --factory-startup --python-exit-code 1 --python tests/blender/test_render.py
"""

import os
import sys

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import _util as u  # noqa: E402
from _util import test  # noqa: E402

vx = u.install_addon()
SIZE = 96
GREEN = (0.0, 0.6, 0.0)


def _emissive(ob, color):
    """Flat, noise-free colour in Cycles: an emission-only material."""
    mat = ob.data.materials[0]
    nt = mat.node_tree
    nt.nodes.clear()
    em = nt.nodes.new("ShaderNodeEmission")
    em.inputs["Color"].default_value = (*color, 1.0)
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    nt.links.new(em.outputs[0], out.inputs["Surface"])


def _scene(opacity=1.0):
    """Ball volume at the origin (radius ~0.26), camera on -Y looking at it,
    black world, Standard view: a pixel's colour is what was composited."""
    scene = u.reset_scene()
    scene.render.engine = "CYCLES"
    scene.cycles.samples = 4
    scene.cycles.use_denoising = False  # Debian's Cycles has no OIDN
    scene.cycles.device = "CPU"
    scene.render.resolution_x = scene.render.resolution_y = SIZE
    scene.render.resolution_percentage = 100
    scene.render.film_transparent = False
    scene.world.color = (0.0, 0.0, 0.0)
    if scene.world.node_tree is not None:  # (World.use_nodes is deprecated in 5.0)
        scene.world.node_tree.nodes["Background"].inputs["Color"].default_value = (0, 0, 0, 1)
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    ob = u.import_volume(u.ball_file())
    ob.voxlight.jitter = False
    ob.voxlight.opacity_scale = opacity
    u.add_camera((0.0, -3.0, 0.0))
    return scene, ob


def _f12(scene, name):
    scene.render.filepath = os.path.join(u.TMP, name + ".png")
    bpy.ops.render.render(write_still=True)
    return u.load_png(scene.render.filepath)


def _is_green(px):
    """The plane's emission (0.6 linear, ~0.8 in sRGB) and nothing else."""
    return px[1] > 0.7 and px[0] < 0.1 and px[2] < 0.1


C = SIZE // 2          # image centre: inside the ball's silhouette
L, R = C - 6, C + 6    # left / right of centre, still inside the ball


@test
def volume_alone_is_composited():
    scene, ob = _scene()
    img = _f12(scene, "alone")
    assert img[C, C, :3].min() > 0.3, img[C, C]      # the ball shows
    assert img[2, 2, :3].max() < 0.02, img[2, 2]     # background stays black


@test
def mesh_in_front_hides_the_volume():
    scene, ob = _scene()
    # An opaque green plane between camera and ball, covering x < 0.
    plane = u.add_plane((1.0, 2.0), (-0.5, -1.0, 0.0), rotation=(1.5708, 0.0, 0.0))
    _emissive(plane, GREEN)
    img = _f12(scene, "front")
    assert _is_green(img[C, L]), img[C, L]            # covered half: plane only
    assert not _is_green(img[C, R]) and img[C, R, :3].min() > 0.3, img[C, R]


@test
def volume_in_front_of_mesh_blends_over_it():
    scene, ob = _scene()
    wall = u.add_plane((4.0, 4.0), (0.0, 1.0, 0.0), rotation=(1.5708, 0.0, 0.0))
    _emissive(wall, GREEN)
    img = _f12(scene, "behind")
    assert _is_green(img[4, 4]), img[4, 4]            # wall around the ball
    assert not _is_green(img[C, C]) and img[C, C, 0] > 0.3, img[C, C]  # ball over the wall


@test
def mesh_inside_the_volume_hides_what_is_behind_it():
    # A translucent ball with a plane through its centre: with occlusion the
    # rays stop at the plane, so the front half of the ball blends over the
    # plane and the back half is gone. Without it (render_occlusion off) the
    # whole ball would be laid over the plane and hide more of it.
    scene, ob = _scene(opacity=0.08)
    ob.voxlight.shading = False
    plane = u.add_plane((0.26, 2.0), (-0.13, 0.0, 0.0), rotation=(1.5708, 0.0, 0.0))
    _emissive(plane, GREEN)
    exact = _f12(scene, "inside")
    scene.voxlight.render_occlusion = False
    naive = _f12(scene, "inside_naive")
    scene.voxlight.render_occlusion = True
    plane.hide_render = True
    alone = _f12(scene, "inside_alone")
    px, nv, al = exact[C, L], naive[C, L], alone[C, L]
    # The plane shows through the front half (its green adds) ...
    assert px[1] > al[1] + 0.05, (px, al)
    # ... the front half still tints it: volume colour over the mesh (the
    # plane itself has no red) ...
    assert px[0] > 0.03, px
    # ... and the back half is gone: less volume red than the whole ball
    # gives, whether alone or composited naively over the plane.
    assert px[0] < al[0] - 0.03 and px[0] < nv[0] - 0.03, (px, al, nv)
    # Where there is no plane, occlusion changes nothing.
    assert np.abs(exact[C, R] - alone[C, R]).max() < 0.02, (exact[C, R], alone[C, R])


@test
def resolution_percentage_and_pixel_aspect():
    scene, ob = _scene()
    scene.render.resolution_percentage = 50
    img = _f12(scene, "half")
    assert img.shape == (SIZE // 2, SIZE // 2, 4)
    assert bpy.data.images["Voxlight Render"].size[:] == (SIZE // 2, SIZE // 2)
    assert img[SIZE // 4, SIZE // 4, :3].min() > 0.3
    # Pixel aspect 2:1 squeezes the ball horizontally in pixel space.
    scene.render.resolution_percentage = 100
    scene.render.pixel_aspect_x = 2.0
    img = _f12(scene, "aspect")
    a = img[..., :3].max(axis=2) > 0.2
    width = a.any(axis=0).sum()
    height = a.any(axis=1).sum()
    assert width < height * 0.7, (width, height)


@test
def animation_render_follows_the_frame():
    scene, ob = _scene()
    ob.location = (-0.5, 0.0, 0.0)
    ob.keyframe_insert("location", frame=1)
    ob.location = (0.5, 0.0, 0.0)
    ob.keyframe_insert("location", frame=2)
    scene.frame_start, scene.frame_end = 1, 2
    scene.render.filepath = os.path.join(u.TMP, "anim_")
    scene.render.image_settings.file_format = "PNG"
    bpy.ops.render.render(animation=True)
    f1 = u.load_png(os.path.join(u.TMP, "anim_0001.png"))
    f2 = u.load_png(os.path.join(u.TMP, "anim_0002.png"))
    xs = np.arange(SIZE)

    def cx(img):
        w = img[..., :3].max(axis=2).sum(axis=0)
        return (w * xs).sum() / w.sum()
    assert cx(f1) < SIZE / 2 - 8 and cx(f2) > SIZE / 2 + 8, (cx(f1), cx(f2))


@test
def users_compositing_tree_is_used_and_kept():
    """F12 composites into the scene's own compositing tree: in 5.0 the
    node group the user assigned (scene.compositing_node_group), before it
    scene.node_tree; the user's nodes stay."""
    scene, ob = _scene()
    if hasattr(scene, "compositing_node_group"):  # 5.0+
        tree = bpy.data.node_groups.new("User Compositing", "CompositorNodeTree")
        tree.interface.new_socket("Image", in_out="OUTPUT", socket_type="NodeSocketColor")
        rl = tree.nodes.new("CompositorNodeRLayers")
        out = tree.nodes.new("NodeGroupOutput")
        tree.links.new(rl.outputs["Image"], out.inputs[0])
        scene.compositing_node_group = tree
    else:
        scene.use_nodes = True
        tree = scene.node_tree
    tree.nodes.new("CompositorNodeBlur").name = "User Blur"
    img = _f12(scene, "user_tree")
    assert img[C, C, :3].max() > 0.05, img[C, C]  # the volume is there
    now = scene.compositing_node_group if hasattr(scene, "compositing_node_group") else scene.node_tree
    assert now == tree and "User Blur" in tree.nodes, [n.name for n in now.nodes]
    assert vx.compositor.NODE_OVER in tree.nodes


@test
def disabled_compositing_leaves_render_alone():
    scene, ob = _scene()
    scene.voxlight.render_enabled = False
    img = _f12(scene, "disabled")
    assert img[C, C, :3].max() < 0.02, img[C, C]


@test
def real_brain_renders_with_workbench():
    scene = u.reset_scene()
    scene.render.engine = "BLENDER_WORKBENCH"
    scene.render.resolution_x = scene.render.resolution_y = 64
    scene.render.resolution_percentage = 100
    scene.view_settings.view_transform = "Standard"
    ob = u.import_volume(u.CH2)
    u.add_camera((0.0, -4.0, 0.3))
    u.add_plane((0.4, 0.4), (0.0, -1.5, 0.0), rotation=(1.5708, 0.0, 0.0))
    img = _f12(scene, "brain")
    vol = vx.render_volume(ob, resolution=(64, 64))
    assert vol[..., 3].max() > 0.9
    # The (green) plane in front of the centre hides the brain there: the
    # volume layer is empty at the centre and the pixel is the plane's.
    assert vol[32, 32, 3] < 0.01
    centre = img[32, 32]
    assert centre[1] > centre[0] + 0.2 and centre[1] > centre[2] + 0.2, centre
    # Beside the plane the brain is composited over the (black) background.
    assert vol[32, 20, 3] > 0.5
    side = img[32, 20]
    assert side[:3].min() > 0.2 and abs(side[0] - side[1]) < 0.15, side


u.run("test_render")
