"""Compositor nodes that put the volume image over the render:

    Render Layers (or whatever fed the output) --> Alpha Over [bg]
    Image "Voxlight Render" (premultiplied)    --> Alpha Over [fg] --> output

Python cannot read Render Result pixels, so the volume is composited here
instead. The nodes are created once and found again by name; with no
volumes to show, the Alpha Over is muted so it passes the render through.
Blender 5.0 moved the compositor to scene.compositing_node_group (with a
Group Output instead of a Composite node); both layouts are handled.
"""

import bpy

IMAGE_NAME = "Voxlight Render"
NODE_IMAGE = "Voxlight Volume"
NODE_OVER = "Voxlight Alpha Over"


def ensure_image(width, height):
    img = bpy.data.images.get(IMAGE_NAME)
    if img is not None and (not img.is_float or tuple(img.size) != (width, height)):
        if tuple(img.size) != (width, height) and img.is_float:
            img.scale(width, height)
        else:
            bpy.data.images.remove(img)
            img = None
    if img is None:
        img = bpy.data.images.new(IMAGE_NAME, width, height, alpha=True, float_buffer=True)
    img.alpha_mode = "PREMUL"  # the library's output is premultiplied
    img.use_fake_user = False
    return img


def _tree(scene):
    if hasattr(scene, "compositing_node_group"):  # Blender 5.0+
        tree = scene.compositing_node_group
        if tree is None:
            tree = bpy.data.node_groups.new("Voxlight Compositing", "CompositorNodeTree")
            tree.interface.new_socket("Image", in_out="OUTPUT", socket_type="NodeSocketColor")
            rl = tree.nodes.new("CompositorNodeRLayers")
            out = tree.nodes.new("NodeGroupOutput")
            out.location = (400, 0)
            tree.links.new(rl.outputs["Image"], out.inputs[0])
            scene.compositing_node_group = tree
        return tree
    scene.use_nodes = True
    if scene.render.use_compositing is False:
        scene.render.use_compositing = True
    return scene.node_tree


def _output_socket(tree):
    for node in tree.nodes:
        if node.bl_idname == "CompositorNodeComposite":
            return node.inputs["Image"]
    for node in tree.nodes:
        if node.bl_idname == "NodeGroupOutput" and node.inputs:
            return node.inputs[0]
    out = tree.nodes.new("CompositorNodeComposite")
    out.location = (600, 0)
    return out.inputs["Image"]


def _render_layers(tree):
    for node in tree.nodes:
        if node.bl_idname == "CompositorNodeRLayers":
            return node
    return tree.nodes.new("CompositorNodeRLayers")


def ensure_nodes(scene, image):
    """Idempotent: builds the nodes on first use, then only re-points them."""
    tree = _tree(scene)
    over = tree.nodes.get(NODE_OVER)
    img_node = tree.nodes.get(NODE_IMAGE)
    if img_node is None:
        img_node = tree.nodes.new("CompositorNodeImage")
        img_node.name = img_node.label = NODE_IMAGE
    if img_node.image != image:
        img_node.image = image
    if over is None:
        over = tree.nodes.new("CompositorNodeAlphaOver")
        over.name = over.label = NODE_OVER
        out = _output_socket(tree)
        src = out.links[0].from_socket if out.is_linked else _render_layers(tree).outputs["Image"]
        tree.links.new(src, over.inputs[1])
        tree.links.new(over.outputs[0], out)
        over.location = (out.node.location.x - 200, out.node.location.y)
        img_node.location = (over.location.x - 300, over.location.y - 250)
    if not over.inputs[2].is_linked:
        tree.links.new(img_node.outputs["Image"], over.inputs[2])
    # The image is already premultiplied: a plain premultiplied 'over'.
    over.use_premultiply = False
    over.premul = 0.0
    over.mute = False
    return tree


def mute(scene):
    tree = scene.compositing_node_group if hasattr(scene, "compositing_node_group") \
        else scene.node_tree
    if tree is not None:
        over = tree.nodes.get(NODE_OVER)
        if over is not None:
            over.mute = True
