"""GUI Blender under Xvfb: the viewport draws a three-channel volume's
channels in their colours (red, green and blue balls apart); hiding one
channel removes its colour from the viewport, a dye preset recolours it, and
a shading model the library cannot draw channels with leaves the scalar
(channel 0) drawn, not an empty or failed viewport.

xvfb-run -a -s "-screen 0 1280x1024x24" blender --factory-startup \
    --enable-event-simulate --python-exit-code 1 --python tests/blender/test_gui_channels.py
"""

import os
import sys

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import _gui  # noqa: E402
import _util as u  # noqa: E402
from nifti_write import write_channels_nifti  # noqa: E402

RUN = _gui.Run("test_gui_channels", limit_s=300)
check = RUN.check
capture = _gui.Capture()
N = 24


def _ball(centre, peak):
    i, j, k = np.indices((N, N, N)).astype(float)
    d = np.sqrt(sum((a - c) ** 2 for a, c in zip((i, j, k), centre)))
    return np.where(d < 5, peak * (1 - 0.5 * d / 5), 0).astype(np.uint16)


def _pure(img, c):
    """Pixels whose colour is channel c's primary (red, green or blue) alone."""
    others = [k for k in range(3) if k != c]
    return (img[..., c] > 0.15) & (img[..., c] > 3 * img[..., others].max(axis=-1))


def steps():
    vx = u.install_addon()
    win, area, space = _gui.view3d()
    space.overlay.show_overlays = False
    space.show_gizmo = False  # the navigation gizmo's red X
    capture.install()
    scene = u.reset_scene()
    s = scene.voxlight
    s.viewport_resolution, s.settle_time = 0.5, 0.3  # llvmpipe: short renders
    path = write_channels_nifti(os.path.join(u.TMP, "gui_channels.nii.gz"),
                                [_ball((6, 12, 12), 40000), _ball((18, 12, 12), 30000),
                                 _ball((12, 12, 4), 20000)], np.diag([4.0, 4.0, 4.0, 1.0]))
    with bpy.context.temp_override(window=win, area=area):
        ob = u.import_volume(path)
    _gui.front_view(space)
    space.shading.background_type = "VIEWPORT"
    space.shading.background_color = (0.0, 0.0, 0.0)
    ob.voxlight.jitter = False
    for ch in ob.voxlight.channels:
        ch.opacity = 8.0

    def settled():
        return capture.settled(vx, area, tries=60)

    yield from settled()
    img = capture.img
    counts = [int(_pure(img, c).sum()) for c in range(3)]
    check("each_channel_in_its_colour", min(counts) > 20, "pure r, g, b pixels: %s" % counts)

    ob.voxlight.channels[1].visible = False
    yield from settled()
    hidden = capture.img
    check("hidden_channel_gone", _pure(hidden, 1).sum() == 0 and _pure(hidden, 0).sum() > 20,
          "green %d, red %d" % (_pure(hidden, 1).sum(), _pure(hidden, 0).sum()))
    ob.voxlight.channels[1].visible = True

    bpy.context.view_layer.objects.active = ob
    with bpy.context.temp_override(window=win, area=area):
        bpy.ops.voxlight.channel_dye(index=0, dye="DAPI")
    yield from settled()
    dyed = capture.img
    check("dye_recolours_the_viewport", _pure(dyed, 0).sum() == 0 and
          _pure(dyed, 2).sum() > counts[2] + 20,
          "red %d, blue %d (was %d)" % (_pure(dyed, 0).sum(), _pure(dyed, 2).sum(), counts[2]))

    ob.voxlight.shading = True
    ob.voxlight.shading_model = "shadowed"
    yield from settled()
    scalar = capture.img
    check("conflict_draws_the_scalar", scalar[..., :3].max() > 0.1 and _pure(scalar, 1).sum() == 0,
          "max %.3f, green %d; why: %s" % (scalar[..., :3].max(), _pure(scalar, 1).sum(),
                                           vx.channel_props.why_not(ob.voxlight)))


RUN.start(steps())
