"""Overlays in Blender: a second volume object (a small bright ball
in its own grid and affine, coloured red by its own ColorRamp) parented to
a base volume is drawn inside the base's ray march. F12 shows red where the
ball lies and not when the overlay is hidden; the pair renders in one
library frame (the overlay is not drawn twice); a linked overlay draws as a
child does; blend add and max differ; opacity takes keyframes; the panel
lists the overlays; a missing overlay file is reported, not a crash.

blender -b --factory-startup --python-exit-code 1 --python tests/blender/test_overlays.py
"""

import os
import sys
import types

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import _util as u  # noqa: E402
from _util import test  # noqa: E402

vx = u.install_addon()
SIZE = 96
N = 16          # the overlay's voxels per axis (1 mm)
CENTRE_MM = (28.0, 0.0, 0.0)  # its ball's centre, scanner mm: beside the base ball (radius ~26 mm)


def _mod(name):
    return sys.modules[u.MODULE + "." + name]


def _ball_file(centre=CENTRE_MM, name="hot_ball.nii.gz"):
    """A bright ball of radius 6 mm centred at `centre` (scanner mm) on a
    1 mm grid (the base is 32^3 voxels of 2 mm: another grid and affine)."""
    g = np.arange(N, dtype=np.float64) - (N - 1) / 2.0
    i, j, k = np.meshgrid(g, g, g, indexing="ij")
    data = np.where(i * i + j * j + k * k <= 36.0, 1000.0, 0.0).astype(np.float32)
    aff = np.eye(4)
    aff[:3, 3] = [c - (N - 1) / 2.0 for c in centre]
    return u.write_nifti(os.path.join(u.TMP, name), data, aff)


def _scene(centre=CENTRE_MM):
    """The base ball at the origin with the red overlay ball (centred at
    `centre`, scanner mm) as its child; camera on -Y. Returns (scene, base,
    overlay)."""
    scene = u.black_cycles_scene(SIZE)
    u.add_camera((0.0, -1.6, 0.0))
    # Scanner coordinates, not centred at the cursor: each file's affine places it.
    base = u.import_volume(u.ball_file(), center=False)
    base.voxlight.jitter = False
    ov = u.import_volume(_ball_file(centre, "hot_ball_%d_%d_%d.nii.gz" % tuple(centre)), center=False)
    p = ov.voxlight
    p.jitter = False
    vx.tf.set_ramp(p.tf_texture.color_ramp, [(0.0, (1, 0, 0, 0)), (0.5, (1, 0, 0, 1)), (1.0, (1, 0, 0, 1))])
    p.window_low, p.window_high = 0.0, 1000.0
    ov.voxlight_overlays.shading = False  # flat red
    world = ov.matrix_world.copy()
    ov.parent = base
    ov.matrix_world = world
    bpy.context.view_layer.update()
    return scene, base, ov


def _ball_pixel(scene, ov):
    """(row, column) of the overlay ball's centre in the image, row 0 = bottom."""
    dg = bpy.context.evaluated_depsgraph_get()
    view, proj = vx.offline.camera_matrices(scene.camera, dg, SIZE, SIZE, scene)
    model = vx.params.model_matrix(ov.evaluated_get(dg))
    clip = proj @ view @ model @ np.array([(N - 1) / 2.0] * 3 + [1.0])
    x, y = clip[:2] / clip[3]
    return int((y + 1) / 2 * SIZE), int((x + 1) / 2 * SIZE)


def _f12(scene, name):
    scene.render.filepath = os.path.join(u.TMP, name + ".png")
    bpy.ops.render.render(write_still=True)
    return u.load_png(scene.render.filepath)[..., :3]


def _offline(scene, only=None):
    rgba, _depth = vx.offline.render(scene, bpy.context.evaluated_depsgraph_get(), scene.camera, SIZE, SIZE,
                                     only=only)
    return rgba


def _red(img):
    return (img[..., 0] > 0.3) & (img[..., 0] > 3 * img[..., 1]) & (img[..., 0] > 3 * img[..., 2])


@test
def f12_shows_the_overlay_where_its_affine_puts_it_and_not_without_it():
    scene, base, ov = _scene()
    r, c = _ball_pixel(scene, ov)
    runtime = _mod("core.runtime")
    n = runtime.render_count
    fused = _f12(scene, "overlay_fused")
    assert runtime.render_count - n == 1, "base and overlay must be one library frame"
    red = _red(fused)
    assert red[r - 1:r + 2, c - 1:c + 2].all(), fused[r - 1:r + 2, c - 1:c + 2]
    ys, xs = np.nonzero(red)
    assert abs(ys.mean() - r) < 2 and abs(xs.mean() - c) < 2, (ys.mean(), xs.mean(), r, c)
    # the base still shows, away from the ball
    assert (fused.max(axis=2) > 0.1).sum() > red.sum() + 200
    ov.hide_render = True
    alone = _f12(scene, "overlay_hidden")
    assert not _red(alone).any()
    rim = red.copy()  # the ball and 2 pixels around it (its soft edge)
    for _ in range(2):
        rim[1:] |= rim[:-1].copy()
        rim[:-1] |= rim[1:].copy()
        rim[:, 1:] |= rim[:, :-1].copy()
        rim[:, :-1] |= rim[:, 1:].copy()
    assert np.abs(alone - fused)[~rim].max() < 0.05  # elsewhere the same frame
    ov.hide_render = False


@test
def a_linked_overlay_draws_as_a_child_does_and_fuse_off_draws_it_alone():
    scene, base, ov = _scene()
    child = _offline(scene)
    world = ov.matrix_world.copy()
    ov.parent = None
    ov.matrix_world = world
    bpy.context.view_layer.update()
    for o in bpy.context.view_layer.objects:
        o.select_set(o is ov or o is base)
    bpy.context.view_layer.objects.active = base
    assert bpy.ops.voxlight.add_overlay() == {"FINISHED"}
    assert [l.object for l in base.voxlight_overlays.links] == [ov]
    linked = _offline(scene)
    assert np.abs(linked - child).max() < 1e-3
    # Fuse off: drawn on its own as without overlays, still red
    ov.voxlight_overlays.fuse = False
    runtime = _mod("core.runtime")
    n = runtime.render_count
    apart = _offline(scene)
    assert runtime.render_count - n == 2
    assert _red(apart[..., :3] / np.maximum(apart[..., 3:], 1e-6)).any()
    ov.voxlight_overlays.fuse = True
    bpy.context.view_layer.objects.active = base
    base.voxlight_overlays.active_index = 0
    assert bpy.ops.voxlight.remove_overlay() == {"FINISHED"}
    assert len(base.voxlight_overlays.links) == 0
    bpy.ops.ed.undo_push(message="removed")


@test
def blend_add_and_max_differ_and_opacity_takes_keyframes():
    scene, base, ov = _scene(centre=(0.0, 0.0, 0.0))  # inside the base: the blends meet its medium
    s = ov.voxlight_overlays
    imgs = {}
    for blend in ("over", "add", "max"):
        s.blend = blend
        imgs[blend] = _offline(scene)
    assert np.abs(imgs["add"] - imgs["max"]).max() > 0.05
    assert np.abs(imgs["over"] - imgs["add"]).max() > 0.05
    s.blend = "over"
    s.opacity = 1.0
    s.keyframe_insert("opacity", frame=1)
    s.opacity = 0.0
    s.keyframe_insert("opacity", frame=10)
    scene.frame_set(10)
    gone = _offline(scene)
    ov.hide_render = True
    alone = _offline(scene)
    ov.hide_render = False
    assert np.abs(gone - alone).max() < 1e-3  # opacity 0: the base alone
    scene.frame_set(1)
    assert abs(s.opacity - 1.0) < 1e-6
    assert np.abs(_offline(scene) - imgs["over"]).max() < 1e-3
    ov.animation_data_clear()


@test
def the_overlays_change_the_viewport_digest_and_are_not_drawn_twice():
    scene, base, ov = _scene()
    frames = _mod("overlay_frames")
    objs = [o for o in bpy.context.view_layer.objects if o.voxlight.is_volume]
    plan = frames.fuse(objs)
    assert [(b.name, [o.name for o in ovs]) for b, ovs in plan] == [(base.name, [ov.name])]
    runtime, native, params = _mod("core.runtime"), _mod("core.native"), _mod("params")
    entry = runtime.entry_for(base.voxlight.filepath, base.voxlight, 1)
    prepared = frames.prepare(entry, base, [ov], 1)
    assert len(prepared.overlays) == 1 and prepared.overlays[0]["slot"] == 0
    key = entry.overlay_key
    assert key is not None and frames.prepare(entry, base, [ov], 1) and entry.overlay_key == key
    view, proj = np.eye(4), np.eye(4)
    proj[2, 3] = -1.0

    def digest():
        p = frames.prepare(entry, base, [ov], 1)
        return native.params_digest(params.build(base, 32, 32, view, proj, overlays=p.overlays),
                                    entry.identity)
    a = digest()
    ov.voxlight_overlays.blend = "max"
    b = digest()
    ov.location.x += 0.01
    bpy.context.view_layer.update()
    c = digest()
    assert len({a, b, c}) == 3
    # a base in MIP draws no overlays, and says why
    base.voxlight.render_mode = "mip"
    assert frames.prepare(entry, base, [ov], 1).overlays == []
    assert "DVR" in frames.problems[base.name][0]
    base.voxlight.render_mode = "dvr"


@test
def the_panel_lists_the_overlays_and_a_missing_file_is_reported():
    scene, base, ov = _scene()
    layout = u.Layout()
    ctx = types.SimpleNamespace(object=base, scene=scene)
    bpy.types.VOXLIGHT_PT_volume_overlays.draw(types.SimpleNamespace(layout=layout), ctx)
    for want in ("use_children", "VOXLIGHT_UL_overlay_links", "voxlight.add_overlay",
                 "voxlight.remove_overlay", ov.name, "blend", "opacity", "shading", "interpolation"):
        assert want in layout.drawn, (want, layout.drawn)
    layout = u.Layout()
    bpy.types.VOXLIGHT_PT_volume_overlays.draw(types.SimpleNamespace(layout=layout),
                                               types.SimpleNamespace(object=ov, scene=scene))
    assert "Drawn inside %s" % base.name in layout.drawn, layout.drawn
    # the overlay's file vanishes: the base renders alone and the panel says why
    ov.voxlight.filepath = os.path.join(u.TMP, "vanished.nii.gz")
    img = _offline(scene)
    assert img[..., 3].max() > 0.1 and not _red(img[..., :3]).any()
    assert any("vanished" in p for p in _mod("overlay_frames").problems[base.name])


u.run("test_overlays")
