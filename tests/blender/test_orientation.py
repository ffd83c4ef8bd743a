"""Headless Blender: the import option that turns a scan so Blender's named
views match its anatomy ("Blender Views Match Anatomy", orientation.py),
for every format, and the import's "Frame in View" option (a no-op
without windows; tests/blender/test_gui_orientation.py checks it in the
GUI together with the depth-tested box outline).

blender -b --factory-startup --python-exit-code 1 --python tests/blender/test_orientation.py
"""

import math
import os
import sys

import bpy
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(os.path.dirname(HERE), "cli"))
import _util as u  # noqa: E402
from _util import test  # noqa: E402
from test_cli_formats import blob, write_nrrd, write_tiff  # noqa: E402
from vdb_write import write_vdb  # noqa: E402

vx = u.install_addon()
N = 32
SPACING = 2.0          # mm; unit_scale 0.01: the box is 0.64 units across
SIZE = 96
CAM_DIST = 3.0


def _blob(vol, centre, radius=3.0):
    i, j, k = np.indices(vol.shape)
    r = np.sqrt((i - centre[0]) ** 2 + (j - centre[1]) ** 2 + (k - centre[2]) ** 2)
    vol[r <= radius] = 100.0


def marker_phantom():
    """Empty RAS volume (voxel axes = R, A, S) with three bright markers:
    anterior (+y) on the centre line, the patient's right (+x) and
    superior (+z)."""
    vol = np.zeros((N, N, N), np.float32)
    mid, near_edge = (N - 1) / 2.0, N - 5
    _blob(vol, (mid, near_edge, mid))   # anterior: the "face"
    _blob(vol, (near_edge, mid, mid))   # the patient's right
    _blob(vol, (mid, mid, near_edge))   # the top of the head
    aff = np.diag([SPACING, SPACING, SPACING, 1.0])
    aff[:3, 3] = -(N - 1) / 2.0 * SPACING
    return u.write_nifti(os.path.join(u.TMP, "markers.nii"), vol, aff)


def front_camera():
    """Blender's Front view (numpad 1) as a camera: at -Y looking along +Y,
    screen right = +X, up = +Z."""
    cam = u.add_camera((0.0, -CAM_DIST, 0.0), lens=100.0, name="Front")
    cam.rotation_euler = (math.radians(90.0), 0.0, 0.0)
    return cam


def render(ob, cam):
    p = ob.voxlight
    p.jitter = False
    vx.tf.set_ramp(p.tf_texture.color_ramp, [(0.0, (0, 0, 0, 0)), (1.0, (1, 1, 1, 1))])
    p.window_low, p.window_high = 0.0, 100.0
    scene = bpy.context.scene
    rgba, depth = vx.offline.render(scene, bpy.context.evaluated_depsgraph_get(), cam, SIZE, SIZE,
                                    only={ob}, for_render=False)
    return rgba, depth


def _mass_centre(alpha, mask):
    w = np.where(mask, alpha, 0.0)
    ys, xs = np.indices(alpha.shape)
    return (xs * w).sum() / w.sum(), (ys * w).sum() / w.sum()


@test
def front_view_sees_the_face():
    u.reset_scene()
    path = marker_phantom()
    cam = front_camera()
    c = SIZE // 2
    seen = {}
    for option in (True, False):
        for ob in [o for o in bpy.data.objects if o.type == "EMPTY"]:
            bpy.data.objects.remove(ob)
        # the default import (the option is on by default), then the option off
        ob = u.import_volume(path) if option else u.import_volume(path, anatomical_views=False)
        assert ob.voxlight.orientation == ("BLENDER_VIEWS" if option else "FILE")
        rgba, depth = render(ob, cam)
        a = rgba[..., 3]
        assert a[c - 2:c + 2, c - 2:c + 2].min() > 0.5, a[c - 2:c + 2, c - 2:c + 2]
        # the centre line meets only the anterior marker: its depth tells its side
        seen[option] = float(np.median(depth[c - 2:c + 2, c - 2:c + 2]))
        # the right-side marker: left or right of the centre line, at mid height
        side = np.zeros_like(a, bool)
        side[c - 6:c + 6, :] = True
        side[:, c - 8:c + 8] = False
        rx, _ = _mass_centre(a, side)
        # the superior marker: above or below the centre, on the centre line
        col = np.zeros_like(a, bool)
        col[:, c - 6:c + 6] = True
        col[c - 8:c + 8, :] = False
        _, sy = _mass_centre(a, col)
        if option:
            # Front sees the face; the patient's right is on the screen's left,
            # as when facing a person; the top stays up.
            assert seen[option] < CAM_DIST - 0.15, seen
            assert rx < c - 10, rx
        else:
            # Scanner axes: the face looks away from Front (toward +Y).
            assert seen[option] > CAM_DIST + 0.15, seen
            assert rx > c + 10, rx
        assert sy > c + 10, sy


def _rotation(ob):
    return np.array(ob.matrix_world.to_3x3().normalized())


@test
def option_off_keeps_scanner_placement_and_on_turns_it():
    """center=False: off, the object sits exactly where the affine says (as
    before the option existed); on, the same turned 180 degrees about Z
    around the scanner origin."""
    u.reset_scene()
    path = marker_phantom()
    off = u.import_volume(path, center=False, anatomical_views=False)
    on = u.import_volume(path, center=False)
    info = {"affine": np.diag([SPACING, SPACING, SPACING, 1.0])}
    info["affine"][:3, 3] = -(N - 1) / 2.0 * SPACING
    s_from_v = vx.core.volume_space.scene_from_voxel(info["affine"], (N, N, N), 0.01)
    want = vx.core.volume_space.object_matrix(s_from_v, (N, N, N))
    assert np.allclose(np.array(off.matrix_world), want, atol=1e-6)
    turn = np.diag([-1.0, -1.0, 1.0, 1.0])
    assert np.allclose(np.array(on.matrix_world), turn @ want, atol=1e-6)
    # the model the renderer uses follows the same turn
    m_on = vx.params.model_matrix(on)
    m_off = vx.params.model_matrix(off)
    assert np.allclose(m_on, turn @ m_off, atol=1e-6)


@test
def every_format_with_anatomy_is_turned_the_rest_is_not():
    u.reset_scene()
    d = blob((12, 10, 8), np.int16)
    # NRRD in LPS (as Slicer writes): the loader converts it to RAS, so it turns.
    nrrd = os.path.join(u.TMP, "lps.nrrd")
    write_nrrd(nrrd, d, extra="space: left-posterior-superior\n"
                              "space directions: (1,0,0) (0,2,0) (0,0,3)\nspace origin: (0,0,0)\n")
    tif = os.path.join(u.TMP, "stack.tif")
    write_tiff(tif, list(blob((6, 5, 4), np.float32)))
    a = 0.01 + blob((8, 6, 4), np.float32) / 1000.0
    vdb = write_vdb(os.path.join(u.TMP, "smoke.vdb"),
                    [{"name": "density", "array": a, "affine": np.diag([0.1, 0.1, 0.1, 1.0])}])
    for path, turned in ((nrrd, True), (tif, False), (vdb, False)):
        off = u.import_volume(path, center=False, anatomical_views=False)
        on = u.import_volume(path, center=False)
        assert off.voxlight.orientation == "FILE", path
        assert on.voxlight.orientation == ("BLENDER_VIEWS" if turned else "FILE"), path
        expect = np.diag([-1.0, -1.0, 1.0, 1.0]) @ np.array(off.matrix_world) if turned \
            else np.array(off.matrix_world)
        assert np.allclose(np.array(on.matrix_world), expect, atol=1e-6), path


@test
def reload_keeps_the_orientation():
    u.reset_scene()
    ob = u.import_volume(marker_phantom())
    before = np.array(ob.matrix_world)
    bpy.context.view_layer.objects.active = ob
    assert bpy.ops.voxlight.reload_volume() == {"FINISHED"}
    assert ob.voxlight.orientation == "BLENDER_VIEWS"
    assert np.allclose(np.array(ob.matrix_world), before)
    # saved with the file
    blend = os.path.join(u.TMP, "orient.blend")
    bpy.ops.wm.save_as_mainfile(filepath=blend)
    bpy.ops.wm.open_mainfile(filepath=blend)
    ob = bpy.data.objects["markers"]
    assert ob.voxlight.orientation == "BLENDER_VIEWS"
    assert np.allclose(np.array(ob.matrix_world), before)


@test
def frame_in_view_is_an_option_and_harmless_headless():
    rna = bpy.ops.voxlight.import_volume.get_rna_type()
    for name in ("frame_in_view", "anatomical_views"):
        assert rna.properties[name].default is True, name
    u.reset_scene()
    ob = u.import_volume(marker_phantom(), frame_in_view=True)
    assert ob.voxlight.is_volume
    # Drawn depth-tested: meshes in front hide the box outline.
    assert not ob.show_in_front


u.run("test_orientation")
