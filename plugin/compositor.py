"""Compositor nodes that put the volume image into the render, before
anything the user built on top of it:

    Render Layers [Image] --> Alpha Over [bg] --> (every node that used to
    Image "Voxlight Render" --> Alpha Over [fg]    read Render Layers' Image)

Python cannot read Render Result pixels, so the volume is composited here
instead. The Alpha Over takes Render Layers' Image, and every link that left
Render Layers' Image now leaves the Alpha Over, so the user's effects
(Invert, Glare, colour grading ...) apply to the volume and the mesh render
alike. Each run re-routes links that the user has since drawn from Render
Layers' Image; a user who feeds the Alpha Over's background from anything
else keeps that wiring. The nodes are found again by name. The nodes change
only before a frame is evaluated (render_init, render_pre): the compositor
runs on Blender's evaluated copy of the tree, which edits made while the
frame renders (frame_change_post) do not reach, so a frame changes only
pixels. With nothing to show the image is emptied, and an 'over' of an
empty image is the render itself; with no volume to render at all the
Alpha Over is also muted.

"Volume as Separate Layer" (scene.voxlight.render_separate_layer) leaves the
user's tree alone instead: the Alpha Over is taken out (its links restored
to Render Layers) and each pass is an image the user can wire, shown by an
unlinked Image node per pass: colour (premultiplied, scene-linear), alpha,
and depth (view-space planar distance, as Blender's Depth pass; 1e10 where
no volume is).

Blender 5.0 moved the compositor to scene.compositing_node_group (with a
Group Output instead of a Composite node) and changed Alpha Over's inputs;
compat.py hides both.
"""

import bpy
import numpy as np

from . import compat, id_writes
from .core import shadow_plan

IMAGE_NAME = "Voxlight Render"
NODE_IMAGE = "Voxlight Volume"
NODE_OVER = "Voxlight Alpha Over"

# Separate-layer passes: (image and node name, what it holds).
PASS_COLOR = "Voxlight Color"
PASS_ALPHA = "Voxlight Alpha"
PASS_DEPTH = "Voxlight Depth"
PASSES = (PASS_COLOR, PASS_ALPHA, PASS_DEPTH)
NO_DEPTH = 1e10  # what Blender's own Depth pass holds where nothing is


def ensure_image(width, height, name=IMAGE_NAME, alpha_mode="PREMUL", is_data=None):
    """The float image `name` at width x height. A new or resized one holds
    nothing (clear_image): Blender fills new images with opaque black, which
    the Alpha Over would lay over the whole frame whenever a render writes
    no pixels into it (the volume hidden, empty or out of view)."""
    img = bpy.data.images.get(name)
    fresh = img is None or not img.is_float or tuple(img.size) != (width, height)
    if img is not None and fresh:
        if tuple(img.size) != (width, height) and img.is_float:
            img.scale(width, height)
        else:
            bpy.data.images.remove(img)
            img = None
    if img is None:
        img = bpy.data.images.new(name, width, height, alpha=True, float_buffer=True)
    # The library's colour is premultiplied; alpha and depth are data.
    # Written only when they differ (id_writes.py: the render thread).
    id_writes.assign(img, "alpha_mode", alpha_mode)
    if is_data is None:
        is_data = name in (PASS_ALPHA, PASS_DEPTH)
    if is_data:
        id_writes.assign(img.colorspace_settings, "is_data", True)
    id_writes.assign(img, "use_fake_user", False)
    if fresh:
        clear_image(img)
    return img


def empty_pixel(name):
    """What image `name` holds where the volume shows nothing: no colour and
    no coverage (an 'over' of it gives the scene back bit for bit), and
    Blender's own empty depth in the depth pass."""
    if name == PASS_DEPTH:
        return (NO_DEPTH, NO_DEPTH, NO_DEPTH, 1.0)
    if name == PASS_ALPHA:
        return (0.0, 0.0, 0.0, 1.0)
    return (0.0, 0.0, 0.0, 0.0)


def clear_image(img):
    """Fill `img` with empty_pixel of its name."""
    w, h = img.size
    px = np.empty((max(h, 0), max(w, 0), 4), np.float32)
    px[...] = empty_pixel(img.name)
    img.pixels.foreach_set(px.ravel())
    img.update()


def _image_node(tree, name, image, location):
    node = tree.nodes.get(name)
    if node is None:
        node = tree.nodes.new("CompositorNodeImage")
        node.name = node.label = name
        node.location = location
    if node.image != image:
        node.image = image
    return node


def _render_layers(tree):
    """The Render Layers node whose Image carries the render: the one
    linked to the output or to anything, else the first, else a new one."""
    rls = [n for n in tree.nodes if n.bl_idname == "CompositorNodeRLayers"]
    linked = [n for n in rls if n.outputs["Image"].is_linked]
    if linked or rls:
        return (linked or rls)[0]
    return tree.nodes.new("CompositorNodeRLayers")


def _route_through(tree, over):
    """Every link leaving the Render Layers node that feeds the Alpha Over's
    background (other than that one) is moved to leave the Alpha Over."""
    background, _foreground = compat.alpha_over_sockets(over)
    src = _chain_origin(background)
    if src is None or src.node.bl_idname != "CompositorNodeRLayers":
        return  # the user fed the background from elsewhere: theirs to keep
    for link in list(src.links):
        if link.to_node == over or _is_shadow_node(link.to_node):
            continue
        to = link.to_socket
        tree.links.remove(link)
        tree.links.new(over.outputs[0], to)


def ensure_nodes(scene, image):
    """Idempotent: builds the nodes on first use, then re-points them and
    routes new links from Render Layers' Image through the Alpha Over."""
    id_writes.assign(scene.render, "use_compositing", True)
    tree = compat.compositor_tree(scene)
    over = tree.nodes.get(NODE_OVER)
    if over is None:
        over = tree.nodes.new("CompositorNodeAlphaOver")
        over.name = over.label = NODE_OVER
        rl = _render_layers(tree)
        background, _foreground = compat.alpha_over_sockets(over)
        tree.links.new(rl.outputs["Image"], background)
        over.location = (rl.location.x + 300, rl.location.y + 150)
        out = compat.compositor_output_socket(tree)
        if not out.is_linked:  # nothing reached the output: the render does now
            tree.links.new(over.outputs[0], out)
    img_node = _image_node(tree, NODE_IMAGE, image,
                           (over.location.x - 300, over.location.y - 250))
    _background, foreground = compat.alpha_over_sockets(over)
    if not foreground.is_linked:
        tree.links.new(img_node.outputs["Image"], foreground)
    _route_through(tree, over)
    # The image is already premultiplied: a plain premultiplied 'over'.
    compat.alpha_over_premultiplied(over)
    id_writes.assign(over, "mute", False)
    return tree


def remove_nodes(scene):
    """Take the Alpha Over and its Image node out of the tree, giving the
    Alpha Over's links back to whatever fed its background."""
    tree = compat.compositor_tree(scene, create=False)
    if tree is None:
        return
    remove_shadow_chain(scene)
    over = tree.nodes.get(NODE_OVER)
    if over is not None:
        background, _foreground = compat.alpha_over_sockets(over)
        src = background.links[0].from_socket if background.is_linked else None
        targets = [link.to_socket for link in over.outputs[0].links]
        tree.nodes.remove(over)
        if src is not None:
            for to in targets:
                tree.links.new(src, to)
    node = tree.nodes.get(NODE_IMAGE)
    if node is not None:
        tree.nodes.remove(node)


def ensure_pass_nodes(scene, width, height):
    """Separate-layer mode: the pass images at render size and an unlinked
    Image node per pass, for the user to wire. Returns the images."""
    tree = compat.compositor_tree(scene)
    remove_nodes(scene)
    rl = _render_layers(tree)
    images = []
    for i, name in enumerate(PASSES):
        img = ensure_image(width, height, name)
        _image_node(tree, name, img, (rl.location.x, rl.location.y - 350 - 250 * i))
        images.append(img)
    return images


def write_passes(scene, rgba_linear, depth):
    """Fill the pass images (made by ensure_pass_nodes before the frame):
    premultiplied colour, alpha as grey, depth as grey (NO_DEPTH where the
    volume shows nothing). Only pixels change: the compositor runs on the
    copy of the node tree Blender evaluated before this frame's handlers,
    so nodes changed now would not take part in this frame."""
    h, w = rgba_linear.shape[:2]
    color, alpha, zimg = (ensure_image(w, h, name) for name in PASSES)
    color.pixels.foreach_set(np.ascontiguousarray(rgba_linear, np.float32).ravel())
    a = rgba_linear[..., 3]
    one = np.ones_like(a)
    alpha.pixels.foreach_set(np.ascontiguousarray(np.stack([a, a, a, one], -1), np.float32).ravel())
    d = np.where(np.isfinite(depth), depth, NO_DEPTH).astype(np.float32)
    zimg.pixels.foreach_set(np.ascontiguousarray(np.stack([d, d, d, one], -1), np.float32).ravel())
    for img in (color, alpha, zimg):
        img.update()


def clear_passes(scene):
    """Nothing to show: the volume image and the separate-layer passes
    emptied (empty_pixel), so the composite and a user's wiring give the
    scene exactly, and nothing stale from an earlier frame."""
    for name in (IMAGE_NAME,) + PASSES:
        img = bpy.data.images.get(name)
        if img is not None:
            clear_image(img)


def mute(scene):
    tree = compat.compositor_tree(scene, create=False)
    if tree is not None:
        over = tree.nodes.get(NODE_OVER)
        if over is not None:
            id_writes.assign(over, "mute", True)


# ------------------------------------------------- the volume's shadows
# between Render Layers' Image and the Alpha Over's background, a
# chain of nodes (planned by core/shadow_plan.py) multiplies each light
# group's light, or the direct light, by the volume's transmittance:
#
#   Render Layers [Image] --> Voxlight Shadow ... Out --> Alpha Over [bg]
#   Render Layers [Combined_<g>] x Image "Voxlight Shadow <g>" -----^
#
# The volume is then laid over the shadowed render, so it never shadows
# itself. Every node of the chain is named shadow_plan.NODE_PREFIX ...

def _is_shadow_node(node):
    return node.name.startswith(shadow_plan.NODE_PREFIX)


def _chain_origin(socket_in):
    """The output socket that feeds `socket_in`, looking through the shadow
    chain (its first colour input, the running result): what the chain is
    applied to. None when nothing feeds it."""
    seen = 0
    while socket_in.is_linked and seen < 1000:
        src = socket_in.links[0].from_socket
        if not _is_shadow_node(src.node) or src.node.type == "IMAGE":
            return src
        socket_in = compat.mix_sockets(src.node)[0]
        seen += 1
    return None


def _pass_socket(rl, source):
    """The Render Layers output of a plan source ("pass", key): a light
    group's Combined_<g>, or a pass by its names in each version."""
    names = shadow_plan.PASS_SOCKETS.get(source[1], (source[1],))
    for name in names:
        out = rl.outputs.get(name)
        if out is not None and out.enabled:
            return out
    return None


def _source_socket(rl, origin, built, source):
    """The output socket a chain input `source` reads: the chain's origin,
    a Render Layers pass, or an earlier node of the chain (in `built`)."""
    if source[0] == "origin":
        return origin
    if source[0] == "pass":
        return _pass_socket(rl, source)
    node = built.get(source[1])
    if node is None:
        return None
    return node.outputs[0] if node.type == "IMAGE" else compat.mix_sockets(node)[2]


def _chain_matches(tree, nodes, rl, origin, background):
    """Whether the tree already holds exactly the chain of plan `nodes`:
    the same nodes, images and links, its end feeding `background`. Then
    nothing is rebuilt (so a render on a ready scene writes no node)."""
    present = {n.name: n for n in tree.nodes if _is_shadow_node(n)}
    if set(present) != {spec.name for spec in nodes}:
        return False
    for spec in nodes:
        node = present[spec.name]
        if spec.kind == "image":
            if node.type != "IMAGE" or node.image is None or node.image.name != spec.inputs[0]:
                return False
            continue
        if node.type == "IMAGE":
            return False
        for sock, source in zip(compat.mix_sockets(node)[:2], spec.inputs):
            want = _source_socket(rl, origin, present, source)
            if want is None or not sock.is_linked or sock.links[0].from_socket != want:
                return False
    end = compat.mix_sockets(present[shadow_plan.NODE_OUT])[2]
    return background.is_linked and background.links[0].from_socket == end


def ensure_shadow_chain(scene, nodes):
    """Build the chain of plan `nodes` (shadow_plan.node_plan) between what
    feeds the Alpha Over's background (Render Layers' Image) and it,
    replacing an older chain unless it is already this one. Returns ""
    when built, else why not (the chain is then gone and the render
    untouched)."""
    tree = compat.compositor_tree(scene)
    over = tree.nodes.get(NODE_OVER)
    if over is None or not nodes:
        remove_shadow_chain(scene)
        return "no Voxlight nodes in the compositor" if over is None else ""
    background, _foreground = compat.alpha_over_sockets(over)
    origin = _chain_origin(background)
    if origin is not None and origin.node.bl_idname == "CompositorNodeRLayers" \
            and _chain_matches(tree, nodes, origin.node, origin, background):
        return ""
    remove_shadow_chain(scene)
    origin = _chain_origin(background)
    if origin is None or origin.node.bl_idname != "CompositorNodeRLayers":
        return "the Alpha Over's background is not fed by Render Layers"
    rl = origin.node
    # Light groups and passes just added reach the node's outputs only when
    # it is updated (4.x, 5.x): setting its view layer again does that.
    view_layer = scene.view_layers.get(rl.layer)
    if view_layer is not None:
        view_layer.update_render_passes()
    rl.layer = rl.layer
    built = {}
    for spec in nodes:
        if spec.kind == "image":
            img = bpy.data.images.get(spec.inputs[0])
            node = tree.nodes.new("CompositorNodeImage")
            node.image = img
        else:
            node = compat.mix_color_node(tree, spec.kind)
        node.name = node.label = spec.name
        node.location = (rl.location.x + spec.location[0], rl.location.y + spec.location[1])
        built[spec.name] = node
        if spec.kind == "image":
            continue
        for sock, source in zip(compat.mix_sockets(node)[:2], spec.inputs):
            out = _source_socket(rl, origin, built, source)
            if out is None:
                remove_shadow_chain(scene)
                return "Render Layers has no %s output" % source[1]
            tree.links.new(out, sock)
    tree.links.new(compat.mix_sockets(built[shadow_plan.NODE_OUT])[2], background)
    return ""


def remove_shadow_chain(scene):
    """Take the shadow chain out, giving what it fed back to its origin."""
    tree = compat.compositor_tree(scene, create=False)
    if tree is None:
        return
    out = tree.nodes.get(shadow_plan.NODE_OUT)
    if out is not None:
        origin = _chain_origin(compat.mix_sockets(out)[0])
        targets = [link.to_socket for link in compat.mix_sockets(out)[2].links]
    for node in [n for n in tree.nodes if _is_shadow_node(n)]:
        tree.nodes.remove(node)
    if out is not None and origin is not None:
        for to in targets:
            tree.links.new(origin, to)


def ensure_shadow_image(name, width, height):
    """Image `name` for a shadow: grey data, alpha unused."""
    return ensure_image(width, height, name, alpha_mode="STRAIGHT", is_data=True)


def write_shadow_image(name, width, height, shadow):
    """Image `name` (grey, data) holding `shadow` = 1 - transmittance,
    (height, width) float32 row 0 = bottom, or 0 everywhere when None."""
    img = ensure_shadow_image(name, width, height)
    s = np.zeros((height, width), np.float32) if shadow is None else np.asarray(shadow, np.float32)
    one = np.ones_like(s)
    img.pixels.foreach_set(np.ascontiguousarray(np.stack([s, s, s, one], -1), np.float32).ravel())
    img.update()
    return img
