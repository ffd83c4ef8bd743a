"""GUI Blender under Xvfb: the volume's shadow on a floor shows in the 3D
viewport as a multiply layer once the view has settled, and
goes when Cast Shadows is switched off.

xvfb-run -a -s "-screen 0 1280x1024x24" blender --factory-startup \
    --enable-event-simulate --python-exit-code 1 --python tests/blender/test_gui_scene_shadows.py
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

RUN = _gui.Run("test_gui_scene_shadows", limit_s=300)
check = RUN.check
capture = _gui.Capture()


def steps():
    vx = u.install_addon()
    layer = vx.scene_shadows_viewport
    win = bpy.context.window_manager.windows[0]
    area = next(a for a in win.screen.areas if a.type == "VIEW_3D")
    space = area.spaces.active
    space.overlay.show_overlays = False
    space.shading.type = "SOLID"
    r3d = space.region_3d
    r3d.view_perspective = "PERSP"
    r3d.view_location = (0.6, 0.0, 0.0)
    r3d.view_rotation = Euler((math.radians(35), 0.0, 0.0)).to_quaternion()  # looking down
    r3d.view_distance = 5.0
    capture.install()
    scene = u.reset_scene()
    s = scene.voxlight
    s.viewport_resolution, s.settle_time = 0.5, 0.3
    u.add_plane((8.0, 8.0), (0.0, 0.0, 0.0), name="Floor", color=(0.8, 0.8, 0.8))
    scene.cursor.location = (0.0, 0.0, 1.0)
    with bpy.context.temp_override(window=win, area=area):
        ob = u.import_volume(u.ball_file())
    ob.voxlight.opacity_scale = 8.0
    ob.voxlight.cast_shadows = False
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    scene.collection.objects.link(sun)
    sun.rotation_euler = (0.0, math.radians(35), 0.0)  # the shadow falls beside the ball
    bpy.context.view_layer.update()
    d = -np.array(sun.matrix_world)[:3, 2]
    c = np.array([0.0, 0.0, 1.0])
    shadow = c - (c[2] / d[2]) * d
    lit = shadow + np.array([0.0, 1.3, 0.0])
    region = next(r for r in area.regions if r.type == "WINDOW")

    def patch(img, world):
        from bpy_extras.view3d_utils import location_3d_to_region_2d
        x, y = location_3d_to_region_2d(region, r3d, world)
        x, y = int(x), int(y)
        return img[y - 3:y + 4, x - 3:x + 4]

    def coverage(img, world):
        return float(patch(img, world)[..., 3].mean())

    def on_rgb(img, world):
        return float(patch(img, world)[..., :3].max())

    def grab(wait_layer):
        for _ in range(60):
            capture.request()
            area.tag_redraw()
            yield 0.3
            st = layer._states.get(region.as_pointer())
            done = st is not None and st.key is not None and st.shown_key == st.key
            if capture.img is not None and (done or not wait_layer) and \
                    not vx.viewport.busy():
                return capture.img
        return capture.img

    off = yield from grab(False)
    ob.voxlight.cast_shadows = True
    on = yield from grab(True)
    st = layer._states.get(region.as_pointer())
    # Receive Shadows: the draw passed the floor (2 triangles) as the occluders.
    occ = vx.scene_shadows._viewport["value"]
    check("viewport_occluders", occ is not None and len(occ[1]) == 2 and
          vx.scene_shadows.for_viewport(ob) is occ)
    check("layer_computed", st is not None and st.shown_key == st.key and st.texture is not None)
    # The handler draws into the buffer Blender lays over its scene: the
    # shadow is black there with coverage 1 - T (scene x T once laid over).
    check("nothing_over_the_floor_when_off", coverage(off, shadow) < 0.02, "%.3f" % coverage(off, shadow))
    check("floor_darker_in_the_shadow", coverage(on, shadow) > 0.4, "%.3f" % coverage(on, shadow))
    check("floor_unchanged_in_the_light", coverage(on, lit) < 0.02, "%.3f" % coverage(on, lit))
    check("the_layer_is_black", float(on_rgb(on, shadow)) < 0.02)
    ob.voxlight.cast_shadows = False
    again = yield from grab(False)
    check("cast_shadows_off_removes_it", coverage(again, shadow) < 0.02, "%.3f" % coverage(again, shadow))


RUN.start(steps())
