"""The path shading model in Blender: F12 and the scripting API render the
volume with Samples samples and Bounces bounces, the same image every time
(a render farm's frames agree), and more samples bring it nearer a
many-sample image."""

import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import _util as u  # noqa: E402  (also puts tests/python on sys.path)
from _util import test  # noqa: E402

vx = u.install_addon()
RES = (32, 32)


def _volume():
    u.reset_scene()
    ob = u.import_volume(u.ball_file())
    u.add_camera((0.0, -2.5, 0.3))
    ob.voxlight.jitter = False
    ob.voxlight.shading_model = "path"
    ob.voxlight.path_bounces = 2
    return ob


def _render(ob, samples):
    ob.voxlight.path_samples = samples
    return vx.render_volume(ob, resolution=RES)


@test
def path_renders_the_same_image_every_time_and_converges():
    ob = _volume()
    a, b = _render(ob, 4), _render(ob, 4)
    assert a[..., 3].max() > 0.2 and np.isfinite(a).all(), a[..., 3].max()
    assert np.array_equal(a, b)
    ref = _render(ob, 64)
    one = _render(ob, 1)
    err1 = float(np.sqrt(((one[..., :3] - ref[..., :3]) ** 2).mean()))
    err16 = float(np.sqrt(((_render(ob, 16)[..., :3] - ref[..., :3]) ** 2).mean()))
    assert err16 < 0.6 * err1, (err1, err16)
    # alpha comes from a deterministic march: no noise in it
    assert np.abs(one[..., 3] - ref[..., 3]).max() < 1e-5


@test
def bounces_brighten_and_never_darken():
    ob = _volume()
    ob.voxlight.path_bounces = 1
    single = _render(ob, 8)
    ob.voxlight.path_bounces = 4
    multi = _render(ob, 8)
    assert multi[..., :3].mean() > single[..., :3].mean(), (multi[..., :3].mean(), single[..., :3].mean())


u.run("test_path")
