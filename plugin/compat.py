"""The one place that knows how Blender's Python API differs between the
releases Voxlight supports (3.4 up to 5.x). Everything else calls these
helpers instead of testing versions itself.

Differences handled here:
  * 5.0 removed scene.node_tree and scene.use_nodes for the compositor: the
    compositing tree is a node group data-block (scene.compositing_node_group)
    whose Group Output replaces the Composite node (also removed);
  * 5.0 turned Alpha Over's options into input sockets and reordered them
    (Background, Foreground, Factor, Type, Straight Alpha); before, the
    inputs were Fac, Image (background), Image (foreground) with
    use_premultiply/premul properties ("Straight Alpha" exists as a socket
    from 4.5 as well);
  * 5.0 removed the compositor's Mix node (CompositorNodeMixRGB): the
    shared Mix node (ShaderNodeMix, colour mode) takes its place;
  * 4.2 made add-ons extensions: the package is then bl_ext.<repo>.voxlight,
    so code uses __package__, never a hard-coded module name; an extension
    keeps its files in its own user folder (private_data_dir).

The version gate (unsupported_message) is bpy-free so it can be tested in
plain Python.
"""

MIN_BLENDER = (3, 4, 0)


def unsupported_message(version):
    """None when this Blender version is supported, else the sentence the
    preferences and the console show instead of a traceback."""
    version = tuple(version)[:3]
    if version >= MIN_BLENDER:
        return None
    return ("Voxlight needs Blender %s or newer; this is Blender %s. "
            "Install a newer Blender from blender.org to use the add-on."
            % (".".join(map(str, MIN_BLENDER)), ".".join(map(str, version))))


def private_data_dir(package):
    """A folder Blender gives this add-on for its own files: the extension's
    user folder (4.2+, kept across updates), or None for a legacy add-on."""
    bpy = _bpy()
    if not package.startswith("bl_ext.") or not hasattr(bpy.utils, "extension_path_user"):
        return None
    try:
        return bpy.utils.extension_path_user(package, path="lib", create=True) or None
    except (OSError, ValueError):
        return None


# ------------------------------------------------------------ compositor

def _bpy():
    import bpy
    return bpy


def volume_cell_offset():
    """Where Blender draws a Volume grid's cell i, in index space: 3.4 to
    4.5 over the cube [i, i + 1] (centred at i + 0.5), 5.0 on at i as
    OpenVDB defines it (measured by tests/blender/test_blender_volume.py)."""
    return 0.5 if _bpy().app.version < (5, 0, 0) else 0.0


def has_compositing_node_group(scene):
    return hasattr(scene, "compositing_node_group")  # Blender 5.0+


def compositor_tree(scene, create=True):
    """The scene's compositing node tree, made (and turned on) when create
    is set; None when there is none and create is not set."""
    if has_compositing_node_group(scene):
        tree = scene.compositing_node_group
        if tree is None and create:
            bpy = _bpy()
            tree = bpy.data.node_groups.new("Compositing", "CompositorNodeTree")
            tree.interface.new_socket("Image", in_out="OUTPUT", socket_type="NodeSocketColor")
            rl = tree.nodes.new("CompositorNodeRLayers")
            out = tree.nodes.new("NodeGroupOutput")
            out.location = (400, 0)
            tree.links.new(rl.outputs["Image"], out.inputs[0])
            scene.compositing_node_group = tree
        return tree
    if create and not scene.use_nodes:
        scene.use_nodes = True
    return scene.node_tree if (create or scene.use_nodes) else None


def compositor_output_socket(tree):
    """The input socket whose image becomes the render result: the
    Composite node's (up to 4.5) or the Group Output's first (5.0+, where
    the Composite node no longer exists). Made when missing."""
    has_composite = hasattr(_bpy().types, "CompositorNodeComposite")
    kind = "CompositorNodeComposite" if has_composite else "NodeGroupOutput"
    outs = [n for n in tree.nodes if n.bl_idname == kind and n.inputs]
    active = [n for n in outs if getattr(n, "is_active_output", True)]
    if active or outs:
        return (active or outs)[0].inputs[0]
    if not has_composite and not [s for s in tree.interface.items_tree
                                  if getattr(s, "in_out", "") == "OUTPUT"]:
        tree.interface.new_socket("Image", in_out="OUTPUT", socket_type="NodeSocketColor")
    out = tree.nodes.new(kind)
    out.location = (600, 0)
    return out.inputs[0]


def alpha_over_sockets(node):
    """(background, foreground) inputs of an Alpha Over node."""
    if "Background" in node.inputs:  # 5.0+
        return node.inputs["Background"], node.inputs["Foreground"]
    return node.inputs[1], node.inputs[2]


def alpha_over_premultiplied(node):
    """Make an Alpha Over a plain premultiplied 'over' (our image is
    premultiplied already)."""
    from . import id_writes  # here: on an unsupported Blender only this module loads
    straight = node.inputs.get("Straight Alpha")
    if straight is not None:
        id_writes.assign(straight, "default_value", False)
    if hasattr(node, "use_premultiply"):  # up to 4.5
        id_writes.assign(node, "use_premultiply", False)
        id_writes.assign(node, "premul", 0.0)


def mix_color_node(tree, blend_type):
    """A compositor node mixing two colours with `blend_type` (MULTIPLY,
    ADD, SUBTRACT, ...) at factor 1, unclamped: the Mix node up to 4.5
    (CompositorNodeMixRGB), the shared Mix node in colour mode from 5.0,
    which removed the compositor's own."""
    if hasattr(_bpy().types, "CompositorNodeMixRGB"):
        node = tree.nodes.new("CompositorNodeMixRGB")
        node.use_clamp = False
        node.inputs[0].default_value = 1.0
    else:
        node = tree.nodes.new("ShaderNodeMix")
        node.data_type = "RGBA"
        node.clamp_result = False
        node.clamp_factor = True
        _socket(node.inputs, "Factor_Float").default_value = 1.0
    node.blend_type = blend_type
    return node


def _socket(sockets, identifier):
    return next(s for s in sockets if s.identifier == identifier)


def mix_sockets(node):
    """(first colour input, second colour input, output) of a node made by
    mix_color_node."""
    if node.bl_idname == "ShaderNodeMix":
        return (_socket(node.inputs, "A_Color"), _socket(node.inputs, "B_Color"),
                _socket(node.outputs, "Result_Color"))
    return node.inputs[1], node.inputs[2], node.outputs[0]


def wrap(text, width):
    """Lines of at most width characters, broken at spaces (UI labels do
    not wrap by themselves)."""
    lines, line = [], ""
    for word in text.split():
        if line and len(line) + 1 + len(word) > width:
            lines.append(line)
            line = word
        else:
            line = "%s %s" % (line, word) if line else word
    return lines + [line] if line else lines
