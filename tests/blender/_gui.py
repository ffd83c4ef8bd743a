"""Shared harness of the GUI test scripts (test_gui*.py, run under Xvfb).

A GUI script cannot end through --python-exit-code: its steps run from a
timer once the window exists, and a timer's exception never reaches Blender's
exit code. So each script records checks here and ends the process itself,
with a watchdog against hangs:

    g = _gui.Run("test_gui_panel", limit_s=300)
    g.check("labels_fit", ok, detail)
    g.start(steps())   # steps(): a generator; each yield is the delay (s)
                       # before the next step

Pixels of the 3D viewport are read by a POST_PIXEL handler (Capture), after
the add-on's own POST_VIEW composite.
"""

import math
import os
import sys
import time
import traceback

import bpy
from mathutils import Euler


def view3d():
    """(window, area, space) of the first 3D viewport."""
    for win in bpy.context.window_manager.windows:
        for area in win.screen.areas:
            if area.type == "VIEW_3D":
                return win, area, area.spaces.active
    raise RuntimeError("no 3D viewport")


def front_view(space):
    """The GUI tests' view: Solid shading, perspective, from the front (-Y),
    4 units from the origin. Returns the view's RegionView3D."""
    space.shading.type = "SOLID"
    r3d = space.region_3d
    r3d.view_perspective = "PERSP"
    r3d.view_location = (0.0, 0.0, 0.0)
    r3d.view_rotation = Euler((math.radians(90), 0.0, 0.0)).to_quaternion()  # front, from -Y
    r3d.view_distance = 4.0
    return r3d


def write(fn, tries=100):
    """A generator step: fn() (it writes Blender data), again on later ticks
    while Blender refuses the write. Blender's "writes refused" flag is one
    for the process, saved and restored around each Python panel draw and
    around Cycles' engine being made on the render thread; when the two
    overlap, the flag stays set on the main thread until the next panel
    draw ends (seen once in CI, right after an F12 with Cycles). A user's
    script meets the same; the add-on's own code is tested for it in
    test_gui_render_writes."""
    for _ in range(tries):
        try:
            fn()
            return
        except AttributeError as e:
            if "not allowed" not in str(e):
                raise
        for win in bpy.context.window_manager.windows:
            for area in win.screen.areas:
                area.tag_redraw()
        yield 0.1
    fn()


class Run:
    def __init__(self, name, limit_s):
        self.name = name
        self.limit_s = limit_s
        self.started = time.time()
        self.results = []

    def check(self, name, cond, detail=""):
        self.results.append((name, bool(cond)))
        print("%s %s %s" % ("PASS" if cond else "FAIL", name, detail), flush=True)

    def finish(self):
        failed = sum(1 for _, ok in self.results if not ok)
        print("RESULT %s: %d passed, %d failed" % (self.name, len(self.results) - failed, failed),
              flush=True)
        sys.stdout.flush()
        os._exit(1 if failed else 0)

    def start(self, steps):
        """Runs the generator's steps from a timer; any exception, the end of
        the steps or the time limit finishes the script."""
        def tick():
            if time.time() - self.started > self.limit_s:
                self.check("finished_in_time", False)
                self.finish()
            try:
                return next(steps)
            except StopIteration:
                self.finish()
            except Exception:
                traceback.print_exc()
                self.check("no_exception", False)
                self.finish()
        bpy.app.timers.register(tick, first_interval=1.0)


class Capture:
    """Reads the 3D viewport's pixels when asked: set want, redraw, then img
    holds (h, w, 4) float, row 0 = bottom."""

    def __init__(self):
        self.want = False
        self.img = None
        self._handle = None

    def install(self):
        self._handle = bpy.types.SpaceView3D.draw_handler_add(self._draw, (), "WINDOW", "POST_PIXEL")

    def request(self):
        self.want, self.img = True, None

    def _draw(self):
        if not self.want:
            return
        import gpu
        import numpy as np
        region = bpy.context.region
        w, h = region.width, region.height
        fb = gpu.state.active_framebuffer_get()
        # A flat Buffer, read without a per-pixel Python list: Blender 3.4
        # exports multi-dimensional Buffers with Fortran strides (see
        # viewport._read_window_depth), a flat one is unambiguous.
        buf = gpu.types.Buffer("FLOAT", w * h * 4)
        fb.read_color(0, 0, w, h, 4, 0, "FLOAT", data=buf)
        self.img = np.array(buf, np.float32).reshape(h, w, 4)
        self.want = False

    def settled(self, vx, area, tries=40):
        """Steps (yield from it) that grab until the add-on `vx` has nothing
        in flight and stops rendering: the refined frame renders in the
        background after the view settles. self.img is then the still frame."""
        last = -1
        for _ in range(tries):
            self.request()
            area.tag_redraw()
            yield 0.5
            if self.img is not None and not vx.viewport.busy() and vx.core.runtime.render_count == last:
                return
            last = vx.core.runtime.render_count
