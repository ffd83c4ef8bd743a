"""GUI Blender under Xvfb: F12 (the render job, as a user starts it), while
the viewport draws the volume, finishes without an error in every engine
(EEVEE, Cycles, Workbench), with perspective and orthographic cameras, and
with the volume's Cast Shadows on and off. A user once saw Blender freeze
on the first EEVEE F12 with a perspective camera and Cast Shadows on, so
that one runs first.

xvfb-run -a -s "-screen 0 1280x1024x24" blender --factory-startup \
    --enable-event-simulate --python-exit-code 1 --python tests/blender/test_gui_f12.py

A frozen main thread runs no timer, so _gui.Run's own limit cannot end a
hang: faulthandler's watchdog thread (no GIL needed) prints every Python
thread's stack and ends the process, which then has no RESULT line and
fails in tools/run_blender_tests.sh.
"""

import faulthandler
import os
import sys
import time

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import _gui  # noqa: E402
import _util as u  # noqa: E402

HANG_S = 560  # under the runner's 600 s per script; each of the 12 renders takes seconds
faulthandler.dump_traceback_later(HANG_S, exit=True)
RUN = _gui.Run("test_gui_f12", limit_s=HANG_S)
check = RUN.check

# Blender prints a handler's exception through sys.excepthook: keep them,
# so one raised on the render thread fails the test (it only printed before).
_raised = []


def _keep(kind, value, tb):
    _raised.append("%s: %s" % (kind.__name__, value))
    sys.__excepthook__(kind, value, tb)


sys.excepthook = _keep
EEVEE = "BLENDER_EEVEE_NEXT" if (4, 2, 0) <= bpy.app.version < (5, 0, 0) else "BLENDER_EEVEE"


def steps():
    vx = u.install_addon()
    scene = u.reset_scene()
    ob = u.import_volume(u.CH2)
    ob.voxlight.cast_shadows = True
    u.add_plane((6.0, 6.0), (0.0, 0.0, -1.0), name="Floor", color=(0.6, 0.6, 0.6))
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy = 3.0
    sun.rotation_euler = (0.4, 0.3, 0.0)
    scene.collection.objects.link(sun)
    cam = u.add_camera((0.0, -5.0, 2.0))
    if hasattr(scene.eevee, "taa_render_samples"):
        scene.eevee.taa_render_samples = 8
    scene.cycles.samples = 4
    scene.cycles.use_denoising = False  # Debian's Cycles has no OIDN
    scene.cycles.device = "CPU"
    scene.render.resolution_x, scene.render.resolution_y = 160, 120
    scene.render.resolution_percentage = 100
    done = []
    bpy.app.handlers.render_complete.append(lambda *a: done.append(True))
    yield 1.0  # the viewport draws the volume first
    for engine in (EEVEE, "CYCLES", "BLENDER_WORKBENCH"):
        for shadows in (True, False):
            for kind in ("PERSP", "ORTHO"):
                def set_up():
                    scene.render.engine = engine
                    ob.voxlight.cast_shadows = shadows
                    cam.data.type = kind
                    cam.data.ortho_scale = 4.0
                yield from _gui.write(set_up)
                name = "%s_%s_%s" % (engine.lower().replace("blender_", ""), kind.lower(),
                                     "shadows" if shadows else "no_shadows")
                del done[:]
                t = time.time()
                bpy.ops.render.render("INVOKE_DEFAULT")
                # until the job has ended, not only rendered: Blender refuses
                # writes to the scene while its render thread is still closing
                while (not done or bpy.app.is_job_running("RENDER")) and time.time() - t < HANG_S / 12:
                    yield 0.25
                check("f12_%s_finishes" % name, done, "%.1f s" % (time.time() - t))
                check("f12_%s_no_error" % name, not vx.render_hooks.last_error and not _raised,
                      vx.render_hooks.last_error or "; ".join(_raised))
                del _raised[:]
                yield 0.5


RUN.start(steps())
