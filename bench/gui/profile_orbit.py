"""Profile viewport draws after view changes (VOXLIGHT_PROFILE=1), ch2better, defaults.
Also Blender's own frame (PRE_VIEW -> POST_PIXEL, synced by a 1-pixel depth read) with
the volume shown and hidden."""
import math, os, sys, time
import bpy, gpu
from mathutils import Quaternion
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tests", "blender"))
import _gui, _util as u

RUN = _gui.Run("profile_orbit", limit_s=560)
T = {"pre": None, "change": None}

def pre_view():
    T["pre"] = time.perf_counter()

def post_pixel():
    if T["pre"] is None:
        return
    gpu.state.active_framebuffer_get().read_depth(0, 0, 1, 1)  # wait for every queued GL command
    t = time.perf_counter()
    since = "" if T["change"] is None else ", view change -> here %.4f s" % (t - T["change"])
    print("frame: pre_view -> post_pixel (synced) %.4f s%s" % (t - T["pre"], since), flush=True)
    T["pre"] = T["change"] = None

def view3d():
    for win in bpy.context.window_manager.windows:
        for area in win.screen.areas:
            if area.type == "VIEW_3D":
                return win, area, area.spaces.active

def steps():
    vx = u.install_addon()
    rt, vp = vx.core.runtime, vx.viewport
    bpy.types.SpaceView3D.draw_handler_add(pre_view, (), "WINDOW", "PRE_VIEW")
    bpy.types.SpaceView3D.draw_handler_add(post_pixel, (), "WINDOW", "POST_PIXEL")
    scene = u.reset_scene()
    win, area, space = view3d()
    r3d = _gui.front_view(space)
    region = [r for r in area.regions if r.type == "WINDOW"][0]
    print("region %dx%d" % (region.width, region.height), flush=True)
    with bpy.context.temp_override(window=win, area=area):
        ob = u.import_volume(u.CH2, frame_in_view=False)
    yield 3.0
    for label, hidden in (("volume shown", False), ("volume hidden", True)):
        ob.hide_set(hidden)
        for i in range(int(os.environ.get("ORBITS", "3"))):
            while vp.busy():
                yield 0.2
            yield 1.0
            T["change"] = t0 = time.perf_counter()
            print("=== orbit %d (%s) at t=%.3f" % (i, label, t0), flush=True)
            r3d.view_rotation = Quaternion((0, 0, 1), math.radians(20)) @ r3d.view_rotation
            area.tag_redraw()
            yield 0.3
            while vp.busy():
                yield 0.1
            yield 0.5
            print("=== orbit %d settled after %.2f s" % (i, time.perf_counter() - t0), flush=True)
    RUN.check("ran", True)

RUN.start(steps())
