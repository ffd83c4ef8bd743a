"""GUI Blender under Xvfb: a preview frame (the reduced-resolution image
drawn right after a change) is composited without blocks and with a clean
mesh silhouette. ch2better with a cube in front of part of it; the view is
still (full frame captured), nudged and put back, and the preview of the
same view drawn while it counts as moving is compared with the full frame:

  * no blocks: the preview's pixel-to-pixel steps are no larger at the
    frame's texel boundaries than between them, and it is closer to the
    full frame than the nearest-texel compositing the add-on used before
    (viewport.PREVIEW_FILTER = "nearest", drawn from the same frame);
  * the silhouette: in a band along the cube's outline the preview matches
    the full frame (no dark, jagged smear), and no volume colour lands on
    the cube.

Screenshots (PNG) go to VOXLIGHT_SCREENSHOT_DIR (default the test's
temporary folder): preview_nearest.png, preview_bilateral.png,
preview_full.png, and outline_full.png with overlays on (the box outline).

xvfb-run -a -s "-screen 0 1280x1024x24" blender --factory-startup \
    --enable-event-simulate --python-exit-code 1 --python tests/blender/test_gui_preview.py
"""

import math
import os
import sys

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import _gui  # noqa: E402
import _util as u  # noqa: E402

RUN = _gui.Run("test_gui_preview", limit_s=500)
check = RUN.check
capture = _gui.Capture()
VOLUME = "/usr/share/mricron/templates/ch2better.nii.gz"
OUT = os.environ.get("VOXLIGHT_SCREENSHOT_DIR", u.TMP)


def _save(img, name):
    os.makedirs(OUT, exist_ok=True)
    h, w = img.shape[:2]
    im = bpy.data.images.new("shot_" + name, w, h, alpha=True)
    px = np.clip(img, 0.0, 1.0).copy()
    px[..., 3] = 1.0
    im.pixels.foreach_set(px.ravel())
    im.filepath_raw = os.path.join(OUT, name)
    im.file_format = "PNG"
    im.save()
    bpy.data.images.remove(im)


def _cube_mask(ob, r3d, w, h):
    """Screen pixels (row 0 = bottom) inside the projection of the cube: the
    convex hull of its 8 corners, as half-plane tests."""
    m = np.array(r3d.window_matrix) @ np.array(r3d.view_matrix) @ np.array(ob.matrix_world)
    pts = []
    for c in ob.bound_box:
        p = m @ np.array(list(c) + [1.0])
        pts.append(((p[0] / p[3] + 1) * 0.5 * w, (p[1] / p[3] + 1) * 0.5 * h))
    pts = np.array(pts)
    # convex hull (monotone chain)
    P = sorted(map(tuple, pts))
    def cross(o, a, b):
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    lower, upper = [], []
    for p in P:
        while len(lower) >= 2 and cross(lower[-2], lower[-1], p) <= 0:
            lower.pop()
        lower.append(p)
    for p in reversed(P):
        while len(upper) >= 2 and cross(upper[-2], upper[-1], p) <= 0:
            upper.pop()
        upper.append(p)
    hull = lower[:-1] + upper[:-1]
    yy, xx = np.mgrid[0:h, 0:w] + 0.5
    inside = np.ones((h, w), bool)
    for a, b in zip(hull, hull[1:] + hull[:1]):
        inside &= (b[0] - a[0]) * (yy - a[1]) - (b[1] - a[1]) * (xx - a[0]) >= 0
    return inside


def _dilate(mask, n):
    out = mask.copy()
    for _ in range(n):
        o = out.copy()
        o[1:] |= out[:-1]
        o[:-1] |= out[1:]
        o[:, 1:] |= out[:, :-1]
        o[:, :-1] |= out[:, 1:]
        out = o
    return out


def steps():
    vx = u.install_addon()
    win, area, space = _gui.view3d()
    space.overlay.show_overlays = False
    r3d = _gui.front_view(space)
    capture.install()
    scene = u.reset_scene()
    s = scene.voxlight
    s.viewport_resolution, s.settle_time = 1.0, 0.3
    with bpy.context.temp_override(window=win, area=area):
        vol = u.import_volume(VOLUME)
    vol.voxlight.jitter = False
    r3d = _gui.front_view(space)
    # a cube in front of the volume's right half (the volume has the default
    # cube's size, 2): its silhouette crosses the brain
    bpy.ops.mesh.primitive_cube_add(size=0.8, location=(0.5, -1.6, 0.1))
    cube = bpy.context.active_object
    cube.rotation_euler = (0.0, 0.0, math.radians(30))

    yield from capture.settled(vx, area, tries=120)
    full = capture.img
    # the preview of the same view: nudge the view and put it back, the
    # view then counts as moving for Refine After (long), so the preview stays
    s.settle_time = 5.0
    s.interactive_resolution = 0.2
    loc = r3d.view_location.copy()
    r3d.view_location = (loc.x + 0.01, loc.y, loc.z)
    area.tag_redraw()
    yield 0.3
    r3d.view_location = loc
    vx.viewport.PREVIEW_FILTER = "bilateral"
    capture.request()
    area.tag_redraw()
    yield 0.3
    new = capture.img
    kind = vx.viewport.shown_log[-1] if vx.viewport.shown_log else None
    vx.viewport.PREVIEW_FILTER = "nearest"
    capture.request()
    area.tag_redraw()
    yield 0.3
    old = capture.img
    vx.viewport.PREVIEW_FILTER = "bilateral"
    kind2 = vx.viewport.shown_log[-1] if vx.viewport.shown_log else None
    check("preview_shown", kind is not None and kind[1] == "preview" and kind == kind2
          and new is not None and old is not None, "%s %s" % (kind, kind2))
    if new is None or old is None or kind is None:
        return
    _save(full, "preview_full.png")
    _save(new, "preview_bilateral.png")
    _save(old, "preview_nearest.png")

    h, w = full.shape[:2]
    scale, fw = kind[2], kind[3]
    texel = w / float(fw)
    cube_px = _cube_mask(cube, r3d, w, h)
    bg = np.median(full[:8, :8, :3].reshape(-1, 3), axis=0)
    volume_px = np.abs(full[..., :3] - bg).sum(axis=2) > 0.05
    interior = volume_px & ~_dilate(cube_px, int(3 * texel)) & ~_dilate(~volume_px, int(2 * texel))

    def rmse(img, m):
        return float(np.sqrt(np.mean((img[m][:, :3] - full[m][:, :3]) ** 2)))

    e_new, e_old = rmse(new, interior), rmse(old, interior)
    check("preview_closer_to_full_than_blocks", e_new < e_old,
          "RMSE inside the volume: bilateral %.4f, nearest %.4f (scale %.3f, texel %.1f px)"
          % (e_new, e_old, scale, texel))

    # blocks: the steps between neighbouring columns at the frame's texel
    # boundaries against those between them
    bounds = np.zeros(w - 1, bool)
    for k in range(1, fw):
        x = int(math.floor(k * texel - 0.5))
        if 0 <= x < w - 1:
            bounds[x] = True

    def block_ratio(img):
        d = np.abs(np.diff(img[..., :3].sum(axis=2), axis=1))
        m = interior[:, 1:] & interior[:, :-1]
        at = d[m & bounds[None, :]].mean()
        off = d[m & ~bounds[None, :]].mean()
        return at / max(off, 1e-6)

    r_new, r_old = block_ratio(new), block_ratio(old)
    check("preview_has_no_blocks", r_new < 2.0 and r_old > 2.0 * r_new,
          "step at texel boundaries / between them: bilateral %.2f, nearest %.2f" % (r_new, r_old))

    # the silhouette: a band outside the cube where the volume shows
    edge = _dilate(cube_px, int(2 * texel)) & ~_dilate(cube_px, 1) & volume_px
    b_new, b_old = rmse(new, edge), rmse(old, edge)
    check("silhouette_band_clean", edge.sum() > 50 and b_new < 0.05 and b_new < b_old,
          "RMSE against the full frame in the %d-pixel band: bilateral %.4f, nearest %.4f"
          % (edge.sum(), b_new, b_old))
    inner = cube_px & ~_dilate(~cube_px, 2)
    on_cube = float(np.abs(new[inner][:, :3] - full[inner][:, :3]).max())
    check("no_volume_on_the_cube", on_cube < 0.02, "largest difference on the cube %.4f" % on_cube)

    # the box outline, overlays on, full frame
    space.overlay.show_overlays = True
    s.settle_time = 0.3
    yield from capture.settled(vx, area, tries=120)
    _save(capture.img, "outline_full.png")
    vol.hide_set(True)
    yield from capture.settled(vx, area, tries=40)
    _save(capture.img, "outline_hidden.png")
    vol.hide_set(False)


RUN.start(steps())
