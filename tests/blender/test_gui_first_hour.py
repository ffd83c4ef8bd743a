"""GUI Blender under Xvfb: a new user's first minutes, from the factory
startup scene.

xvfb-run -a -s "-screen 0 1280x1024x24" blender --factory-startup \
    --python-exit-code 1 --python tests/blender/test_gui_first_hour.py

  * import ch2better into the factory scene (Cube, Camera, Light): the
    factory Cube, which would hide the volume, is hidden from the viewport
    and renders, and the viewport shows the volume (pixels differ from the
    Cube's grey over a good part of the view); undo brings the Cube back;
  * the box outline's front edges are whole over the volume, in the still
    frame and in a preview while the view turns;
  * the Object Data tab (the Empty's own) shows the Voxlight panel below the
    Empty's two-line panel, one click and no scrolling;
  * every render mode, switched to once on the fresh import, draws
    something (pixels differ from the empty viewport), MinIP included (its
    floor, fitted at the first switch, skips the air), and MIP is not
    saturated (under a quarter of the volume's pixels at full white).
Screenshots (first_hour_*.png) go to VOXLIGHT_SCREENSHOT_DIR (default the
test's temporary folder).
"""

import os
import sys

import bpy
import numpy as np
from mathutils import Euler

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import _gui  # noqa: E402
import _util as u  # noqa: E402

RUN = _gui.Run("test_gui_first_hour", limit_s=400)
check = RUN.check
OUT = os.environ.get("VOXLIGHT_SCREENSHOT_DIR", u.TMP)


def area_of(win, kind):
    return next(a for a in win.screen.areas if a.type == kind)


def changed_share(a, b, tol=0.06):
    """Share of pixels whose colour differs by more than tol."""
    return float((np.abs(a[..., :3] - b[..., :3]).max(-1) > tol).mean())


def front_edges_whole(vx, area, ob, img):
    """(whether, detail): every pixel along the middle 80% of each front
    edge of ob's box outline (core/box_edges.py) shows the outline's theme
    colour, in the capture img of the area's 3D view."""
    if img is None:
        return False, "no capture"
    region = next(r for r in area.regions if r.type == "WINDOW")
    rv3d = area.spaces.active.region_3d
    be = vx.core.box_edges
    corners = vx.box_outline.corners(ob)
    want = np.array(vx.box_outline.colour(ob, bpy.context)[:3])
    pm = np.array(rv3d.perspective_matrix, np.float64)
    h, w = img.shape[:2]
    misses = total = 0
    for i, j in be.front_edges(corners, np.array(rv3d.view_matrix), rv3d.is_perspective):
        for t in np.linspace(0.1, 0.9, 40):
            p = pm @ np.r_[corners[i] * (1 - t) + corners[j] * t, 1.0]
            x = int((p[0] / p[3] + 1.0) * 0.5 * region.width)
            y = int((p[1] / p[3] + 1.0) * 0.5 * region.height)
            if not (1 <= x < w - 1 and 1 <= y < h - 1):
                continue
            near = img[y - 1:y + 2, x - 1:x + 2, :3].reshape(-1, 3)
            total += 1
            misses += np.abs(near - want).max(axis=1).min() > 0.12
    return total > 100 and misses <= 0.02 * total, "%d of %d edge samples not the outline's colour" % (
        misses, total)


def steps():
    os.makedirs(OUT, exist_ok=True)
    vx = u.install_addon()
    win = bpy.context.window_manager.windows[0]
    v3d = area_of(win, "VIEW_3D")
    props = area_of(win, "PROPERTIES")
    scene = bpy.context.scene
    cube = bpy.data.objects.get("Cube")
    check("factory_scene_has_the_cube", cube is not None)
    cap = _gui.Capture()
    cap.install()

    def view_png(img, name):
        """The viewport's pixels as read (the startup splash, drawn over
        the window, is not in them), downscaled 2x to keep the file small."""
        path = os.path.join(OUT, name)
        small = np.ascontiguousarray(img[::2, ::2])
        h, w = small.shape[:2]
        im = bpy.data.images.new("shot", w, h, alpha=False)
        small = small.copy()
        small[..., 3] = 1.0
        im.pixels.foreach_set(small.ravel())
        im.filepath_raw = path
        im.file_format = "PNG"
        im.save()
        bpy.data.images.remove(im)
        return os.path.isfile(path)

    def shot(area, name):
        path = os.path.join(OUT, name)
        with bpy.context.temp_override(window=win, area=area):
            bpy.ops.screen.screenshot_area(filepath=path)
        return os.path.isfile(path)

    # What the user saw before: the grey Cube where the volume will land.
    yield 0.5
    cap.request()
    v3d.tag_redraw()
    yield 0.5
    before = cap.img

    with bpy.context.temp_override(window=win, area=v3d):
        res = bpy.ops.voxlight.import_volume(filepath=u.CH2)
    check("import_finished", res == {"FINISHED"}, res)
    ob = bpy.context.view_layer.objects.active
    check("cube_hidden_in_viewport_and_render", cube.hide_get() and cube.hide_render,
          "hidden %s, render %s" % (cube.hide_get(), cube.hide_render))
    yield from cap.settled(vx, v3d)
    after = cap.img
    share = changed_share(after, before) if before is not None and after is not None else 0.0
    check("volume_visible_after_import", share > 0.05,
          "%.1f%% of the view changed from the Cube's" % (100 * share))
    check("screenshot_import", view_png(after, "first_hour_import.png"))
    # The box outline's front edges are whole over the volume, not broken
    # where tissue lies behind them: in the still frame and in a preview
    # while the view turns.
    whole, detail = front_edges_whole(vx, v3d, ob, after)
    check("box_outline_front_edges_whole_still", whole, detail)
    v3d.spaces.active.region_3d.view_rotation.rotate(Euler((0.0, 0.0, 0.02)))
    cap.request()
    v3d.tag_redraw()
    yield 0.05
    whole, detail = front_edges_whole(vx, v3d, ob, cap.img)
    check("box_outline_front_edges_whole_preview", whole, detail)
    yield from cap.settled(vx, v3d)

    # The Object Data tab (the Empty's own): one click, Voxlight in view
    # below the Empty's two-line panel, nothing to scroll past.
    props.spaces.active.context = "DATA"
    props.tag_redraw()
    yield 0.8
    check("voxlight_in_the_object_data_tab",
          props.spaces.active.context == "DATA" and bpy.types.VOXLIGHT_PT_volume.bl_context == "data",
          "tab %s, panel context %s" % (props.spaces.active.context, bpy.types.VOXLIGHT_PT_volume.bl_context))
    check("screenshot_panels", shot(props, "first_hour_object_tab.png"))

    # Each mode, switched to once: non-empty. The empty view to compare with
    # is the same view without the volume.
    scene.voxlight.viewport_enabled = False
    cap.request()
    v3d.tag_redraw()
    yield 0.8
    empty = cap.img
    scene.voxlight.viewport_enabled = True
    for mode in ("mip", "minip", "average", "iso", "dvr"):
        ob.voxlight.render_mode = mode
        yield from cap.settled(vx, v3d)
        img = cap.img
        share = changed_share(img, empty) if img is not None and empty is not None else 0.0
        name = "mode_%s_nonempty" % mode
        detail = "%s: %.1f%% of the view shows the volume (window %.4g..%.4g, iso %.4g)" % (
            mode, 100 * share, ob.voxlight.window_low, ob.voxlight.window_high,
            ob.voxlight.iso_value)
        check(name, share > 0.03, detail)
        if mode == "mip" and img is not None and empty is not None:
            # A window ending below the data's maximum turned MIP into a
            # white silhouette: most of the volume's pixels at full white.
            vol = np.abs(img[..., :3] - empty[..., :3]).max(-1) > 0.06
            white = (img[..., :3].min(-1) > 0.98) & vol
            sat = float(white.sum()) / max(int(vol.sum()), 1)
            check("mip_not_saturated", sat < 0.25,
                  "%.1f%% of the volume's pixels at full white" % (100 * sat))
        if img is not None:
            view_png(img, "first_hour_mode_%s.png" % mode)
    check("dvr_window_restored", abs(ob.voxlight.window_low - 50.09) < 0.5,
          "Volume's window %.4g..%.4g" % (ob.voxlight.window_low, ob.voxlight.window_high))

    # Undo of the import brings the Cube back (the hide is part of its step).
    with bpy.context.temp_override(window=win, area=v3d):
        bpy.ops.ed.undo_push(message="after modes")
    cube_name = cube.name
    for _ in range(12):
        with bpy.context.temp_override(window=win, area=v3d):
            if bpy.ops.ed.undo() != {"FINISHED"}:
                break
        yield 0.2
        c = bpy.data.objects.get(cube_name)
        if c is not None and not c.hide_get() and not any(
                o.voxlight.is_volume for o in bpy.data.objects):
            break
    c = bpy.data.objects.get(cube_name)
    check("undo_shows_the_cube_again", c is not None and not c.hide_get() and not c.hide_render)


RUN.start(steps())
