"""GUI Blender under Xvfb: dragging a Sun in the viewport relights the
shadowed volume with a coarse illumination volume, and once the light
settles the viewport refines it to the chosen Shadow Quality.

xvfb-run -a -s "-screen 0 1280x1024x24" blender --factory-startup \
    --enable-event-simulate --python-exit-code 1 --python tests/blender/test_gui_shadow.py

The library calls are observed by wrapping native.Renderer.render, through
which every viewport frame (preview, half and full refine) passes.
"""

import os
import sys

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import _gui  # noqa: E402
import _util as u  # noqa: E402

RUN = _gui.Run("test_gui_shadow", limit_s=400)
check = RUN.check
capture = _gui.Capture()


def steps():
    vx = u.install_addon()
    win = bpy.context.window_manager.windows[0]
    area = next(a for a in win.screen.areas if a.type == "VIEW_3D")
    area.spaces.active.overlay.show_overlays = False
    _gui.front_view(area.spaces.active)
    capture.install()
    scene = u.reset_scene()
    s = scene.voxlight
    s.viewport_resolution, s.settle_time = 0.5, 0.3  # llvmpipe: short renders

    sizes = []  # illumination_size of every library call, in order
    plain_render = vx.core.native.Renderer.render

    def recording_render(self, params=None, *args, **kwargs):
        if params is not None:
            sizes.append(params.illumination_size)
        return plain_render(self, params, *args, **kwargs)
    vx.core.native.Renderer.render = recording_render

    with bpy.context.temp_override(window=win, area=area):
        ob = u.import_volume(u.ball_file())
    ob.voxlight.shadow_quality = "HIGH"
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    scene.collection.objects.link(sun)
    sun.data.angle = 0.05
    sun.rotation_euler = (0.0, 0.9, 0.0)

    def settled():
        return capture.settled(vx, area)

    yield from settled()
    before = capture.img
    check("still_frame_has_the_chosen_quality", sizes and sizes[-1] == 256, sizes[-3:])
    # Drag: the Sun turns a little per redraw, faster than the settle time.
    sizes.clear()
    for i in range(6):
        sun.rotation_euler.y -= 0.25
        area.tag_redraw()
        yield 0.08
    dragged = list(sizes)
    check("dragged_frames_are_coarse", vx.core.lighting.DRAG_ILLUMINATION_SIZE in dragged
          and 256 not in dragged[1:], "sizes %s" % sorted(set(dragged)))
    sizes.clear()
    yield from settled()
    after = capture.img
    check("settled_frame_is_refined", sizes and sizes[-1] == 256, "last size %s" % sizes[-1:])
    st = next(v for k, v in vx.viewport._states.items() if k[1] == ob.name)
    check("settled_frame_is_shown_full", st.shown is not None and st.shown.full)
    change = np.abs(after[..., :3] - before[..., :3]).max(axis=2).mean()
    check("moving_the_sun_relights", change > 0.005, "mean change %.4f" % change)
    vx.core.native.Renderer.render = plain_render


RUN.start(steps())
