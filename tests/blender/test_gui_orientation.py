"""GUI Blender under Xvfb: Blender's named views against orientation.py's
table, "Frame in View" on import (perspective and orthographic) against
Blender's own projection, and the volume's box outline hidden by a mesh
in front of it.

xvfb-run -a -s "-screen 0 1280x1024x24" blender --factory-startup \
    --enable-event-simulate --python-exit-code 1 --python tests/blender/test_gui_orientation.py

Steps run from a timer once the window exists (as in test_gui.py); pixels
are read back by a POST_PIXEL handler of this test. The script exits
itself with status 0 or 1.
"""

import math
import os
import sys

import bpy
import numpy as np
from mathutils import Euler

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import _gui  # noqa: E402
import _util as u  # noqa: E402

RUN = _gui.Run("test_gui_orientation", limit_s=300)
check = RUN.check
finish = RUN.finish
capture = _gui.Capture()





def view3d():
    win = bpy.context.window_manager.windows[0]
    area = next(a for a in win.screen.areas if a.type == "VIEW_3D")
    region = next(r for r in area.regions if r.type == "WINDOW")
    return win, area, region


def ndc_of(points, r3d):
    m = np.array(r3d.perspective_matrix, np.float64)
    clip = np.c_[points, np.ones(len(points))] @ m.T
    return clip[:, :3] / clip[:, 3:4], clip[:, 3]


def steps():
    vx = u.install_addon()
    capture.install()
    bpy.context.preferences.view.smooth_view = 0  # view changes land at once
    scene = u.reset_scene()
    win, area, region = view3d()
    space = area.spaces.active
    r3d = space.region_3d

    def grab():
        capture.request()
        area.tag_redraw()

    # 1. The named views, as orientation.py and test_orientation.py assume:
    # the direction each looks along (view -Z in world) and screen right.
    want = {"FRONT": ((0, 1, 0), (1, 0, 0)), "RIGHT": ((-1, 0, 0), (0, 1, 0)),
            "LEFT": ((1, 0, 0), (0, -1, 0)), "TOP": ((0, 0, -1), (1, 0, 0))}
    for name, (look, right) in want.items():
        with bpy.context.temp_override(window=win, area=area, region=region):
            bpy.ops.view3d.view_axis(type=name)
        rot = np.array(r3d.view_rotation.to_matrix(), np.float64)  # view -> world
        got_look, got_right = -rot[:, 2], rot[:, 0]
        check("named_view_%s" % name.lower(),
              np.allclose(got_look, look, atol=1e-5) and np.allclose(got_right, right, atol=1e-5),
              "looks along %s, right %s" % (np.round(got_look, 3), np.round(got_right, 3)))

    # 2. Frame in View: from a view far away, the import frames the box in
    # perspective and in orthographic views (Blender's projection decides).
    path = u.ball_file()
    for persp in ("PERSP", "ORTHO"):
        u.reset_scene()
        r3d.view_perspective = persp
        r3d.view_rotation = Euler((math.radians(60), 0, math.radians(30))).to_quaternion()
        r3d.view_location = (7.0, -4.0, 3.0)
        r3d.view_distance = 40.0
        with bpy.context.temp_override(window=win, area=area):
            ob = u.import_volume(path)
        grab()
        yield 0.5  # a redraw updates perspective_matrix
        model = vx.params.model_matrix(ob)
        corners = vx.core.volume_space.world_corners(model, tuple(ob.voxlight.dims))
        ndc, w = ndc_of(corners, r3d)
        extent = np.abs(ndc[:, :2]).max()
        check("frame_in_view_%s" % persp.lower(), (w > 0).all() and 0.4 < extent < 1.0,
              "corner NDC extent %.3f" % extent)
        # and off: the view stays where it was
        r3d.view_location = (7.0, -4.0, 3.0)
        with bpy.context.temp_override(window=win, area=area):
            u.import_volume(path, frame_in_view=False)
        check("frame_in_view_off_%s" % persp.lower(),
              np.allclose(np.array(r3d.view_location), (7.0, -4.0, 3.0)))

    # 3. The box outline (Blender's wire cube of the volume's Empty) is
    # hidden by a mesh in front of it. Only the outline is drawn: the
    # volume's own render is off, and the overlays that would also draw
    # (grid, origins, cursor, text, gizmos) are hidden.
    u.reset_scene()
    scene.voxlight.viewport_enabled = False
    space.shading.type = "SOLID"
    ov = space.overlay
    ov.show_overlays = True
    for name in ("show_floor", "show_axis_x", "show_axis_y", "show_axis_z", "show_cursor",
                 "show_text", "show_object_origins", "show_ortho_grid", "show_stats",
                 "show_relationship_lines"):
        if hasattr(ov, name):
            setattr(ov, name, False)
    space.show_gizmo = False
    r3d.view_perspective = "PERSP"
    r3d.view_rotation = Euler((math.radians(80), 0.0, math.radians(15))).to_quaternion()
    r3d.view_location = (0.0, 0.0, 0.0)
    r3d.view_distance = 2.5
    with bpy.context.temp_override(window=win, area=area):
        ob = u.import_volume(u.ball_file(), frame_in_view=False)  # 0.64 units across
    # an opaque quad between the eye and the left half of the box
    plane = u.add_plane((0.8, 1.4), (-0.35, -0.6, 0.0), rotation=(math.radians(90), 0, 0))

    def shot():
        grab()
        yield 0.7
        grab()
        yield 0.7
        return capture.img

    ob.hide_viewport = True
    base = yield from shot()
    ob.hide_viewport = False
    with_box = yield from shot()
    ob.show_in_front = True  # how it was drawn before: over every mesh
    in_front = yield from shot()
    ob.show_in_front = False
    if base is None or with_box is None or in_front is None:
        check("captured", False)
        return
    # the plane's pixels, 3 px inside its projected outline
    h, wd = base.shape[:2]
    pc = np.array([[-0.75, -0.6, -0.7], [0.05, -0.6, -0.7], [0.05, -0.6, 0.7], [-0.75, -0.6, 0.7]])
    ndc, _ = ndc_of(pc, r3d)
    px = (ndc[:, 0] * 0.5 + 0.5) * wd
    py = (ndc[:, 1] * 0.5 + 0.5) * h
    x0, x1 = int(px.min()) + 3, int(px.max()) - 3
    y0, y1 = int(py.min()) + 3, int(py.max()) - 3
    inside = np.zeros((h, wd), bool)
    inside[max(y0, 0):y1, max(x0, 0):x1] = True
    # What POST_PIXEL reads is the overlay framebuffer: the wire is there as
    # opaque (black, unselected) pixels over transparent ones, so compare
    # RGBA, not only colour.
    diff = np.abs(with_box - base).max(axis=2)
    diff_front = np.abs(in_front - base).max(axis=2)
    check("outline_drawn_beside_the_mesh", (diff[~inside] > 0.1).sum() > 50,
          "%d outline pixels outside the plane" % (diff[~inside] > 0.1).sum())
    check("outline_hidden_by_the_mesh", (diff[inside] > 0.05).sum() == 0,
          "%d outline pixels over the plane (%d when drawn in front)"
          % ((diff[inside] > 0.05).sum(), (diff_front[inside] > 0.05).sum()))
    # the check can see the old behaviour: in front, the outline crosses the plane
    check("in_front_outline_would_show", (diff_front[inside] > 0.05).sum() > 20)
    bpy.data.objects.remove(plane)

    # 4. With the outline in the depth buffer, the volume still renders
    # inside the box (rays stop at its lines only).
    scene.voxlight.viewport_enabled = True
    scene.voxlight.viewport_resolution = 0.5
    ob.hide_viewport = True
    base = yield from shot()
    ob.hide_viewport = False
    for _ in range(10):
        img = yield from shot()
        if not vx.viewport.busy():
            break
    c = np.array([h // 2, wd // 2])
    d = np.abs(img[..., :3] - base[..., :3]).max(axis=2)
    check("volume_renders_with_outline", d[c[0] - 10:c[0] + 10, c[1] - 10:c[1] + 10].mean() > 0.1,
          "mean change at the centre %.3f" % d[c[0] - 10:c[0] + 10, c[1] - 10:c[1] + 10].mean())


RUN.start(steps())
