"""Headless Blender: 4D volumes follow the timeline (scene frame N shows
volume frame N - Start Frame; F12 and animation renders step through time;
Fixed mode holds one frame), and a DICOM folder's series is chosen with the
import operator's `series` property.

blender -b --factory-startup --python-exit-code 1 --python tests/blender/test_frames4d.py
"""

import os
import struct
import sys

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import _util as u  # noqa: E402
from _util import test  # noqa: E402

sys.path.insert(0, os.path.join(u.ROOT, "tests", "python"))
from dicom_write import write_dicom  # noqa: E402
from nifti_write import nifti1_bytes  # noqa: E402

vx = u.install_addon()
SIZE = 64
FRAMES = 5


def _moving_cube_file():
    """16^3 x 5 frames: a bright cube whose x position moves with the frame."""
    n = 16
    data = np.zeros((n, n, n, FRAMES), np.float32)
    for t in range(FRAMES):
        data[1 + 2 * t: 5 + 2 * t, 6:10, 6:10, t] = 100.0
    raw = bytearray(nifti1_bytes(data, np.diag([4.0, 4.0, 4.0, 1.0])))
    struct.pack_into("<h", raw, 40, 4)  # dim[0] = 4
    path = os.path.join(u.TMP, "moving.nii")
    with open(path, "wb") as f:
        f.write(bytes(raw))
    return path


def _scene():
    scene = u.reset_scene()
    scene.render.resolution_x = scene.render.resolution_y = SIZE
    scene.render.resolution_percentage = 100
    ob = u.import_volume(_moving_cube_file(), anatomical_views=False)  # the file's +x = screen right
    ob.voxlight.jitter = False
    u.add_camera((0.0, -3.0, 0.0))  # looks along +Y: volume x is image x
    return scene, ob


def _cx(img):
    """Horizontal centre of what was drawn."""
    w = img[..., 3].sum(axis=0)
    assert w.sum() > 0, "nothing drawn"
    return float((w * np.arange(img.shape[1])).sum() / w.sum())


@test
def import_reports_the_frame_count():
    _scene_, ob = _scene()
    assert ob.voxlight.frame_count == FRAMES
    assert ob.voxlight.frame_mode == "TIMELINE" and ob.voxlight.frame_offset == 1


@test
def scene_frame_selects_the_volume_frame():
    scene, ob = _scene()
    xs = []
    for f in range(1, FRAMES + 1):
        scene.frame_set(f)
        xs.append(_cx(vx.render_volume(ob)))
    # the cube moves by 2 voxels (8 mm) per frame: strictly increasing x
    assert all(b > a + 1.0 for a, b in zip(xs, xs[1:])), xs
    # past the last frame the last volume stays
    scene.frame_set(FRAMES + 10)
    assert abs(_cx(vx.render_volume(ob)) - xs[-1]) < 1e-3
    # a later Start Frame delays the sequence
    ob.voxlight.frame_offset = 3
    scene.frame_set(4)
    assert abs(_cx(vx.render_volume(ob)) - xs[1]) < 1e-3
    # Fixed mode ignores the timeline
    ob.voxlight.frame_mode = "FIXED"
    ob.voxlight.fixed_frame = 2
    for f in (1, 5):
        scene.frame_set(f)
        assert abs(_cx(vx.render_volume(ob)) - xs[2]) < 1e-3


@test
def animation_render_steps_through_time():
    scene, ob = _scene()
    scene.render.engine = "BLENDER_WORKBENCH"
    scene.render.film_transparent = False
    scene.view_settings.view_transform = "Standard"
    scene.frame_start, scene.frame_end = 1, 3
    scene.render.filepath = os.path.join(u.TMP, "t4d_")
    scene.render.image_settings.file_format = "PNG"
    bpy.ops.render.render(animation=True)
    xs = []
    for f in (1, 2, 3):
        img = u.load_png(os.path.join(u.TMP, "t4d_%04d.png" % f))
        bright = img[..., :3].max(axis=2)
        w = np.clip(bright - np.median(bright), 0, None).sum(axis=0)
        xs.append(float((w * np.arange(SIZE)).sum() / w.sum()))
    assert xs[0] + 1.0 < xs[1] < xs[2] - 1.0, xs


@test
def import_chooses_a_dicom_series():
    u.reset_scene()
    d = os.path.join(u.TMP, "study")
    os.makedirs(d, exist_ok=True)
    px = (np.arange(12, dtype=np.uint16).reshape(3, 4) + 1100)
    for k in range(4):
        write_dicom(os.path.join(d, "a%d.dcm" % k), "1.2.7.1", px, 2.0 * k)
    for k in range(2):
        write_dicom(os.path.join(d, "b%d.dcm" % k), "1.2.7.2", px, 2.0 * k, modality="MR")
    assert [s["uid"] for s in vx.core.native.list_dicom_series(d)] == ["1.2.7.1", "1.2.7.2"]
    ob = u.import_volume(os.path.join(d, "a0.dcm"), series="1.2.7.2")
    assert tuple(ob.voxlight.dims) == (4, 3, 2) and ob.voxlight.series == "1.2.7.2"
    assert vx.render_volume(ob, resolution=(32, 32)).shape == (32, 32, 4)
    # a file of series A without a choice is series A
    ob = u.import_volume(os.path.join(d, "a1.dcm"))
    assert tuple(ob.voxlight.dims) == (4, 3, 4)
    # a bad choice is reported, nothing is created
    before = set(bpy.data.objects)
    try:
        res = bpy.ops.voxlight.import_volume(filepath=os.path.join(d, "a1.dcm"), series="9")
    except RuntimeError as e:  # operator errors are raised in background mode
        assert "no series '9'" in str(e), e
    else:
        assert res == {"CANCELLED"}, res
    assert set(bpy.data.objects) == before


u.run("test_frames4d")
