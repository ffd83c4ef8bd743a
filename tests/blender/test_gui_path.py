"""GUI Blender under Xvfb: the path model in the viewport refines sample by
sample while the view is still (one library call a sample, offsets 0, 1,
2, ... up to Viewport Samples), each pass merged into the running mean, so
the still image comes nearer a many-sample image; a change of the view
starts again at sample 0.

xvfb-run -a -s "-screen 0 1280x1024x24" blender --factory-startup \
    --enable-event-simulate --python-exit-code 1 --python tests/blender/test_gui_path.py
"""

import os
import sys

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import _gui  # noqa: E402
import _util as u  # noqa: E402

RUN = _gui.Run("test_gui_path", limit_s=400)
check = RUN.check
capture = _gui.Capture()
SAMPLES = 6


def steps():
    vx = u.install_addon()
    win = bpy.context.window_manager.windows[0]
    area = next(a for a in win.screen.areas if a.type == "VIEW_3D")
    area.spaces.active.overlay.show_overlays = False
    _gui.front_view(area.spaces.active)
    capture.install()
    scene = u.reset_scene()
    s = scene.voxlight
    s.viewport_resolution, s.settle_time = 0.25, 0.3  # llvmpipe: short renders

    calls = []  # (offset, samples, width) of every refined (tiled) library frame
    firsts = {}  # the first full pass's image, and a 64-sample one of the same frame
    plain = vx.core.native.Renderer.render_tiled

    def recording(self, params, *args, **kwargs):
        out = plain(self, params, *args, **kwargs)
        calls.append((params.path_sample_offset, params.path_samples, params.width))
        if out is not None and params.path_sample_offset == 0 and params.width not in firsts:
            n = params.path_samples
            params.path_samples = 64
            ref = plain(self, params, *args, **kwargs)
            params.path_samples = n
            if ref is not None:
                firsts[params.width] = (out[0].copy(), ref[0].copy())
        return out
    vx.core.native.Renderer.render_tiled = recording

    with bpy.context.temp_override(window=win, area=area):
        ob = u.import_volume(u.ball_file())
    ob.voxlight.shading_model = "path"
    ob.voxlight.path_viewport_samples = SAMPLES
    ob.voxlight.path_bounces = 2
    yield from capture.settled(vx, area, tries=80)
    st = next(v for k, v in vx.viewport._states.items() if k[1] == ob.name)
    full_w = st.full.width if st.full is not None else -1
    offsets = [c[0] for c in calls if c[2] == full_w]
    check("still_view_accumulates_its_samples", st.full is not None and st.full.path_samples == SAMPLES,
          "samples %s" % (st.full.path_samples if st.full is not None else None))
    check("one_sample_a_pass_in_order", offsets[-SAMPLES:] == list(range(SAMPLES))
          and all(c[1] == 1 for c in calls), "calls %s" % calls[-SAMPLES - 2:])
    first, ref = firsts.get(full_w, (None, None))
    if first is not None:
        e1 = float(np.sqrt(((first[..., :3] - ref[..., :3]) ** 2).mean()))
        en = float(np.sqrt(((st.full.rgba[..., :3] - ref[..., :3]) ** 2).mean()))
        check("the_mean_nears_a_many_sample_image", en < 0.75 * e1, "RMSE %.5f after 1, %.5f after %d"
              % (e1, en, SAMPLES))
    else:
        check("the_mean_nears_a_many_sample_image", False, "no first pass recorded")
    calls.clear()
    ob.rotation_euler.z += 0.3  # a change: start again
    yield from capture.settled(vx, area, tries=80)
    offsets = [c[0] for c in calls if c[2] == full_w]
    check("a_change_starts_again", offsets[:1] == [0] and offsets[-SAMPLES:] == list(range(SAMPLES)),
          "offsets %s" % offsets)
    vx.core.native.Renderer.render_tiled = plain


RUN.start(steps())
