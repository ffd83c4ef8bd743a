"""Scripted orbit: how many frames a second Blender draws while the view turns,
with the Voxlight volume shown and without it, and how soon the full-resolution
image follows once the view stops. ch2better, the add-on's defaults.

Run by Blender under Xvfb (docs/viewport_latency.md has the command):

    xvfb-run -a -s "-screen 0 1280x1024x24" blender --factory-startup \
        --enable-event-simulate --python-exit-code 1 --python bench/gui/orbit_fps.py

A timer turns the view about the vertical axis at ORBIT_DEG_S degrees a
second (by wall time, as a mouse drag would) for ORBIT_S seconds; the timer
fires once per pass of Blender's event loop, so every frame Blender draws
shows a new view. A POST_PIXEL handler counts the 3D view's frames. Each
orbit runs ORBITS times with the volume shown and as often with it hidden
(the baseline: Blender's own scene, the add-on's handler returns at once).

The setup (environment):
  LAYOUT    "single": the 3D view alone in the window (the other editors
            closed: one area, so one region redraws);
            "default": the factory layout (3D view, outliner, properties,
            timeline). Default "single".
  OVERLAYS  1 (default) the viewport overlays as an artist has them (grid,
            axes, gizmos, outlines); 0 none.
  AA        the viewport anti-aliasing preference (Preferences > Viewport >
            Quality): "OFF", "FXAA", "5", "8", ...; default: Blender's own.
The window size is Xvfb's screen (or Blender's -p x y w h).

Prints per orbit a line, then one summary line to paste:
  orbit_fps: region WxH layout=... | with volume F fps (...) | without F fps |
             full resolution S s after the view stopped (...)
"""

import math
import os
import statistics
import sys
import time

import bpy
from mathutils import Quaternion

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..",
                                "tests", "blender"))
import _gui  # noqa: E402
import _util as u  # noqa: E402

RUN = _gui.Run("orbit_fps", limit_s=560)
ORBIT_S = float(os.environ.get("ORBIT_S", "4"))
ORBIT_DEG_S = float(os.environ.get("ORBIT_DEG_S", "90"))
ORBITS = int(os.environ.get("ORBITS", "2"))
LAYOUT = os.environ.get("LAYOUT", "single")
OVERLAYS = os.environ.get("OVERLAYS", "1") not in ("", "0")
AA = os.environ.get("AA", "")


class Counter:
    """POST_PIXEL of the 3D view: the time of each frame drawn, and of each
    new image the add-on shows (viewport.shown_log grows by one per image)."""

    def __init__(self, vp):
        self.vp = vp
        self.frames = []
        self.images = []     # (time, kind, width, height)
        self._seen = None

    def post_pixel(self):
        t = time.perf_counter()
        self.frames.append(t)
        log = self.vp.shown_log
        last = log[-1] if log else None
        if last is not None and (self._seen is None or last is not self._seen):
            self.images.append((t, last[1], last[3], last[4]))
        self._seen = last

    def reset(self):
        self.frames, self.images = [], []


def fps(times):
    if len(times) < 2:
        return 0.0
    return (len(times) - 1) / (times[-1] - times[0])


def orbit(r3d, area, seconds):
    """Generator steps: turn the view for `seconds`; returns the time of the
    last view change (perf_counter)."""
    base = r3d.view_rotation.copy()
    t0 = time.perf_counter()
    state = {"last": t0}

    def tick():
        t = time.perf_counter()
        angle = math.radians(ORBIT_DEG_S * (t - t0))
        r3d.view_rotation = Quaternion((0, 0, 1), angle) @ base
        area.tag_redraw()
        state["last"] = t
        return 0.0 if t - t0 < seconds else None

    bpy.app.timers.register(tick, first_interval=0.0)
    while bpy.app.timers.is_registered(tick):
        yield 0.2
    return state["last"]


def steps():
    vx = u.install_addon()
    vp, rt = vx.viewport, vx.core.runtime
    if AA:
        bpy.context.preferences.system.viewport_aa = AA
    u.reset_scene()
    win, area, space = _gui.view3d()
    if LAYOUT == "single":
        # Close the other editors (Blender 3.4's screen_full_area crashes
        # when run from a timer).
        for a in list(win.screen.areas):
            if a.type != "VIEW_3D":
                with bpy.context.temp_override(window=win, screen=win.screen, area=a):
                    bpy.ops.screen.area_close()
        yield 0.5
        win, area, space = _gui.view3d()
    space.overlay.show_overlays = OVERLAYS
    r3d = _gui.front_view(space)
    region = [r for r in area.regions if r.type == "WINDOW"][0]
    with bpy.context.temp_override(window=win, area=area):
        ob = u.import_volume(u.CH2, frame_in_view=False)
    counter = Counter(vp)
    bpy.types.SpaceView3D.draw_handler_add(counter.post_pixel, (), "WINDOW", "POST_PIXEL")
    yield 3.0
    import gpu
    setup = "region %dx%d layout=%s overlays=%s aa=%s areas=%d gl=%s" % (
        region.width, region.height, LAYOUT, "on" if OVERLAYS else "off",
        bpy.context.preferences.system.viewport_aa, len(win.screen.areas),
        gpu.platform.renderer_get().split(" (")[0].replace(" ", "_"))
    print("orbit_fps setup: " + setup, flush=True)

    results = {True: [], False: []}
    refine = []
    cpu_per_frame = {True: [], False: []}
    for shown in (True, False) * ORBITS:
        ob.hide_set(not shown)
        for _ in range(100):  # the view and every refine settled
            yield 0.2
            if not vp.busy():
                break
        yield 1.0
        counter.reset()
        d0 = vp.draw_count
        t_start = time.perf_counter()
        cpu0 = time.process_time()
        last_change = yield from orbit(r3d, area, ORBIT_S)
        cpu = time.process_time() - cpu0
        frames = [t for t in counter.frames if t_start <= t <= last_change + 1e-3]
        new = min(vp.draw_count - d0, len(vp.draw_log))
        handler = [d for d, moving, _ in list(vp.draw_log)[len(vp.draw_log) - new:] if moving]
        previews = [i for i in counter.images if i[1] == "preview" and i[0] <= last_change + 1e-3]
        rate = fps(frames)
        results[shown].append(rate)
        cpu_frame = cpu / max(len(frames), 1)
        cpu_per_frame[shown].append(cpu_frame)
        line = "orbit (%s): %d frames in %.2f s = %.1f fps, CPU %.3f s a frame (all threads)" % (
            "volume shown" if shown else "volume hidden", len(frames),
            frames[-1] - frames[0] if len(frames) > 1 else 0.0, rate, cpu_frame)
        if shown:
            widths = sorted(w for _t, _k, w, _h in previews)
            line += "; %d new previews (median width %d px); handler median %.1f ms" % (
                len(previews), widths[len(widths) // 2] if widths else 0,
                1000 * statistics.median(handler) if handler else 0.0)
            # The refinement after the view stopped.
            for _ in range(300):
                yield 0.1
                if any(k == "full" and t > last_change for t, k, _w, _h in counter.images):
                    break
            after = [(t - last_change, k, w, h) for t, k, w, h in counter.images if t > last_change]
            full = [a for a in after if a[1] == "full"]
            refine.append(full[0][0] if full else float("inf"))
            line += "; after the stop: " + ", ".join("%s %dx%d +%.2f s" % (k, w, h, dt)
                                                      for dt, k, w, h in after)
        print(line, flush=True)

    RUN.check("orbit_drew_frames", all(results[True]) and all(results[False]))
    full_s = [r for r in refine if math.isfinite(r)]
    RUN.check("full_resolution_after_orbit", len(full_s) == len(refine))
    print("orbit_fps: %s | with volume %.1f fps (CPU %.3f s a frame) | without %.1f fps "
          "(CPU %.3f s) | full resolution %s s after "
          "the view stopped | orbit %.0f deg/s for %.0f s, median of %d, load %.2f" % (
              setup, statistics.median(results[True]), statistics.median(cpu_per_frame[True]),
              statistics.median(results[False]), statistics.median(cpu_per_frame[False]),
              "%.2f" % statistics.median(full_s) if full_s else "never",
              ORBIT_DEG_S, ORBIT_S, ORBITS, os.getloadavg()[0]), flush=True)


RUN.start(steps())
