"""Convert to Blender Volume: the active Voxlight volume, classified as it
looks now (transfer function, window, opacity, gradient opacity, clip
planes and crop box, the frame shown of a 4D series), written as an
OpenVDB file with a "density" grid (extinction per world unit) and a
"color" grid, and a Volume object that shows it with a Principled Volume
material: docs/physical_model.md says why these settings reproduce what
Voxlight draws. Cycles and EEVEE then render it natively."""

import os
import time

import bpy
import numpy as np
from bpy.props import IntProperty, StringProperty

from . import compat, params
from .core import budget_split, lighting, native, runtime, vdb_export
from .operators import OnActiveVolume


def cell_shift():
    """Index space as this Blender draws it -> OpenVDB's (and
    vxl_grid_info.index_to_world's), where cell i is centred at i: before
    5.0 Blender centres it at i + 0.5 (compat.volume_cell_offset), so the
    file's transform starts that much back and each value lands where
    Voxlight samples it."""
    m = np.eye(4)
    m[:3, 3] = -compat.volume_cell_offset()
    return m


def default_path(obj, volume_frame):
    """Beside the .blend file, else in Blender's temporary folder; a name
    no file has yet, so an earlier conversion (and the Volume reading it)
    keeps its own."""
    stem = "%s_frame%04d" % (bpy.path.clean_name(obj.name), volume_frame)
    folder = bpy.path.abspath("//voxlight_volumes") if bpy.data.filepath else \
        (bpy.app.tempdir or os.path.dirname(bpy.app.binary_path))
    path, n = os.path.join(folder, stem + ".vdb"), 1
    while os.path.exists(path):
        path, n = os.path.join(folder, "%s_%d.vdb" % (stem, n)), n + 1
    return path


def forget_cached_grids(path):
    """Blender caches a file's grids by path: Volumes that read a file
    being written over let go of theirs, so every reader sees the new one."""
    for v in bpy.data.volumes:
        if os.path.abspath(bpy.path.abspath(v.filepath)) == os.path.abspath(path):
            v.grids.unload()


def _cpu_volume(path, props, volume_frame, budget):
    """The volume's voxels on the CPU: the renderer keeps none once they
    are on the GL side, so the frame is read again (whole, not streamed)."""
    lib = native.load_library()
    if runtime.is_phantom(path):
        return native.Volume.phantom(path, lib=lib)
    return native.Volume.load(path, lib=lib, frame=volume_frame, series=props.series or None, streaming="off",
                              memory_budget=budget_split.volume_share(budget))


def principled_material(name, props):
    """A material whose Principled Volume takes the density grid as Density
    and the color grid as Color with a black Absorption Color, so extinction
    = density and albedo = color (docs/physical_model.md). Without shading
    (pure emission-absorption) the volume emits density * color instead and
    scatters nothing."""
    mat = bpy.data.materials.new(name)
    if bpy.app.version < (5, 0, 0):  # 5.0: materials always use nodes
        mat.use_nodes = True
    nt = mat.node_tree
    nt.nodes.clear()
    pv = nt.nodes.new("ShaderNodeVolumePrincipled")
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    out.location = (300, 0)
    nt.links.new(pv.outputs[0], out.inputs["Volume"])
    pv.inputs["Density"].default_value = 1.0
    pv.inputs["Density Attribute"].default_value = "density"
    pv.inputs["Absorption Color"].default_value = (0.0, 0.0, 0.0, 1.0)
    if props.shading:
        pv.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
        pv.inputs["Color Attribute"].default_value = "color"
        scatter = lighting.shading_model_of(props) == "scatter"
        pv.inputs["Anisotropy"].default_value = props.anisotropy if scatter else 0.0
    else:
        pv.inputs["Color"].default_value = (0.0, 0.0, 0.0, 1.0)
        pv.inputs["Color Attribute"].default_value = ""
        dens = nt.nodes.new("ShaderNodeAttribute")
        dens.attribute_name = "density"
        col = nt.nodes.new("ShaderNodeAttribute")
        col.attribute_name = "color"
        dens.location, col.location = (-300, 0), (-300, -200)
        nt.links.new(dens.outputs["Fac"], pv.inputs["Emission Strength"])
        nt.links.new(col.outputs["Color"], pv.inputs["Emission Color"])
    return mat


def add_volume_object(context, src, path):
    """A Volume object reading path, placed as src (its grids are in src's
    local space, so moving the object moves the volume)."""
    data = bpy.data.volumes.new(src.name + " Volume")
    data.filepath = bpy.path.relpath(path) if bpy.data.filepath else path
    # Every cell written holds extinction: none is below a cut-off.
    data.render.clipping = 0.0
    # The density grid is per world unit; Blender's default (OBJECT) would
    # scale it by the object's scale.
    data.render.space = "WORLD"
    ob = bpy.data.objects.new(src.name + " Volume", data)
    ob.matrix_world = src.matrix_world
    context.scene.collection.objects.link(ob)
    data.materials.append(principled_material(src.name + " Volume", src.voxlight))
    return ob


class VOXLIGHT_OT_convert_to_blender_volume(OnActiveVolume, bpy.types.Operator):
    """Write the active volume, classified as it looks now (clip planes and
    crop box baked in, the current frame of a 4D series), as an OpenVDB file
    of density and color grids, and add a Volume object with a Principled
    Volume material that Cycles and EEVEE render natively"""
    bl_idname = "voxlight.convert_to_blender_volume"
    bl_label = "Convert to Blender Volume"
    bl_options = {"REGISTER", "UNDO"}

    resolution: IntProperty(name="Resolution", default=0, min=0, max=4096,
                            description="Cells along the volume's longest axis; 0 = one cell per voxel")
    filepath: StringProperty(name="File", subtype="FILE_PATH", default="",
                             description="Where the .vdb goes; empty = beside the .blend file "
                                         "(voxlight_volumes/), or the temporary folder when unsaved")

    def execute(self, context):
        t0 = time.perf_counter()
        src = context.object
        props = src.voxlight
        try:
            ob, path, size, dims = self._convert(context, src, props)
        except (native.VoxlightError, vdb_export.ExportError) as e:
            self.report({"ERROR"}, "Voxlight: %s" % e)
            return {"CANCELLED"}
        seconds = time.perf_counter() - t0
        self.report({"INFO"}, "Voxlight: wrote %s (%.2f MiB, %d x %d x %d cells) in %.2f s"
                    % (path, size / 1048576.0, dims[0], dims[1], dims[2], seconds))
        return {"FINISHED"}

    def _convert(self, context, src, props):
        writer = vdb_export.writer_path(native.load_library().source_path)
        scene = context.scene
        opts = runtime.options_of(scene.voxlight)
        source = bpy.path.abspath(props.filepath) if not runtime.is_phantom(props.filepath) else props.filepath
        entry = runtime.entry_for(source, props, scene.frame_current, **opts)
        dims = vdb_export.grid_dims(entry.info["dims"], self.resolution)
        # the CPU copy read for classifying: the renderer's own is on the GL side
        volume_bytes = int(np.prod(entry.info["dims"], dtype=np.int64)) * (entry.info.get("texture_bits") or 32) // 8
        vdb_export.check_budget(dims, volume_bytes, opts["memory_budget"])
        path = bpy.path.abspath(self.filepath or default_path(src, entry.frame))
        vol = _cpu_volume(source, props, entry.frame, opts["memory_budget"])
        try:
            # the scalar is classified (a multi-channel volume's channel 0)
            p = native.make_params(model=params.model_matrix(src),
                                   **params.look_kwargs(props, channels=False))
            info, density, rgb = vol.classified_grid(p, dims)
        finally:
            vol.close()
        index_to_local = np.linalg.inv(np.array(src.matrix_world, np.float64)) @ info["index_to_world"] @ cell_shift()
        forget_cached_grids(path)
        size = vdb_export.write(writer, path, info["dims"], index_to_local, density, rgb)
        ob = add_volume_object(context, src, path)
        for o in context.view_layer.objects:
            o.select_set(False)
        ob.select_set(True)
        context.view_layer.objects.active = ob
        return ob, path, size, info["dims"]


_classes = (VOXLIGHT_OT_convert_to_blender_volume,)


def register():
    for c in _classes:
        bpy.utils.register_class(c)


def unregister():
    for c in reversed(_classes):
        bpy.utils.unregister_class(c)
