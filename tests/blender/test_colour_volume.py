"""A colour volume (RGB NIfTI) in Blender: it imports in colour, its
colour is scene-linear in the add-on's renders (the file's sRGB bytes
decoded, so F12 under the Standard view transform shows the file's colour),
and the panel's Colour switch gives the ramp's colour instead."""

import os
import sys

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import _util as u  # noqa: E402  (also puts tests/python on sys.path)
from _util import test  # noqa: E402
from nifti_write import write_nifti  # noqa: E402

vx = u.install_addon()
N = 16
COLOUR = (200, 90, 30)  # sRGB bytes of every voxel


def _import():
    u.reset_scene()
    rgb = np.zeros((N, N, N, 3), np.uint8)
    rgb[...] = COLOUR
    path = write_nifti(os.path.join(u.TMP, "rgb.nii"), rgb, np.diag([2.0, 2.0, 2.0, 1.0]), rgb=True)
    ob = u.import_volume(path)
    u.add_camera((0.0, -2.5, 0.3))
    ob.voxlight.jitter = False
    ob.voxlight.shading = False
    # the luminance (109) above the window: the ramp's last stop, made
    # opaque at the first voxel, so the pixel is the voxel's colour
    ob.voxlight.window_low, ob.voxlight.window_high = 0.0, 50.0
    ob.voxlight.opacity_scale = 50.0
    return ob


def _centre(ob):
    img = vx.render_volume(ob, resolution=(32, 32))
    return img[16, 16]


@test
def rgb_nifti_renders_its_own_colour_scene_linear():
    ob = _import()
    entry = vx.core.runtime.find_entry(bpy.path.abspath(ob.voxlight.filepath))
    assert entry.info["components"] == 3 and entry.info["opacity_source"] == "luminance", entry.info
    px = _centre(ob)
    want = vx.core.colour_space.srgb_to_linear(np.array(COLOUR) / 255.0)
    assert px[3] > 0.99, px
    assert np.abs(px[:3] / px[3] - want).max() < 0.01, (px, want)


@test
def colour_switch_takes_the_ramps_colour_instead():
    ob = _import()
    data = _centre(ob)
    ob.voxlight.color_source = "tf"
    ramp = _centre(ob)
    # the ramp's last stop (the luminance is above the window), not the file's orange
    want = vx.tf.table(ob.voxlight)[-1, :3]
    assert ramp[3] > 0.99 and np.abs(ramp[:3] / ramp[3] - want).max() < 0.01, (ramp, want)
    assert np.abs(data[:3] - ramp[:3]).max() > 0.2, (data, ramp)


u.run("test_colour_volume")
