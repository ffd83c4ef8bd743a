"""GUI Blender under Xvfb: the viewport draw handler composites the volume.

xvfb-run -a -s "-screen 0 1280x1024x24" blender --factory-startup \
    --python-exit-code 1 --python tests/blender/test_gui.py

The steps run from a timer once the window exists. Pixels are read back by
a POST_PIXEL handler of this test (after the add-on's POST_VIEW composite).
The script exits itself with status 0 or 1 (a timer's exception would not
reach --python-exit-code), with a watchdog against hangs.
"""

import math
import os
import sys
import time

import bpy
import gpu
import numpy as np
from mathutils import Euler, Quaternion

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import _util as u  # noqa: E402

START = time.time()
LIMIT_S = 400
results = []
capture = {"want": False, "img": None}


def _capture_handler():
    if not capture["want"]:
        return
    region = bpy.context.region
    fb = gpu.state.active_framebuffer_get()
    buf = fb.read_color(0, 0, region.width, region.height, 4, 0, "FLOAT")
    capture["img"] = np.array(buf.to_list(), np.float32).reshape(region.height, region.width, 4)
    capture["want"] = False


def view3d():
    for win in bpy.context.window_manager.windows:
        for area in win.screen.areas:
            if area.type == "VIEW_3D":
                return win, area, area.spaces.active
    raise RuntimeError("no 3D viewport")


def redraw():
    for win in bpy.context.window_manager.windows:
        for area in win.screen.areas:
            area.tag_redraw()


def check(name, cond, detail=""):
    results.append((name, bool(cond)))
    print("%s %s %s" % ("PASS" if cond else "FAIL", name, detail), flush=True)


def finish():
    failed = sum(1 for _, ok in results if not ok)
    print("RESULT test_gui: %d passed, %d failed" % (len(results) - failed, failed), flush=True)
    sys.stdout.flush()
    os._exit(1 if failed else 0)


def steps():
    """A generator: each yield is the delay (s) before the next step."""
    vx = u.install_addon()
    bpy.types.SpaceView3D.draw_handler_add(_capture_handler, (), "WINDOW", "POST_PIXEL")
    scene = u.reset_scene()
    scene.voxlight.viewport_resolution = 0.5  # llvmpipe: keep each render short
    scene.voxlight.settle_time = 0.3
    win, area, space = view3d()
    space.shading.type = "SOLID"
    space.overlay.show_overlays = False  # no grid or outlines in the pixels
    r3d = space.region_3d
    r3d.view_perspective = "PERSP"
    r3d.view_location = (0.0, 0.0, 0.0)
    r3d.view_rotation = Euler((math.radians(90), 0.0, 0.0)).to_quaternion()  # front, from -Y
    r3d.view_distance = 4.0
    yield 0.5

    def grab():
        capture["want"], capture["img"] = True, None
        redraw()

    def settled():
        """Grab until the add-on stops re-rendering: after a scene change the
        viewport's anti-aliasing redraws a few times, and the depth the
        add-on reads settles with it."""
        last = -1
        for _ in range(15):
            grab()
            yield 1.0
            if capture["img"] is not None and vx.runtime.render_count == last:
                return
            last = vx.runtime.render_count

    # 1. The scene before the volume exists.
    grab()
    yield 1.0
    empty = capture["img"]
    check("capture_works", empty is not None)
    if empty is None:
        return

    with bpy.context.temp_override(window=win, area=area):
        ob = u.import_volume(u.CH2)
    yield from settled()
    vol = capture["img"]
    h, w = vol.shape[:2]
    cy, cx = h // 2, w // 2
    diff = np.abs(vol[..., :3] - empty[..., :3]).max(axis=2)
    centre = diff[cy - 20:cy + 20, cx - 20:cx + 20].mean()
    corner = diff[:40, :40].mean()
    check("volume_visible", centre > 0.1 and corner < 0.02, "centre %.3f corner %.3f"
          % (centre, corner))
    st = [s for k, s in vx.viewport._states.items() if k[1] == ob.name][0]
    region_w = [r for r in area.regions if r.type == "WINDOW"][0].width
    check("full_resolution_when_still", st.color is not None
          and st.color.width == max(1, round(region_w * 0.5)),
          "texture %dx%d, region width %d" % (st.color.width, st.color.height, region_w))

    # 2. Unrelated redraws do not re-render.
    n = vx.runtime.render_count
    for _ in range(3):
        redraw()
        yield 0.3
    check("no_rerender_on_redraw", vx.runtime.render_count == n,
          "%d -> %d" % (n, vx.runtime.render_count))

    # 3. An opaque plane in front of the left half hides the volume there.
    with bpy.context.temp_override(window=win, area=area):
        bpy.ops.mesh.primitive_plane_add(size=1.0, location=(-0.5, -1.5, 0.0),
                                         rotation=(math.radians(90), 0.0, 0.0))
    plane = bpy.context.view_layer.objects.active
    plane.scale = (1.0, 2.0, 1.0)
    ob.hide_set(True)
    yield from settled()
    plane_only = capture["img"]
    ob.hide_set(False)
    yield from settled()
    both = capture["img"]
    left = (cy, cx - 40)
    right = (cy, cx + 40)
    d_left = np.abs(both[left][:3] - plane_only[left][:3]).max()
    d_right = np.abs(both[right][:3] - vol[right][:3]).max()
    check("occluded_by_mesh_in_front", d_left < 0.02, "left differs from plane by %.3f" % d_left)
    check("visible_beside_mesh", d_right < 0.05 and np.abs(vol[right][:3] - empty[right][:3]).max()
          > 0.1, "right differs from volume-alone by %.3f" % d_right)

    # 4. Orbiting changes the image, first coarse then refined.
    plane.hide_set(True)
    yield from settled()
    before = capture["img"]
    n = vx.runtime.render_count
    r3d.view_rotation = Quaternion((0, 0, 1), math.radians(35)) @ r3d.view_rotation
    grab()
    yield 0.05
    moving_w = st.color.width if st.color is not None else 0
    yield from settled()
    after = capture["img"]
    change = np.abs(after[..., :3] - before[..., :3]).max(axis=2).mean()
    check("orbit_changes_image", change > 0.01, "mean change %.4f" % change)
    check("refined_after_moving", vx.runtime.render_count >= n + 2 and moving_w < st.color.width,
          "renders %d -> %d, widths %d -> %d" % (n, vx.runtime.render_count, moving_w,
                                                 st.color.width))


def main():
    it = steps()

    def tick():
        if time.time() - START > LIMIT_S:
            check("finished_in_time", False)
            finish()
        try:
            return next(it)
        except StopIteration:
            finish()
        except Exception:
            import traceback
            traceback.print_exc()
            check("no_exception", False)
            finish()
    bpy.app.timers.register(tick, first_interval=1.0)


main()
