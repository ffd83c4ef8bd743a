"""File › Import › Medical/Scientific Volume: every format libvoxlight loads
(NIfTI, NRRD, MetaImage, TIFF/PNG stacks, OpenVDB, DICOM files and folders),
picked by the library from the extension, the folder or the first bytes.

From the menu the load runs on a worker thread (import_job.ImportJob) while
a modal operator shows progress and cancels on Esc. From scripts,
bpy.ops.voxlight.import_volume(filepath=...) blocks and returns FINISHED or
CANCELLED with an error report. Either way nothing is created before the
load has succeeded, and a failure while creating the object removes what
was made, so a failed or cancelled import leaves bpy.data as it was.
"""

import os

import bpy
import numpy as np
from bpy.props import BoolProperty, EnumProperty, FloatProperty, FloatVectorProperty, StringProperty
from bpy_extras.io_utils import ImportHelper
from mathutils import Matrix

from . import channel_props, label_props, mode_start, preferences, tf
from .core import (framing, import_job, label_import, orientation, runtime, startup_cube,
                   volume_space)


def _to_matrix(a):
    return Matrix([list(map(float, row)) for row in np.asarray(a).reshape(4, 4)])


def resolve_path(filepath, directory):
    """The file, or the folder when no file was picked (the browser then
    gives a filepath ending in a separator, or only the directory). A
    generated volume's name ("phantom:...") passes through: bpy.path.abspath
    only expands "//"."""
    path = bpy.path.abspath(filepath) if filepath else ""
    if (not path or path.endswith(os.sep)) and directory:
        path = bpy.path.abspath(directory)
    return path.rstrip(os.sep) or path


def fill_volume_properties(obj, path, info, v2l, unit_scale):
    """The identity and data fields every Voxlight volume carries (shared by
    imported volumes and Blender Volume objects rendered with Voxlight)."""
    p = obj.voxlight
    p.is_volume = True
    p.filepath = path
    p.unit_scale = unit_scale
    p.voxel_to_local = np.asarray(v2l, np.float64).T.ravel().tolist()
    p.dims = info["dims"]
    p.data_min = info["value_min"]
    p.data_max = info["value_max"]
    p.window_low = info["value_min"]
    p.window_high = info["value_max"]
    if "histogram" in info:
        p.histogram = [int(min(c, 2**31 - 1)) for c in info["histogram"]]
    p.frame_count = info.get("frame_count", 1)
    p.reader_notes = info.get("notes", "")
    channel_props.fill(p, info)  # a multi-channel volume's channels; none otherwise


class VOXLIGHT_OT_import_volume(bpy.types.Operator, ImportHelper):
    """Import a medical or scientific volume (NIfTI, NRRD, MetaImage, TIFF/PNG stack, OpenVDB, DICOM) as a Voxlight volume object"""
    bl_idname = "voxlight.import_volume"
    bl_label = "Import Medical/Scientific Volume"
    bl_options = {"REGISTER", "UNDO"}

    filename_ext = ""
    filter_glob: StringProperty(default=import_job.FILTER_GLOB, options={"HIDDEN"})
    directory: StringProperty(subtype="DIR_PATH", options={"HIDDEN", "SKIP_SAVE"},
                              description="Folder to import when no file is picked "
                                          "(image stack or DICOM series)")
    # Default 0.01: 1 mm becomes 1 cm, so a 180 mm head is 1.8 units across,
    # the size of Blender's default cube. Use 0.001 for true metres.
    unit_scale: FloatProperty(name="Units per mm", default=0.01, min=1e-6, max=1e3,
                              soft_min=0.0001, soft_max=1.0,
                              description="Scene units per millimetre of the scan (0.01: a "
                                          "180 mm head is 1.8 units, the default cube's size; "
                                          "0.001: true metres). OpenVDB files are in scene "
                                          "units already")
    center: BoolProperty(name="Center at Cursor", default=True,
                         description="Put the volume's centre at the 3D cursor instead of "
                                     "at the scanner origin")
    voxel_size: FloatVectorProperty(name="Voxel Size", size=3, default=(1.0, 1.0, 1.0),
                                    min=1e-6, soft_min=0.001, soft_max=100.0, precision=4,
                                    description="x, y, z voxel size in millimetres for inputs "
                                                "without geometry (TIFF/PNG stacks); files with "
                                                "geometry ignore it")
    # DICOM folders with several series: which one (index or UID, as
    # native.list_dicom_series / `voxlight info` list them); "" = the only one.
    series: StringProperty(name="Series", default="",
                           description="Series of a DICOM folder to import: index or "
                                       "SeriesInstanceUID (empty = the only series)")
    # orientation.py: 180 degrees about Z, so Front (numpad 1) shows the face.
    anatomical_views: BoolProperty(
        name="Anatomical Views", default=True,
        description="Blender's views match the anatomy: turn the scan so Front (numpad 1) "
                    "shows the face, Top the top of the head, and Left/Right the patient's right/left side, as for a Blender character. "
                    "Off keeps the scanner's (RAS) axes. Image stacks and OpenVDB have no anatomy "
                    "and are never turned")
    frame_in_view: BoolProperty(name="Frame in View", default=True,
                                description="Point every 3D viewport at the imported volume "
                                            "(as View Selected does)")
    # label maps (core/label_import.py decides, label_props.py holds them).
    import_as: EnumProperty(name="Import As", default="AUTO",
                            items=[m + (i,) for i, m in enumerate(label_import.IMPORT_MODES)],
                            description="An intensity volume, or a label map (integer volume of "
                                        "label ids named by a lookup file beside it)")
    lookup_file: StringProperty(name="Lookup File", default="", subtype="FILE_PATH",
                                description="Label names and colours (empty = the first lookup "
                                            "file found beside the image)")
    # core/startup_cube.py: why hiding it is the right first sight.
    hide_startup_cube: BoolProperty(
        name="Hide Startup Cube", default=True,
        description="Hide the factory startup Cube (unedited, at the origin) from the viewport "
                    "and renders when it overlaps the volume, so the volume is what you see. "
                    "The Outliner's eye (or Alt+H) shows it again; undo restores it")
    # Set by invoke: the file browser path runs modal, scripts block.
    use_modal: BoolProperty(default=False, options={"HIDDEN", "SKIP_SAVE"})

    def invoke(self, context, event):
        self.use_modal = True
        return ImportHelper.invoke(self, context, event)

    def execute(self, context):
        path = resolve_path(self.filepath, self.directory)
        preferences.sync(context)  # streaming mode and cache folder
        opts = runtime.options_of(context.scene.voxlight)  # backend, storage, memory budget
        if self.use_modal and context.window is not None:
            self._job = import_job.ImportJob(path, tuple(self.voxel_size), series=self.series, **opts)
            wm = context.window_manager
            wm.progress_begin(0.0, 1.0)
            self._timer = wm.event_timer_add(0.1, window=context.window)
            wm.modal_handler_add(self)
            return {"RUNNING_MODAL"}
        job = import_job.ImportJob(path, tuple(self.voxel_size), start=False, series=self.series, **opts)
        job.run()
        return self._finish(context, job)

    def modal(self, context, event):
        job = self._job
        if event.type == "ESC":
            job.cancel()
            self._end_modal(context)
            self.report({"WARNING"}, "Voxlight: import of %s cancelled" % os.path.basename(job.path))
            return {"CANCELLED"}
        if event.type == "TIMER":
            context.window_manager.progress_update(job.progress)
            _show_status(context, job)
            if job.done:
                self._end_modal(context)
                return self._finish(context, job)
        return {"PASS_THROUGH"}

    def cancel(self, context):  # Blender ends the operator (e.g. the file closes)
        self._job.cancel()
        self._end_modal(context)

    def _end_modal(self, context):
        wm = context.window_manager
        wm.event_timer_remove(self._timer)
        wm.progress_end()
        _show_status(context, None)

    def _finish(self, context, job):
        """Creates the object from a finished job, or reports its error."""
        name = os.path.basename(job.path)
        if job.error is not None:
            # Nothing has been created yet, so a failure leaves no trace.
            self.report({"ERROR"}, "Voxlight: cannot import %s: %s" % (name, job.error))
            return {"CANCELLED"}
        entry = job.take()
        if entry is None:
            self.report({"WARNING"}, "Voxlight: import of %s cancelled" % name)
            return {"CANCELLED"}
        labels, err = self._label_plan(context, job.path, entry.info)
        if err:
            entry.close()
            self.report({"ERROR"}, "Voxlight: cannot import %s as labels: %s" % (name, err))
            return {"CANCELLED"}
        if labels is not None and labels[0] == "attach":
            entry.close()  # the active volume keeps its own renderer; it gets the label file
            target = context.view_layer.objects.active
            label_props.attach(target, job.path, labels[1], labels[2], "tint")
            self.report({"INFO"}, "Voxlight: %s (%d labels) attached to %s"
                        % (name, len(target.voxlight_labels.labels), target.name))
            return {"FINISHED"}
        try:
            obj = self._create_object(context, job.path, entry.info)
            if labels is not None:
                label_props.attach(obj, job.path, labels[1], labels[2], "surface")
        except Exception as e:
            entry.close()
            self.report({"ERROR"}, "Voxlight: cannot import %s: %s" % (name, e))
            return {"CANCELLED"}
        runtime.adopt(entry)
        self.report({"INFO"}, import_job.import_report(name, entry.info, self._why)
                    + self._cube_note)
        return {"FINISHED"}

    def _label_plan(self, context, path, info):
        """((kind, lookup, table) or None for an intensity volume, error).
        Sets self._why: what the volume became and why, for the report."""
        lookup = bpy.path.abspath(self.lookup_file) if self.lookup_file else ""
        if self.import_as == "AUTO":  # labels only on evidence (core/label_import.guess)
            kind, lookup, why = label_import.guess(
                info["dtype"], info.get("distinct_ids"), label_import.candidates(path, lookup),
                _lookup_ids)
            self._why = ("as a label map: " if kind == "new" else "as an intensity volume: ") + why
            if kind == "intensity":
                return None, ""
            table, err = label_props.read_lookup(lookup)
            return ("new", lookup, table), err
        self._why = ("as an intensity volume" if self.import_as == "INTENSITY"
                     else "as a label map: chosen in the importer")
        kind, lookup = label_import.plan(self.import_as, path, lookup)
        kind, err = label_import.check(kind, self.import_as, info["dtype"], lookup, path,
                                       value_range=(info["value_min"], info["value_max"]))
        if err or kind == "intensity":
            return None, err
        if kind == "attach":
            target = context.view_layer.objects.active
            if target is None or not target.voxlight.is_volume:
                return None, "no active Voxlight volume to attach the labels to"
        table, err = label_props.read_lookup(lookup)
        return (kind, lookup, table), err

    def _create_object(self, context, path, info):
        dims = info["dims"]
        cursor = context.scene.cursor.location if self.center else None
        unit_scale = 1.0 if import_job.is_vdb(path) else self.unit_scale
        turn = orientation.choose(self.anatomical_views, info, import_job.is_vdb(path))
        s_from_v = volume_space.scene_from_voxel(orientation.oriented_affine(info["affine"], turn),
                                                 dims, unit_scale, center_at=cursor)
        obj = bpy.data.objects.new(import_job.display_name(path), None)
        try:
            obj.empty_display_type = "CUBE"
            obj.empty_display_size = 1.0
            # Not "in front": Blender then depth-tests the wire cube against the
            # scene, so meshes hide it (in front, it drew over them). Its lines
            # enter the depth buffer the viewport reads at POST_VIEW, and rays
            # stop at them: right, since that is where the lines are (a back
            # edge stops rays behind everything inside the box, a front edge
            # hides what is behind it, like any wire in front).
            obj.show_in_front = False
            obj.matrix_world = _to_matrix(volume_space.object_matrix(s_from_v, dims))
            # Blender keeps loc/rot/scale only; whatever it could not hold
            # (shear) stays in voxel_to_local so the render remains exact.
            v2l = volume_space.voxel_to_local(s_from_v, np.array(obj.matrix_world))
            fill_volume_properties(obj, path, info, v2l, unit_scale)
            obj.voxlight.series = self.series
            obj.voxlight.orientation = turn
            context.collection.objects.link(obj)
            tf.ensure_texture(obj, info)  # the preset that suits the data, fitted to it
            mode_start.fit_iso(obj, info)  # ISO shows a surface the first time it is picked
        except Exception:
            tex = obj.voxlight.tf_texture
            if tex is not None:
                bpy.data.textures.remove(tex)
            bpy.data.objects.remove(obj)
            raise
        for o in context.view_layer.objects:
            o.select_set(False)
        obj.select_set(True)
        context.view_layer.objects.active = obj
        self._cube_note = hide_startup_cube(context, obj) if self.hide_startup_cube else ""
        if self.frame_in_view:
            frame_in_views(context, obj)
        return obj


def hide_startup_cube(context, obj):
    """Hides the factory Cube when it overlaps the new volume's box
    (core/startup_cube.py says when and why); returns the sentence the
    import report adds, "" when nothing was hidden."""
    model = np.array(obj.matrix_world, np.float64) @ \
        np.array(obj.voxlight.voxel_to_local, np.float64).reshape(4, 4).T
    corners = volume_space.world_corners(model, tuple(obj.voxlight.dims))
    box = (np.min(corners, 0), np.max(corners, 0))
    for ob in context.view_layer.objects:
        if ob.type != "MESH" or ob.hide_get() or not startup_cube.is_factory_cube(
                ob.name, ob.type, len(ob.data.vertices), ob.matrix_world,
                [tuple(c) for c in ob.bound_box]):
            continue
        if not startup_cube.overlaps(box, startup_cube.world_box(ob.matrix_world, ob.bound_box)):
            continue
        ob.hide_set(True)
        ob.hide_render = True
        return "; hid the startup Cube, which hid the volume (Outliner or Alt+H shows it)"
    return ""


def _lookup_ids(path):
    """The ids a lookup file names, or None when it is no lookup file."""
    table, _err = label_props.read_lookup(path)
    return None if table is None else [t["id"] for t in table]


def _show_status(context, job):
    """The status bar while a file is opened: what the library's
    first pass is doing and how far it is, and that Esc cancels; job None
    gives the status bar back."""
    workspace = getattr(context, "workspace", None)
    if workspace is None:
        return
    if job is None:
        workspace.status_text_set(None)
        return
    what = job.stage or "loading"
    workspace.status_text_set("Voxlight: %s %s: %d%% (Esc cancels)"
                              % (what, os.path.basename(job.path), round(job.progress * 100)))


def frame_in_views(context, obj):
    """Points every 3D viewport of every window at the volume's box
    (framing.py). Views through a camera or locked to an object are left
    alone: moving them would move the user's camera or fight the lock.
    Headless (no windows) there is nothing to do."""
    model = np.array(obj.matrix_world, np.float64) @ \
        np.array(obj.voxlight.voxel_to_local, np.float64).reshape(4, 4).T
    corners = volume_space.world_corners(model, tuple(obj.voxlight.dims))
    for win in context.window_manager.windows:
        for area in win.screen.areas:
            if area.type != "VIEW_3D":
                continue
            space = area.spaces.active
            if getattr(space, "lock_object", None) is not None:
                continue
            for region in area.regions:
                r3d = region.data if region.type == "WINDOW" else None
                if r3d is None or r3d.view_perspective == "CAMERA" or region.width < 1 \
                        or region.height < 1:
                    continue
                centre, dist = framing.frame(corners, space.lens, region.width, region.height,
                                             perspective=r3d.view_perspective == "PERSP")
                r3d.view_location = tuple(centre)
                r3d.view_distance = dist
            area.tag_redraw()


def menu_import(self, context):
    self.layout.operator(VOXLIGHT_OT_import_volume.bl_idname,
                         text="Medical/Scientific Volume (.nii, .nrrd, .mha, .tif, .vdb, DICOM...)")


def register():
    bpy.utils.register_class(VOXLIGHT_OT_import_volume)
    bpy.types.TOPBAR_MT_file_import.append(menu_import)


def unregister():
    bpy.types.TOPBAR_MT_file_import.remove(menu_import)
    bpy.utils.unregister_class(VOXLIGHT_OT_import_volume)
