"""Headless Blender: the one importer (File › Import › Medical/Scientific
Volume) on every format family, folders, the voxel size for stacks, OpenVDB
in scene units, and failures that leave bpy.data exactly as it was.

blender -b --factory-startup --python-exit-code 1 --python tests/blender/test_import.py
"""

import os
import sys

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "cli"))
import _util as u  # noqa: E402
from _util import test  # noqa: E402
from helper_reply import notes_helper  # noqa: E402
from test_cli_formats import blob, write_mha, write_nrrd, write_png, write_tiff  # noqa: E402
from vdb_write import write_vdb  # noqa: E402

vx = u.install_addon()

# Every kind of datablock an import could leave behind.
_COLLECTIONS = ("objects", "textures", "images", "meshes", "materials", "node_groups", "volumes",
                "collections")


def _snapshot():
    return {c: set(getattr(bpy.data, c)) for c in _COLLECTIONS}


def _expect_failure(needle, **kw):
    before = _snapshot()
    try:
        res = bpy.ops.voxlight.import_volume(**kw)
    except RuntimeError as e:  # background mode turns ERROR reports into exceptions
        msg = str(e)
    else:
        raise AssertionError("no error report (%s)" % res)
    assert "Voxlight: cannot import" in msg and needle in msg, msg
    assert _snapshot() == before, "a failed import left datablocks behind"


@test
def menu_entry_lists_every_format():
    rna = bpy.ops.voxlight.import_volume.get_rna_type()
    glob = rna.properties["filter_glob"].default.split(";")
    for pattern in ("*.nii", "*.nii.gz", "*.hdr", "*.img", "*.nrrd", "*.nhdr", "*.mha", "*.mhd",
                    "*.tif", "*.tiff", "*.png", "*.vdb", "*.dcm", "DICOMDIR"):
        assert pattern in glob, pattern
    assert "Medical/Scientific" in rna.name


@test
def nrrd_mha_and_tiff_import():
    u.reset_scene()
    d = blob((12, 10, 8), np.int16)
    write_nrrd(os.path.join(u.TMP, "b.nrrd"), d, extra="spacings: 1 2 3\n")
    write_mha(os.path.join(u.TMP, "b.mha"), d)
    for name in ("b.nrrd", "b.mha"):
        ob = u.import_volume(os.path.join(u.TMP, name), unit_scale=0.01)
        assert tuple(ob.voxlight.dims) == (8, 10, 12) and ob.name.startswith("b"), (name, ob.name)
    ob = bpy.data.objects["b"]  # the NRRD: 8 x 10 x 12 voxels of 1 x 2 x 3 mm
    assert np.allclose(np.array(ob.scale) * 2, [0.08, 0.20, 0.36], atol=1e-6), ob.scale


@test
def stack_voxel_size_sets_the_box():
    u.reset_scene()
    path = os.path.join(u.TMP, "stack.tif")
    write_tiff(path, list(blob((6, 5, 4), np.float32)))
    ob = u.import_volume(path, unit_scale=0.01)
    assert np.allclose(np.array(ob.scale) * 2, [0.04, 0.05, 0.06], atol=1e-6)  # 1 mm default
    ob = u.import_volume(path, unit_scale=0.01, voxel_size=(0.5, 2.0, 3.0))
    assert np.allclose(np.array(ob.scale) * 2, [0.02, 0.10, 0.18], atol=1e-6), ob.scale


@test
def folder_by_directory_or_filepath():
    u.reset_scene()
    folder = os.path.join(u.TMP, "pngs")
    os.makedirs(folder, exist_ok=True)
    for k, img in enumerate(blob((5, 6, 7), np.uint8)):
        write_png(os.path.join(folder, "s%02d.png" % k), img)
    # the file browser with no file picked: only the folder
    before = set(bpy.data.objects)
    assert bpy.ops.voxlight.import_volume(filepath=folder + os.sep, directory=folder + os.sep) == {"FINISHED"}
    ob = (set(bpy.data.objects) - before).pop()
    assert tuple(ob.voxlight.dims) == (7, 6, 5) and ob.name == "pngs"
    ob = u.import_volume(folder)  # a script naming the folder
    assert tuple(ob.voxlight.dims) == (7, 6, 5)


@test
def vdb_import_is_in_scene_units():
    u.reset_scene()
    a = 0.01 + blob((8, 6, 4), np.float32) / 1000.0  # a ball; > 0 everywhere, so every voxel is active
    aff = np.diag([0.1, 0.1, 0.1, 1.0])
    aff[:3, 3] = [1.0, 2.0, 3.0]
    path = write_vdb(os.path.join(u.TMP, "smoke.vdb"), [{"name": "density", "array": a, "affine": aff}])
    ob = u.import_volume(path, center=False)  # unit_scale (per mm) does not apply
    assert ob.name == "smoke" and tuple(ob.voxlight.dims) == (8, 6, 4)
    assert np.allclose(np.array(ob.scale) * 2, [0.8, 0.6, 0.4], atol=1e-6), ob.scale
    corner = ob.matrix_world @ __import__("mathutils").Vector((-1, -1, -1))
    assert np.allclose(corner, [0.95, 1.95, 2.95], atol=1e-6), corner  # voxel 0's centre at (1, 2, 3)
    u.add_camera((1.35, -3.0, 3.15), target=(1.35, 2.25, 3.15))
    img = vx.render_volume(ob, resolution=(48, 48))
    assert img[..., 3].max() > 0.2 and img[0, 0, 3] < 0.01


@test
def reader_notes_reach_the_object():
    """What a reader decided rather than read (vxl_volume_info.notes) is kept
    on the object for the Voxlight panel; a stand-in helper sends them."""
    u.reset_scene()
    path = os.path.join(u.TMP, "noted.png")
    write_png(path, blob((1, 3, 4), np.uint16)[0])
    notes = "PixelSpacing missing: 1 mm assumed; 2 slices interpolated where slices are missing"
    os.environ["VOXLIGHT_READ_OIIO"] = notes_helper(u.TMP, notes)
    try:
        ob = u.import_volume(path)
    finally:
        del os.environ["VOXLIGHT_READ_OIIO"]
    assert tuple(ob.voxlight.dims) == (4, 3, 2) and ob.voxlight.reader_notes == notes, ob.voxlight.reader_notes
    assert vx.core.import_job.note_lines(ob.voxlight.reader_notes)[1].startswith("2 slices")
    path = os.path.join(u.TMP, "plain.nrrd")
    write_nrrd(path, blob((4, 5, 6), np.int16))
    assert u.import_volume(path).voxlight.reader_notes == ""


@test
def dicom_as_hospitals_send_it_imports_with_its_notes():
    """The add-on imports the DICOM the library reads through its helper: an
    enhanced multi-frame CT (pydicom's writer, frames shuffled) lands with
    its slices; a series with a missing slice is resampled and the object
    keeps the note that says so."""
    import subprocess
    u.reset_scene()
    enhanced = os.path.join(u.TMP, "enhanced", "e.dcm")
    os.makedirs(os.path.dirname(enhanced), exist_ok=True)
    subprocess.run(["/usr/bin/python3", os.path.join(u.ROOT, "tests", "make_enhanced_dicom.py"), enhanced, "6", "5",
                    "7", "1", "1", "0", "0", "0", "1", "0", "0", "0", "0", "0", "0", "2", "5"], check=True)
    ob = u.import_volume(enhanced)
    assert tuple(ob.voxlight.dims) == (6, 5, 7) and ob.voxlight.reader_notes == "", ob.voxlight.reader_notes
    sys.path.insert(0, os.path.join(u.ROOT, "tests", "python"))
    from dicom_write import write_dicom
    gap = os.path.join(u.TMP, "gap")
    os.makedirs(gap, exist_ok=True)
    for k, z in enumerate((0, 2, 4, 8, 10)):
        write_dicom(os.path.join(gap, "%d.dcm" % k), "1.2.840.99.501", np.full((5, 6), 100 * k, np.uint16), z)
    ob = u.import_volume(gap)
    assert tuple(ob.voxlight.dims) == (6, 5, 6), tuple(ob.voxlight.dims)
    assert "uneven slice spacing" in ob.voxlight.reader_notes and "1 of them interpolated" in ob.voxlight.reader_notes


@test
def openvdb_abort_is_an_error_and_blender_lives_on():
    """libopenvdb aborts on this file (tests/fuzz/upstream/): the add-on's
    helper process dies instead of Blender, the import reports it, and the
    next .vdb import still works through the installed helper."""
    u.reset_scene()
    helper = os.path.join(os.path.dirname(vx.__file__), vx.core.native.VDB_HELPER_NAME)
    assert os.access(helper, os.X_OK), helper  # zip install dropped the bit; the add-on restored it
    repro = os.path.join(u.ROOT, "tests", "fuzz", "upstream", "openvdb_delayed_load_mask_assert.vdb")
    _expect_failure("the OpenVDB reader crashed (signal 6: SIGABRT)", filepath=repro)
    path = write_vdb(os.path.join(u.TMP, "after.vdb"), [{"name": "density", "array": np.ones((3, 4, 5), np.float32)}])
    assert tuple(u.import_volume(path).voxlight.dims) == (3, 4, 5)


@test
def failures_leave_bpy_data_unchanged():
    u.reset_scene()
    bad = os.path.join(u.TMP, "broken.vdb")
    with open(bad, "wb") as f:
        f.write(b" BDV" + b"\0" * 40)
    _expect_failure("broken.vdb", filepath=bad)
    _expect_failure("nothing-here.nrrd", filepath=os.path.join(u.TMP, "nothing-here.nrrd"))
    empty = os.path.join(u.TMP, "empty-folder")
    os.makedirs(empty, exist_ok=True)
    _expect_failure("empty-folder", filepath=empty)
    huge = os.path.join(u.TMP, "huge.mha")
    with open(huge, "w") as f:
        f.write("NDims = 3\nDimSize = 100000 100000 100000\nElementType = MET_FLOAT\nElementDataFile = LOCAL\n")
    _expect_failure("memory budget", filepath=huge)


@test
def failure_while_creating_the_object_removes_it():
    """The load succeeded but building the object failed half-way (here: the
    transfer-function texture): the object and its texture are removed and
    the loaded renderer is not kept."""
    u.reset_scene()
    path = u.ball_file()
    real = vx.tf.ensure_texture

    def broken(obj, *args):
        real(obj, *args)  # the texture exists, then the step fails
        raise RuntimeError("simulated failure")
    vx.tf.ensure_texture = broken
    try:
        _expect_failure("simulated failure", filepath=path)
    finally:
        vx.tf.ensure_texture = real
    assert vx.core.runtime.find_entry(path) is None


u.run("test_import")
