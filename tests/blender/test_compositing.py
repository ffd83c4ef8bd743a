"""The volume joins the render before the user's compositing nodes: with
Render Layers -> Invert -> output, F12 inverts the volume as well as the
background, however and whenever the user drew that tree; the nodes are
found again (not duplicated); "Volume as Separate Layer" leaves the tree
alone and gives colour, alpha and depth images instead.

blender -b --factory-startup --python-exit-code 1 --python tests/blender/test_compositing.py
"""

import os
import sys

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import _util as u  # noqa: E402
from _util import test  # noqa: E402

vx = u.install_addon()
SIZE = 64
C = SIZE // 2  # inside the ball's silhouette
NEW_API = hasattr(bpy.context.scene, "compositing_node_group")  # 5.0+


def _scene():
    """Ball volume at the origin, camera on -Y, black world, Standard view:
    a pixel's colour is what the compositor produced."""
    scene = u.reset_scene()
    scene.render.engine = "CYCLES"
    scene.cycles.samples = 1
    scene.cycles.use_denoising = False
    scene.cycles.device = "CPU"
    scene.render.resolution_x = scene.render.resolution_y = SIZE
    scene.render.film_transparent = False
    scene.world.color = (0.0, 0.0, 0.0)
    if scene.world.node_tree is not None:
        scene.world.node_tree.nodes["Background"].inputs["Color"].default_value = (0, 0, 0, 1)
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    ob = u.import_volume(u.ball_file())
    ob.voxlight.jitter = False
    u.add_camera((0.0, -3.0, 0.0))
    return scene


def _user_tree(scene, invert):
    """A fresh user tree: Render Layers -> [Invert ->] output."""
    if NEW_API:
        tree = bpy.data.node_groups.new("User Compositing", "CompositorNodeTree")
        tree.interface.new_socket("Image", in_out="OUTPUT", socket_type="NodeSocketColor")
        out = tree.nodes.new("NodeGroupOutput")
        scene.compositing_node_group = tree
    else:
        scene.use_nodes = True
        tree = scene.node_tree
        tree.nodes.clear()
        out = tree.nodes.new("CompositorNodeComposite")
    rl = tree.nodes.new("CompositorNodeRLayers")
    if invert:
        inv = _add_invert(tree)
        tree.links.new(rl.outputs["Image"], inv.inputs["Color"])
        tree.links.new(inv.outputs[0], out.inputs[0])
    else:
        tree.links.new(rl.outputs["Image"], out.inputs[0])
    return tree


def _add_invert(tree):
    inv = tree.nodes.new("CompositorNodeInvert")
    inv.name = "User Invert"
    return inv


def _output_node(tree):
    kind = "NodeGroupOutput" if NEW_API else "CompositorNodeComposite"
    return next(n for n in tree.nodes if n.bl_idname == kind)


def _f12(scene, name):
    scene.render.filepath = os.path.join(u.TMP, name + ".png")
    bpy.ops.render.render(write_still=True)
    return _linear(u.load_png(scene.render.filepath)[..., :3])


def _linear(srgb):
    """The PNG holds sRGB-encoded values; the compositor works in linear."""
    return np.where(srgb <= 0.04045, srgb / 12.92, ((srgb + 0.055) / 1.055) ** 2.4)


def _assert_inverted(img, plain):
    """The whole picture, volume included, is 1 - the plain render."""
    assert img[2, 2].min() > 0.97, img[2, 2]                      # black background -> white
    assert plain[C, C].max() > 0.1, plain[C, C]                   # the volume shows ...
    assert np.abs(img[C, C] - (1.0 - plain[C, C])).max() < 0.03, (img[C, C], plain[C, C])
    assert np.abs(img - (1.0 - plain)).max() < 0.05               # ... and is inverted everywhere


_plain = None


def _plain_render():
    global _plain
    if _plain is None:
        scene = _scene()
        _user_tree(scene, invert=False)
        _plain = _f12(scene, "plain")
    return _plain


@test
def users_invert_applies_to_the_volume():
    plain = _plain_render()
    scene = _scene()
    tree = _user_tree(scene, invert=True)
    img = _f12(scene, "inverted")
    _assert_inverted(img, plain)
    over = tree.nodes[vx.compositor.NODE_OVER]
    inv = tree.nodes["User Invert"]
    # Render Layers -> Alpha Over -> Invert -> output: the user's node kept its place.
    assert inv.inputs["Color"].links[0].from_node == over
    assert _output_node(tree).inputs[0].links[0].from_node == inv
    bg, fg = vx.compat.alpha_over_sockets(over)
    assert bg.links[0].from_node.bl_idname == "CompositorNodeRLayers"
    assert fg.links[0].from_node.name == vx.compositor.NODE_IMAGE


@test
def rerunning_finds_its_nodes_and_routes_new_links():
    plain = _plain_render()
    scene = _scene()
    tree = _user_tree(scene, invert=False)
    _f12(scene, "first")
    nodes, links = len(tree.nodes), len(tree.links)
    _f12(scene, "second")
    assert (len(tree.nodes), len(tree.links)) == (nodes, links), [n.name for n in tree.nodes]
    # The user then puts an Invert straight after Render Layers, by hand:
    # the next F12 routes that link through the volume too.
    rl = next(n for n in tree.nodes if n.bl_idname == "CompositorNodeRLayers")
    inv = _add_invert(tree)
    out = _output_node(tree)
    tree.links.new(rl.outputs["Image"], inv.inputs["Color"])
    tree.links.new(inv.outputs[0], out.inputs[0])
    img = _f12(scene, "inverted_later")
    _assert_inverted(img, plain)
    assert sum(n.name.startswith(vx.compositor.NODE_OVER) for n in tree.nodes) == 1
    assert sum(n.name.startswith(vx.compositor.NODE_IMAGE) for n in tree.nodes) == 1


@test
def nothing_to_show_passes_the_users_effects_through():
    scene = _scene()
    tree = _user_tree(scene, invert=True)
    _f12(scene, "before_disabling")
    scene.voxlight.render_enabled = False
    img = _f12(scene, "disabled")
    assert tree.nodes[vx.compositor.NODE_OVER].mute
    # Only the (inverted, black) background: white everywhere, no volume.
    assert img.min() > 0.97, img.min()


@test
def separate_layer_leaves_the_tree_alone_and_gives_passes():
    plain = _plain_render()
    scene = _scene()
    tree = _user_tree(scene, invert=True)
    _f12(scene, "composited")
    scene.voxlight.render_separate_layer = True
    img = _f12(scene, "separate")
    cp = vx.compositor
    # The Alpha Over is gone and the user's wiring is as they drew it.
    assert cp.NODE_OVER not in tree.nodes and cp.NODE_IMAGE not in tree.nodes
    inv = tree.nodes["User Invert"]
    assert inv.inputs["Color"].links[0].from_node.bl_idname == "CompositorNodeRLayers"
    assert img.min() > 0.97, img.min()  # the render is the user's alone
    # One image (and an unlinked Image node) per pass, at render size.
    for name in cp.PASSES:
        node = tree.nodes[name]
        assert node.image == bpy.data.images[name]
        assert not any(s.is_linked for s in node.outputs), name
        assert tuple(node.image.size) == (SIZE, SIZE)

    def px(name):
        a = np.empty(SIZE * SIZE * 4, np.float32)
        bpy.data.images[name].pixels.foreach_get(a)
        return a.reshape(SIZE, SIZE, 4)
    color, alpha, depth = px(cp.PASS_COLOR), px(cp.PASS_ALPHA), px(cp.PASS_DEPTH)
    assert alpha[C, C, 0] > 0.5 and alpha[2, 2, 0] == 0.0, (alpha[C, C], alpha[2, 2])
    assert np.allclose(alpha[..., 0], color[..., 3])
    # The colour pass is what the composited render showed (black behind).
    assert np.abs(color[C, C, :3] - plain[C, C]).max() < 0.03, (color[C, C], plain[C, C])
    # Depth: the ball's front is ~2.5 units from the camera at 3; none elsewhere.
    assert 2.0 < depth[C, C, 0] < 3.0, depth[C, C]
    assert depth[2, 2, 0] == cp.NO_DEPTH, depth[2, 2]
    # Back to compositing: the Alpha Over returns before the Invert.
    scene.voxlight.render_separate_layer = False
    _assert_inverted(_f12(scene, "composited_again"), plain)


u.run("test_compositing")
