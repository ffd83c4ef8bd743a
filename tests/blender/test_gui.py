"""GUI Blender under Xvfb: the viewport draw handler composites the volume.

xvfb-run -a -s "-screen 0 1280x1024x24" blender --factory-startup \
    --enable-event-simulate --python-exit-code 1 --python tests/blender/test_gui.py

The steps run from a timer once the window exists. Pixels are read back by
a POST_PIXEL handler of this test (after the add-on's POST_VIEW composite).
The script exits itself with status 0 or 1 (a timer's exception would not
reach --python-exit-code), with a watchdog against hangs.

Renders are counted with the add-on's counters: runtime.render_count
(frames), runtime.call_count (library vxl_render calls) and
viewport.draw_count (draw handler calls, to prove that a redraw happened).
--enable-event-simulate lets the test move the mouse over buttons and
gizmos (Window.event_simulate): real UI hover redraws.
"""

import math
import os
import sys
import time

import bpy
import numpy as np
from mathutils import Quaternion

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import _gui  # noqa: E402
import _util as u  # noqa: E402

RUN = _gui.Run("test_gui", limit_s=560)  # a watchdog, under the runner's 600 s
check = RUN.check
finish = RUN.finish
capture = _gui.Capture()


def redraw(types=None):
    for win in bpy.context.window_manager.windows:
        for area in win.screen.areas:
            if types is None or area.type in types:
                area.tag_redraw()


def steps():
    """A generator: each yield is the delay (s) before the next step."""
    vx = u.install_addon()
    rt, vp = vx.core.runtime, vx.viewport
    capture.install()
    scene = u.reset_scene()
    scene.voxlight.viewport_resolution = 0.5  # llvmpipe: keep each render short
    scene.voxlight.settle_time = 0.3
    win, area, space = _gui.view3d()
    space.overlay.show_overlays = False  # no grid or outlines in the pixels
    r3d = _gui.front_view(space)
    region = [r for r in area.regions if r.type == "WINDOW"][0]
    for a in win.screen.areas:  # the Voxlight panel (with its frame stats) is drawn too
        if a.type == "PROPERTIES":
            a.spaces.active.context = "DATA"
    yield 0.5

    def grab():
        capture.request()
        redraw(("VIEW_3D",))

    def settled():
        """Grab until the add-on has nothing in flight and stops rendering:
        the refined frame is rendered in the background after the view
        settles."""
        last = -1
        for _ in range(40):
            grab()
            yield 0.5
            if capture.img is not None and not vp.busy() and rt.render_count == last:
                return
            last = rt.render_count

    def counts():
        return rt.render_count, rt.call_count, vp.draw_count

    # 1. The scene before the volume exists.
    grab()
    yield 1.0
    empty = capture.img
    check("capture_works", empty is not None)
    if empty is None:
        return

    with bpy.context.temp_override(window=win, area=area):
        ob = u.import_volume(u.CH2, frame_in_view=False)  # this test sets its own view
    yield from settled()
    vol = capture.img
    h, w = vol.shape[:2]
    cy, cx = h // 2, w // 2
    diff = np.abs(vol[..., :3] - empty[..., :3]).max(axis=2)
    centre = diff[cy - 20:cy + 20, cx - 20:cx + 20].mean()
    corner = diff[:40, :40].mean()
    check("volume_visible", centre > 0.1 and corner < 0.02, "centre %.3f corner %.3f"
          % (centre, corner))
    st = [s for k, s in vp._states.items() if k[1] == ob.name][0]
    check("full_resolution_when_still", st.shown is not None and st.shown.full
          and st.shown.width == max(1, round(region.width * 0.5)),
          "texture %dx%d, region width %d" % (st.shown.width, st.shown.height, region.width))

    # 2. Unrelated redraws do not re-render: tagged redraws of every area and
    # of other editors, frame changes with nothing animated, and the mouse
    # hovering over header buttons, the navigation gizmo and other editors.
    f0, c0, d0 = counts()
    for _ in range(3):
        redraw()
        yield 0.3
    for _ in range(2):
        redraw(("PROPERTIES", "OUTLINER", "DOPESHEET_EDITOR", "TIMELINE"))
        yield 0.2
    f1, c1, d1 = counts()
    check("no_rerender_on_tagged_redraws", (f1, c1) == (f0, c0) and d1 >= d0 + 3,
          "frames %d -> %d, calls %d -> %d, viewport draws %d -> %d" % (f0, f1, c0, c1, d0, d1))

    for frame in (5, 17, 2, 1):
        scene.frame_set(frame)
        yield 0.3
    scene.frame_current = 40
    yield 0.3
    scene.frame_set(1)
    yield 0.5
    f2, c2, d2 = counts()
    check("no_rerender_on_frame_change", (f2, c2) == (f1, c1) and d2 > d1,
          "frames %d -> %d, calls %d -> %d, viewport draws %d -> %d" % (f1, f2, c1, c2, d1, d2))

    hover_ok = hasattr(win, "event_simulate")
    if hover_ok:
        header = [r for r in area.regions if r.type == "HEADER"][0]
        targets = []
        # Along the 3D view's header (its buttons highlight under the mouse).
        for fx in np.linspace(0.05, 0.95, 12):
            targets.append((header.x + int(header.width * fx), header.y + header.height // 2))
        # Over the navigation gizmo at the region's top right, and back out.
        for dx, dy in ((60, 80), (45, 60), (80, 130), (60, 190), (200, 200)):
            targets.append((region.x + region.width - dx, region.y + region.height - dy))
        # Over the other editors (outliner, properties, timeline).
        for a in win.screen.areas:
            if a.type != "VIEW_3D":
                for fy in (0.3, 0.6):
                    targets.append((a.x + a.width // 2, a.y + int(a.height * fy)))
        try:
            for x, y in targets:
                win.event_simulate(type="MOUSEMOVE", value="NOTHING", x=int(x), y=int(y))
                yield 0.1
        except Exception as e:  # Blender started without --enable-event-simulate
            hover_ok = False
            print("event_simulate unavailable: %s" % e)
        yield 0.5
    f3, c3, d3 = counts()
    check("no_rerender_on_hover", hover_ok and (f3, c3) == (f2, c2) and d3 > d2,
          "frames %d -> %d, calls %d -> %d, viewport draws %d -> %d (hover simulated: %s)"
          % (f2, f3, c2, c3, d2, d3, hover_ok))

    # 3. An opaque plane in front of the left half hides the volume there.
    with bpy.context.temp_override(window=win, area=area):
        bpy.ops.mesh.primitive_plane_add(size=1.0, location=(-0.5, -1.5, 0.0),
                                         rotation=(math.radians(90), 0.0, 0.0))
    plane = bpy.context.view_layer.objects.active
    plane.scale = (1.0, 2.0, 1.0)
    ob.hide_set(True)
    yield from settled()
    plane_only = capture.img
    ob.hide_set(False)
    yield from settled()
    both = capture.img
    left = (cy, cx - 40)
    right = (cy, cx + 40)
    d_left = np.abs(both[left][:3] - plane_only[left][:3]).max()
    d_right = np.abs(both[right][:3] - vol[right][:3]).max()
    check("occluded_by_mesh_in_front", d_left < 0.02, "left differs from plane by %.3f" % d_left)
    check("visible_beside_mesh", d_right < 0.05 and np.abs(vol[right][:3] - empty[right][:3]).max()
          > 0.1, "right differs from volume-alone by %.3f" % d_right)
    # The whole unoccluded half equals the volume alone, not only one pixel.
    half = np.abs(both[:, cx + 10:, :3] - vol[:, cx + 10:, :3]).max(axis=2)
    check("unoccluded_half_unchanged", np.mean(half > 0.05) < 0.002,
          "%.4f of the right half differs" % np.mean(half > 0.05))

    # 4. Hidden, excluded, disabled or off-screen volumes cost nothing: no
    # library call while they are away. When they come back unchanged, the
    # cached frame is still right, so even then nothing is rendered.
    plane.hide_set(True)
    yield from settled()
    coll = bpy.data.collections.new("Volumes")
    scene.collection.children.link(coll)
    coll.objects.link(ob)
    for c in list(ob.users_collection):
        if c is not coll:
            c.objects.unlink(ob)
    yield from settled()
    layer_coll = bpy.context.view_layer.layer_collection.children[coll.name]

    def away_and_back(label, hide, show):
        f_a, c_a, d_a = counts()
        hide()
        for _ in range(3):
            grab()
            yield 0.4
        gone = capture.img
        f_b, c_b, d_b = counts()
        no_volume = gone is not None and np.abs(gone[..., :3] - empty[..., :3]).max() < 0.02
        check("no_render_when_" + label, c_b == c_a and d_b > d_a and no_volume,
              "calls %d -> %d, draws %d -> %d, volume gone from the pixels: %s"
              % (c_a, c_b, d_a, d_b, no_volume))
        show()
        yield from settled()
        back = capture.img
        f_c, c_c, _ = counts()
        same = np.abs(back[..., :3] - vol[..., :3]).max() < 0.02
        check("cached_frame_when_back_from_" + label, c_c == c_b and same,
              "calls %d -> %d, image as before: %s" % (c_b, c_c, same))

    yield from away_and_back("hidden", lambda: ob.hide_set(True), lambda: ob.hide_set(False))
    yield from away_and_back("collection_excluded",
                             lambda: setattr(layer_coll, "exclude", True),
                             lambda: setattr(layer_coll, "exclude", False))
    # exclude resets the layer collection; fetch it again
    layer_coll = bpy.context.view_layer.layer_collection.children[coll.name]
    yield from away_and_back("collection_disabled",
                             lambda: setattr(coll, "hide_viewport", True),
                             lambda: setattr(coll, "hide_viewport", False))
    yield from away_and_back("collection_hidden",
                             lambda: setattr(layer_coll, "hide_viewport", True),
                             lambda: setattr(layer_coll, "hide_viewport", False))
    home = tuple(ob.location)
    culled = vp.culled_count
    yield from away_and_back("outside_frustum",
                             lambda: setattr(ob, "location", (home[0] + 50.0, home[1], home[2])),
                             lambda: setattr(ob, "location", home))
    check("outside_frustum_was_culled", vp.culled_count > culled,
          "culled %d -> %d" % (culled, vp.culled_count))

    # 5. Orbiting changes the image, first coarse then refined in steps the
    # artist sees: the interactive preview, half the still resolution, then
    # the full one. With previews of at most 0.1 the half step (0.25 of the
    # still 0.5) is always sharper than the preview, so it is due.
    interactive_was = scene.voxlight.interactive_resolution
    scene.voxlight.interactive_resolution = 0.1
    worth_was = vp.HALF_STEP_WORTH_S
    vp.HALF_STEP_WORTH_S = 0.0  # the half step is due however fast the full frame is
    yield from settled()
    before = capture.img
    n = rt.render_count
    vp.shown_log.clear()
    r3d.view_rotation = Quaternion((0, 0, 1), math.radians(35)) @ r3d.view_rotation
    grab()
    yield 0.05
    moving_w = st.shown.width if st.shown is not None else 0
    yield from settled()
    after = capture.img
    change = np.abs(after[..., :3] - before[..., :3]).max(axis=2).mean()
    # (a frame left stale changes nothing: 0; the shading turning with the
    # view changes the image by about 0.01 of the display range, less since
    # the lit colour is scene-linear and encoded for display, which
    # compresses the lit side's contrast)
    check("orbit_changes_image", change > 0.004, "mean change %.4f" % change)
    check("refined_after_moving", rt.render_count >= n + 2 and moving_w < st.shown.width
          and st.shown.full,
          "renders %d -> %d, widths %d -> %d" % (n, rt.render_count, moving_w, st.shown.width))
    shown = [e[1:] for e in vp.shown_log if e[0] == ob.name]  # (kind, scale, width, height)
    steps_seen = [k for i, (k, *_rest) in enumerate(shown) if i == 0 or shown[i - 1][0] != k]
    interactive = scene.voxlight.interactive_resolution
    check("refine_steps_preview_half_full",
          steps_seen == ["preview", "half", "full"]
          and all(sc <= interactive + 1e-6 for k, sc, _w, _h in shown if k == "preview")
          and all(sc == 0.25 and w == round(region.width * 0.25) for k, sc, w, _h in shown if k == "half")
          and all(sc == 0.5 and w == round(region.width * 0.5) for k, sc, w, _h in shown if k == "full"),
          "shown after the view change: %s" % ["%s %.3f %dx%d" % e for e in shown])

    # 5b. A scripted orbit, as the artist drags (bench/gui/orbit_fps.py
    # measures its speed): a timer turns the view on every pass of Blender's
    # event loop until the viewport has drawn 6 times. Every frame of the
    # orbit shows a new preview, and the full resolution follows once the
    # view stops; with the full frame predicted quick (forced here) the
    # half step is skipped, so the full image comes one redraw sooner.
    vp.HALF_STEP_WORTH_S = float("inf")
    yield from settled()
    vp.shown_log.clear()
    d0 = vp.draw_count

    def turn():
        r3d.view_rotation = Quaternion((0, 0, 1), math.radians(4)) @ r3d.view_rotation
        area.tag_redraw()
        return 0.0 if vp.draw_count - d0 < 6 else None
    bpy.app.timers.register(turn, first_interval=0.0)
    for _ in range(600):
        yield 0.1
        if not bpy.app.timers.is_registered(turn):
            break
    orbit_draws = vp.draw_count - d0
    moving_draws = [m for _d, m, _f in list(vp.draw_log)[-min(orbit_draws, len(vp.draw_log)):]]
    orbit_shown = [e[1] for e in vp.shown_log if e[0] == ob.name]
    yield from settled()
    shown = [e[1:] for e in vp.shown_log if e[0] == ob.name]
    kinds = [k for k, *_rest in shown]
    after = kinds[len(kinds) - 1 - kinds[::-1].index("preview") + 1:] if "preview" in kinds else kinds
    check("orbit_draws_previews", orbit_draws >= 6 and orbit_shown.count("preview") >= 4
          and set(orbit_shown) == {"preview"},
          "%d draws, %d moving; shown during the orbit: %s"
          % (orbit_draws, sum(moving_draws), orbit_shown))
    check("orbit_refines_to_full", after == ["full"] and st.shown.full
          and st.shown.width == round(region.width * 0.5),
          "shown after the last preview: %s (%dx%d)" % (after, st.shown.width, st.shown.height))
    vp.HALF_STEP_WORTH_S = worth_was
    scene.voxlight.interactive_resolution = interactive_was

    # 6. A full-resolution frame in flight never blocks navigation. Make the
    # full frame slow (the whole region), orbit, wait until its refine
    # is being rendered in the background, then orbit on: the stale frame is
    # dropped within one band, and the draws made while it was in flight
    # take far less than a full frame.
    scene.voxlight.viewport_resolution = 1.0
    # a fine step makes the full frame slow enough (tens of seconds on
    # llvmpipe) that its refine is surely in flight when the view moves,
    # whatever the transfer function lets the library skip
    ob.voxlight.step = 0.15
    yield from settled()
    entry = rt.find_entry(ob.voxlight.filepath)
    full_s = entry.last_frame["seconds"]
    dropped = rt.cancelled_count
    waits = []
    in_flight_seen = 0
    for i in range(3):
        r3d.view_rotation = Quaternion((0, 0, 1), math.radians(10)) @ r3d.view_rotation
        redraw(("VIEW_3D",))
        for _ in range(200):  # until the full-resolution refine has started (after the half)
            yield 0.05
            if vp.busy_full():
                break
        in_flight_seen += vp.busy_full()
        mark = vp.draw_count
        r3d.view_rotation = Quaternion((0, 0, 1), math.radians(-7)) @ r3d.view_rotation
        redraw(("VIEW_3D",))
        yield 0.05
        new = vp.draw_count - mark
        log = list(vp.draw_log)[-new:] if new > 0 else []
        waits += [d for d, moving, inflight in log if moving and inflight]
        print("navigation %d: draws %s" % (i, ["%.3f moving=%s in-flight=%s" % x for x in log]),
              flush=True)
    yield from settled()
    last = entry.last_frame
    if last["kind"] == "refined":
        full_s = min(full_s, last["seconds"])
    check("stale_refine_dropped", in_flight_seen == 3 and rt.cancelled_count >= dropped + 3,
          "refines in flight when the view moved: %d of 3; dropped %d -> %d"
          % (in_flight_seen, dropped, rt.cancelled_count))
    check("navigation_not_blocked_by_refine", bool(waits) and max(waits) < 0.5 * full_s,
          "draws while a refine was in flight took %s s; a full frame takes %.3f s"
          % (["%.3f" % x for x in waits], full_s))
    ob.voxlight.step = 0.5
    check("refined_in_the_end", st.shown is not None and st.shown.full
          and st.shown.width == region.width,
          "shown %dx%d full=%s" % (st.shown.width, st.shown.height, st.shown.full))

    # 7. The importer from the UI runs modal: the load is on a worker thread,
    # the operator returns at once and the object appears when it is done.
    # Esc cancels: nothing is created, and the renderer the worker finishes
    # after the cancel is closed.
    yield from gui_import_steps(vx, win, area)

    # 8. A Blender Volume object with "Render with Voxlight" in the viewport.
    for o in list(bpy.data.objects):
        o.hide_set(True)
    scene.voxlight.viewport_resolution = 0.5
    yield from settled()
    blank = capture.img
    smoke = volume_object_with_ball(scene)
    smoke.voxlight_vdb.enabled = True
    yield from settled()
    diff = np.abs(capture.img[..., :3] - blank[..., :3]).max(axis=2)
    h, w = diff.shape
    check("volume_object_in_viewport", diff[h // 2 - 10:h // 2 + 10, w // 2 - 10:w // 2 + 10].mean() > 0.1
          and diff[:30, :30].mean() < 0.02, "centre %.3f corner %.3f"
          % (diff[h // 2 - 10:h // 2 + 10, w // 2 - 10:w // 2 + 10].mean(), diff[:30, :30].mean()))
    smoke.voxlight_vdb.enabled = False
    yield from settled()
    diff = np.abs(capture.img[..., :3] - blank[..., :3]).max(axis=2)
    check("volume_object_off_draws_nothing", diff.mean() < 0.01, "mean %.4f" % diff.mean())


def volume_object_with_ball(scene):
    """A Volume object (bounds display) holding a ball written by pyopenvdb."""
    from vdb_write import write_vdb
    i, j, k = np.meshgrid(*[np.arange(24.0)] * 3, indexing="ij")
    ball = (0.02 + np.clip(1.0 - np.sqrt((i - 11.5) ** 2 + (j - 11.5) ** 2 + (k - 11.5) ** 2) / 11.5, 0, None))
    aff = np.diag([0.05, 0.05, 0.05, 1.0])
    aff[:3, 3] = -0.575
    path = write_vdb(os.path.join(u.TMP, "gui_ball.vdb"),
                     [{"name": "density", "array": ball.astype(np.float32), "affine": aff}])
    vol = bpy.data.volumes.new("GuiSmoke")
    vol.filepath = path
    ob = bpy.data.objects.new("GuiSmoke", vol)
    scene.collection.objects.link(ob)
    return ob


def gui_import_steps(vx, win, area):
    native = vx.core.native
    made = []
    real_init, real_load = native.Renderer.__init__, native.Volume.load
    gate = {"open": True}

    def init(self, *a, **kw):
        real_init(self, *a, **kw)
        made.append(self)

    def gated_load(*a, **kw):
        while not gate["open"]:
            time.sleep(0.02)
        return real_load(*a, **kw)
    native.Renderer.__init__, native.Volume.load = init, gated_load
    try:
        before = set(bpy.data.objects)
        with bpy.context.temp_override(window=win, area=area):
            res = bpy.ops.voxlight.import_volume("EXEC_DEFAULT", filepath=u.CH2, use_modal=True,
                                               frame_in_view=False)
        check("import_runs_modal", res == {"RUNNING_MODAL"} and set(bpy.data.objects) == before, str(res))
        for _ in range(120):
            yield 0.25
            if set(bpy.data.objects) != before:
                break
        new = set(bpy.data.objects) - before
        check("modal_import_creates_the_object", len(new) == 1
              and tuple(new.pop().voxlight.dims) == (301, 370, 316))

        gate["open"] = False  # the next load blocks until released
        before = set(bpy.data.objects)
        n_made = len(made)
        with bpy.context.temp_override(window=win, area=area):
            bpy.ops.voxlight.import_volume("EXEC_DEFAULT", filepath=u.ball_file("esc.nii.gz"), use_modal=True,
                                               frame_in_view=False)
        yield 0.3
        win.event_simulate(type="ESC", value="PRESS")
        win.event_simulate(type="ESC", value="RELEASE")
        yield 0.5
        gate["open"] = True  # the worker now finishes, after the cancel
        yield 2.0
        # Without the cancel the object would exist by now (the load was
        # released 2 s ago); the worker stops at its next step, so it makes
        # no renderer, or closes the one it made.
        check("esc_cancels_the_import", set(bpy.data.objects) == before
              and vx.core.runtime.find_entry(os.path.join(u.TMP, "esc.nii.gz")) is None
              and all(r._handle is None for r in made[n_made:]),
              "renderers made %d, closed %s" % (len(made) - n_made, [r._handle is None for r in made[n_made:]]))
    finally:
        gate["open"] = True
        native.Renderer.__init__, native.Volume.load = real_init, real_load


RUN.start(steps())
