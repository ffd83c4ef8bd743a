"""GUI Blender under Xvfb: the viewport draws a base volume with its overlay
child fused. A red ball in its own grid, parented to the ball
phantom, shows red where its affine puts it on screen; the overlay is not
drawn on its own (no viewport state of its own, one frame per refine step
for the pair); hiding it removes the red; its blend reaches the frame.

xvfb-run -a -s "-screen 0 1280x1024x24" blender --factory-startup \
    --enable-event-simulate --python-exit-code 1 --python tests/blender/test_gui_overlays.py
"""

import os
import sys

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import _gui  # noqa: E402
import _util as u  # noqa: E402

RUN = _gui.Run("test_gui_overlays", limit_s=400)
check = RUN.check
capture = _gui.Capture()
N = 16


def _ball_file():
    """A bright ball of radius 6 mm on a 1 mm grid centred at scanner (28, 0, 0) mm."""
    g = np.arange(N, dtype=np.float64) - (N - 1) / 2.0
    i, j, k = np.meshgrid(g, g, g, indexing="ij")
    data = np.where(i * i + j * j + k * k <= 36.0, 1000.0, 0.0).astype(np.float32)
    aff = np.eye(4)
    aff[:3, 3] = [28.0 - (N - 1) / 2.0, -(N - 1) / 2.0, -(N - 1) / 2.0]
    return u.write_nifti(os.path.join(u.TMP, "gui_hot_ball.nii.gz"), data, aff)


def _red(img):
    return (img[..., 0] > 0.3) & (img[..., 0] > 3 * img[..., 1]) & (img[..., 0] > 3 * img[..., 2])


def steps():
    vx = u.install_addon()
    win, area, space = _gui.view3d()
    space.overlay.show_overlays = False
    r3d = _gui.front_view(space)
    capture.install()
    scene = u.reset_scene()
    s = scene.voxlight
    s.viewport_resolution, s.settle_time = 0.5, 0.3  # llvmpipe: short renders

    # Red drawn without any volume (a gizmo, the cursor): not the overlay's.
    capture.request()
    area.tag_redraw()
    yield 0.5
    stray = _red(capture.img) if capture.img is not None else False
    with bpy.context.temp_override(window=win, area=area):
        base = u.import_volume(u.ball_file(), center=False)
        ov = u.import_volume(_ball_file(), center=False)
    r3d = _gui.front_view(space)  # the import framed the last volume: back to the whole scene
    base.voxlight.jitter = ov.voxlight.jitter = False
    p = ov.voxlight
    vx.tf.set_ramp(p.tf_texture.color_ramp, [(0.0, (1, 0, 0, 0)), (0.5, (1, 0, 0, 1)), (1.0, (1, 0, 0, 1))])
    p.window_low, p.window_high = 0.0, 1000.0
    ov.voxlight_overlays.shading = False
    world = ov.matrix_world.copy()
    ov.parent = base
    ov.matrix_world = world

    def settled():
        return capture.settled(vx, area, tries=60)

    yield from settled()
    fused = capture.img
    region = next(r for r in area.regions if r.type == "WINDOW")
    view, proj = np.array(r3d.view_matrix), np.array(r3d.window_matrix)
    dg = bpy.context.evaluated_depsgraph_get()
    model = vx.params.model_matrix(ov.evaluated_get(dg))
    clip = proj @ view @ model @ np.array([(N - 1) / 2.0] * 3 + [1.0])
    x, y = clip[:2] / clip[3]
    h, w = fused.shape[:2]
    r, c = int((y + 1) / 2 * h), int((x + 1) / 2 * w)
    red = _red(fused) & ~stray
    check("overlay_red_where_its_affine_says", red[r - 2:r + 3, c - 2:c + 3].all(),
          "pixel (%d, %d) of %dx%d region %dx%d: %s" % (r, c, w, h, region.width, region.height, fused[r, c]))
    # every red pixel within the ball's projected radius (6 mm) of its centre
    edge = proj @ view @ model @ np.array([(N - 1) / 2.0 + 6.0] + [(N - 1) / 2.0] * 2 + [1.0])
    radius = np.hypot(*((edge[:2] / edge[3] - (x, y)) * (w / 2, h / 2)))
    ys, xs = np.nonzero(red)
    far = np.hypot(ys - r, xs - c).max() if len(ys) else None
    check("red_only_around_it", far is not None and far < radius + 3, "farthest %s px, radius %.1f" % (far, radius))
    names = {k[1] for k in vx.viewport._states}
    check("overlay_not_drawn_on_its_own", base.name in names and ov.name not in names, sorted(names))
    base_px = fused[..., 3] > 0.1
    check("base_still_drawn", base_px.sum() > red.sum() + 500, "%d lit, %d red" % (base_px.sum(), red.sum()))

    ov.voxlight_overlays.blend = "add"
    yield from settled()
    check("blend_reaches_the_viewport", np.abs(capture.img - fused).max() > 0.02,
          "max change %.4f" % np.abs(capture.img - fused).max())
    ov.voxlight_overlays.blend = "over"

    ov.hide_set(True)
    yield from settled()
    left = _red(capture.img) & ~stray
    check("hidden_overlay_not_drawn", not left.any(),
          "%d red; fused %s" % (left.sum(), vx.overlay_frames.current(base.name).overlays))
    ov.hide_set(False)
    yield from settled()
    check("shown_again", _red(capture.img)[r - 2:r + 3, c - 2:c + 3].all())


RUN.start(steps())
