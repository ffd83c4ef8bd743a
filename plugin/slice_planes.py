"""Slice planes: a mesh plane marked as a slice of a volume
(Object.voxlight_slice) shows the volume resampled on it, with the
volume's window and colour map: vxl_render_slice writes an Image, and an
emission material on the plane shows it (transparent where the plane
leaves the volume). Being an ordinary material, it shows in the viewport
and in F12 with any engine.

The image is rewritten when the plane, the volume or a setting changes
(depsgraph_update_post), on every frame change, including each frame of an
animation render (frame_change_post: the render's own depsgraph, so
animated planes and volumes are taken at the frame being rendered), and
after a file loads. A key of everything the image depends on skips
rewrites that would change nothing (writing the image itself triggers
another depsgraph update).

The pure parts (the slice square of a plane, the image size, where each
pixel lies) are in core/slice_plane.py."""

import bpy
import numpy as np
from bpy.app.handlers import persistent
from bpy.props import EnumProperty, IntProperty, PointerProperty

from . import app_handlers, params
from .properties import INTERPOLATION_ITEMS
from .core import native, runtime, slice_plane

IMAGE_PREFIX = "Voxlight Slice "
MATERIAL_PREFIX = "Voxlight Slice "
_keys = {}       # plane object name -> key of the image it shows
_errors = {}     # plane object name -> why its image could not be made ("" when fine)
update_count = 0  # images written (tests)


def _is_volume(self, ob):
    return ob.voxlight.is_volume


def _changed(self, context):
    ob = self.id_data
    _keys.pop(ob.name, None)
    if context is not None and context.scene is not None:
        update(ob, context.scene, None)


class VoxlightSliceProperties(bpy.types.PropertyGroup):
    volume: PointerProperty(type=bpy.types.Object, name="Slice of", poll=_is_volume,
                            update=_changed,
                            description="The Voxlight volume this plane shows, resampled on the "
                                        "plane with the volume's window and colour map")
    interpolation: EnumProperty(name="Interpolation", default="linear", update=_changed,
                                items=INTERPOLATION_ITEMS,
                                description="How values between voxels are worked out")
    resolution: IntProperty(name="Resolution", default=512, min=8, max=4096, update=_changed,
                            description="Most pixels along the image's longer side (fewer when "
                                        "a voxel is larger than a pixel would be)")


def is_slice(ob):
    return ob is not None and ob.type == "MESH" and ob.voxlight_slice.volume is not None


def error(ob):
    return _errors.get(ob.name, "")


# ------------------------------------------------------- image and material

def _image(ob, w, h):
    name = IMAGE_PREFIX + ob.name
    img = bpy.data.images.get(name)
    if img is not None and tuple(img.size) != (w, h):
        bpy.data.images.remove(img)
        img = None
    if img is None:
        img = bpy.data.images.new(name, w, h, alpha=True, float_buffer=True)
    # Float images hold scene-linear colour, as the library's slices are
    # (params.look_kwargs asks for it).
    img.alpha_mode = "PREMUL"
    return img


def _material(ob, img):
    name = MATERIAL_PREFIX + ob.name
    mat = bpy.data.materials.get(name)
    if mat is None:
        mat = bpy.data.materials.new(name)
        if bpy.app.version < (5, 0, 0):  # 5.0: materials always use nodes
            mat.use_nodes = True
        nt = mat.node_tree
        nt.nodes.clear()
        coord = nt.nodes.new("ShaderNodeTexCoord")
        tex = nt.nodes.new("ShaderNodeTexImage")
        tex.name = "Voxlight Slice"
        tex.interpolation = "Closest"  # the slice is resampled already: show its pixels
        tex.extension = "CLIP"
        emit = nt.nodes.new("ShaderNodeEmission")
        clear = nt.nodes.new("ShaderNodeBsdfTransparent")
        mix = nt.nodes.new("ShaderNodeMixShader")
        out = nt.nodes.new("ShaderNodeOutputMaterial")
        for i, n in enumerate((coord, tex, emit, mix, out)):
            n.location = (i * 220 - 440, 0)
        clear.location = (220, -160)
        # Generated coordinates are the mesh's bounding box as [0, 1]^3: the slice square.
        nt.links.new(coord.outputs["Generated"], tex.inputs["Vector"])
        nt.links.new(tex.outputs["Color"], emit.inputs["Color"])
        nt.links.new(tex.outputs["Alpha"], mix.inputs[0])
        nt.links.new(clear.outputs[0], mix.inputs[1])
        nt.links.new(emit.outputs[0], mix.inputs[2])
        nt.links.new(mix.outputs[0], out.inputs["Surface"])
        if hasattr(mat, "blend_method"):  # EEVEE before 4.2; 4.2+ dithers by default
            mat.blend_method = "HASHED"
    tex = mat.node_tree.nodes.get("Voxlight Slice")
    if tex is not None and tex.image != img:
        tex.image = img
    mesh = ob.data
    if not mesh.materials:
        mesh.materials.append(mat)
    elif mesh.materials[0] != mat:
        mesh.materials[0] = mat
    return mat


# ------------------------------------------------------------ resampling

def _evaluated(ob, depsgraph):
    return ob.evaluated_get(depsgraph) if depsgraph is not None else ob


def slice_inputs(ob, scene, depsgraph):
    """(entry, params, plane_to_world, interpolation, key) of a slice plane
    as it is now. Raises ValueError or native errors with a message."""
    props = ob.voxlight_slice
    vol = props.volume
    if vol is None or not vol.voxlight.is_volume:
        raise ValueError("pick the volume this plane slices")
    pe, ve = _evaluated(ob, depsgraph), _evaluated(vol, depsgraph)
    corners = np.array([tuple(c) for c in pe.bound_box], np.float64)
    plane = slice_plane.plane_to_world(np.array(pe.matrix_world, np.float64), corners.min(0),
                                       corners.max(0))
    model = params.model_matrix(ve)
    w, h = slice_plane.image_size(plane, model, props.resolution)
    look = params.look_kwargs(vol.voxlight)
    p = native.make_params(width=w, height=h, model=model, preset=look["preset"],
                           window=look["window"], tf_rgba=look["tf_rgba"],
                           color_space=look["color_space"])
    entry = runtime.entry_for(bpy.path.abspath(vol.voxlight.filepath), vol.voxlight,
                              scene.frame_current, **runtime.options_of(scene.voxlight))
    interp = props.interpolation
    key = native.params_digest(p, entry.identity, plane.tobytes(), interp)
    return entry, p, plane, interp, key


def update(ob, scene, depsgraph):
    """Rewrite the slice image of plane `ob` when what it shows changed.
    Returns True when it was written. Never raises: a problem is kept for
    the panel (error(ob)) and printed once."""
    global update_count
    if not is_slice(ob):
        return False
    try:
        entry, p, plane, interp, key = slice_inputs(ob, scene, depsgraph)
        if _keys.get(ob.name) == key and bpy.data.images.get(IMAGE_PREFIX + ob.name) is not None:
            return False
        rgba = entry.renderer.render_slice(p, plane, interp)
    except (ValueError, native.VoxlightError, native.LibraryUnavailable) as e:
        msg = str(e)
        if _errors.get(ob.name) != msg:
            print("Voxlight: slice plane %s: %s" % (ob.name, msg))
        _errors[ob.name] = msg
        _keys.pop(ob.name, None)
        return False
    _errors[ob.name] = ""
    img = _image(ob, p.width, p.height)  # ob is the original (scene.objects)
    img.pixels.foreach_set(np.ascontiguousarray(rgba, np.float32).ravel())
    img.update()
    _material(ob, img)
    _keys[ob.name] = key
    update_count += 1
    return True


def update_all(scene, depsgraph=None):
    n = 0
    for ob in scene.objects:
        if is_slice(ob):
            n += update(ob, scene, depsgraph)
    return n


@persistent
def on_depsgraph_update(scene, depsgraph=None, *args):
    update_all(scene, depsgraph)


@persistent
def on_frame_change(scene, depsgraph=None, *args):
    update_all(scene, depsgraph)


@persistent
def on_load_post(*args):
    _keys.clear()
    _errors.clear()
    for scene in bpy.data.scenes:
        update_all(scene)


_handlers = ((bpy.app.handlers.depsgraph_update_post, on_depsgraph_update),
             (bpy.app.handlers.frame_change_post, on_frame_change),
             (bpy.app.handlers.load_post, on_load_post))


def register():
    bpy.utils.register_class(VoxlightSliceProperties)
    bpy.types.Object.voxlight_slice = PointerProperty(type=VoxlightSliceProperties)
    app_handlers.add(_handlers)


def unregister():
    app_handlers.remove(_handlers)
    del bpy.types.Object.voxlight_slice
    bpy.utils.unregister_class(VoxlightSliceProperties)
