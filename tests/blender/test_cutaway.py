"""In Blender: clip-plane Empties cut the volume in F12 and the cut
follows the Empty; the viewport's frame key changes when the Empty moves;
slice planes show the library's resample and follow the plane (in its
image and in F12); the render mode and MatCap change F12; the new
properties take keyframes; missing or wrong objects are reported, not a
crash.

blender -b --factory-startup --python-exit-code 1 --python tests/blender/test_cutaway.py
"""

import os
import sys

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import _util as u  # noqa: E402
from _util import test  # noqa: E402

vx = u.install_addon()
SIZE = 96


def _mod(name):
    return sys.modules[u.MODULE + "." + name]


def _scene():
    """The ball volume at the origin (radius ~0.26), camera on -Y looking at
    it (image up = world +Z), black world, Standard view."""
    scene = u.black_cycles_scene(SIZE)
    ob = u.import_volume(u.ball_file())
    ob.voxlight.jitter = False
    u.add_camera((0.0, -3.0, 0.0))
    bpy.context.view_layer.objects.active = ob
    ob.select_set(True)
    return scene, ob


def _f12(scene, name):
    scene.render.filepath = os.path.join(u.TMP, name + ".png")
    bpy.ops.render.render(write_still=True)
    return u.load_png(scene.render.filepath)


def _rows_with_volume(img, thr=0.08):
    """Image rows (row 0 = bottom) where the volume shows."""
    return np.nonzero(img[..., :3].max(axis=2).max(axis=1) > thr)[0]


def _clip_empty(ob):
    assert bpy.ops.voxlight.add_clip_plane() == {"FINISHED"}
    e = ob.voxlight.clip_planes[-1].object
    assert e is not None and e.type == "EMPTY"
    e.rotation_euler = (0.0, 0.0, 0.0)  # keep world +Z (image up)
    e.location = (0.0, 0.0, 0.0)
    return e


@test
def moving_the_clip_empty_moves_the_cut_in_f12():
    scene, ob = _scene()
    whole = _rows_with_volume(_f12(scene, "uncut"))
    assert len(whole) > 10 and whole.min() < SIZE // 2 - 5 < SIZE // 2 + 5 < whole.max(), whole
    e = _clip_empty(ob)
    cut = _rows_with_volume(_f12(scene, "cut_centre"))
    # The +Z half is kept: nothing below the centre row, the top as before.
    assert cut.min() >= SIZE // 2 - 2, (cut.min(), whole.min())
    assert abs(cut.max() - whole.max()) <= 1, (cut.max(), whole.max())
    # 0.1 up: ~44 pixels per unit at this distance (50 mm lens, 36 mm sensor, 3 units away)
    e.location.z = 0.1
    up = _rows_with_volume(_f12(scene, "cut_up"))
    shift = up.min() - cut.min()
    assert 2.5 <= shift <= 6.5, (cut.min(), up.min())
    # Turned over, the other half is kept.
    e.location.z = 0.0
    e.rotation_euler.x = np.pi
    down = _rows_with_volume(_f12(scene, "cut_down"))
    assert down.max() <= SIZE // 2 + 2 and abs(down.min() - whole.min()) <= 1, (down.min(), down.max())
    # A slab: only [0, 0.1] above the plane (turned back) is kept.
    e.rotation_euler.x = 0.0
    ob.voxlight.clip_planes[0].thickness = 0.1
    slab = _rows_with_volume(_f12(scene, "slab"))
    assert slab.min() >= SIZE // 2 - 2 and slab.max() <= SIZE // 2 + 7, (slab.min(), slab.max())


@test
def the_viewport_frame_key_follows_the_clip_empty():
    """The viewport re-renders when its frame key (params digest) changes:
    moving the Empty must change it, an unrelated object must not."""
    scene, ob = _scene()
    params, native = _mod("params"), _mod("core.native")
    e = _clip_empty(ob)
    view = np.array(scene.camera.matrix_world.inverted(), np.float64)
    proj = np.diag([2.0, 2.0, -1.0, 1.0])
    proj[2, 3], proj[3, 2], proj[3, 3] = -0.2, -1.0, 0.0

    def key():
        bpy.context.view_layer.update()
        dg = bpy.context.evaluated_depsgraph_get()
        return native.params_digest(params.build(ob.evaluated_get(dg), 32, 32, view, proj))

    k0 = key()
    assert key() == k0
    other = bpy.data.objects.new("Bystander", None)
    scene.collection.objects.link(other)
    other.location.x = 5.0
    assert key() == k0
    e.location.z = 0.05
    k1 = key()
    assert k1 != k0
    e.rotation_euler.y = 0.3
    assert key() != k1


@test
def slice_plane_shows_the_library_resample_and_follows_the_plane():
    scene, ob = _scene()
    sp, slice_plane, native = _mod("slice_planes"), _mod("core.slice_plane"), _mod("core.native")
    assert bpy.ops.voxlight.add_slice_plane() == {"FINISHED"}
    plane = next(o for o in scene.objects if o.type == "MESH" and o.voxlight_slice.volume == ob)
    plane.voxlight_slice.interpolation = "nearest"

    def check(tag):
        bpy.context.view_layer.update()
        sp.update_all(scene)
        assert sp.error(plane) == "", sp.error(plane)
        img = bpy.data.images[sp.IMAGE_PREFIX + plane.name]
        w, h = img.size
        px = np.empty(w * h * 4, np.float32)
        img.pixels.foreach_get(px)
        px = px.reshape(h, w, 4)
        # Independently of the add-on: the plane's square from its own
        # vertices and matrix, the volume's model from its properties.
        co = np.array([v.co[:] for v in plane.data.vertices])
        mw = np.array(plane.matrix_world, np.float64)
        sq = slice_plane.plane_to_world(mw, co.min(0), co.max(0))
        model = np.array(ob.matrix_world, np.float64) @ \
            np.array(ob.voxlight.voxel_to_local, np.float64).reshape(4, 4).T
        entry = _mod("core.runtime").find_entry(bpy.path.abspath(ob.voxlight.filepath))
        look = _mod("params").look_kwargs(ob.voxlight)
        p = native.make_params(width=w, height=h, model=model, preset=look["preset"],
                               window=look["window"], tf_rgba=look["tf_rgba"], color_space=look["color_space"])
        # the slice is scene-linear, as the image holds it
        want = entry.renderer.render_slice(p, sq, "nearest")
        # equal to float rounding: the add-on takes the plane and model from
        # the evaluated objects, this check from the originals, whose float
        # matrices may differ in the last bit (seen once: 6e-8 after a move)
        assert np.abs(px - want).max() <= 1e-6, (tag, np.abs(px - want).max())
        inside = slice_plane.inside_volume(slice_plane.pixel_positions(sq, w, h), model,
                                           tuple(ob.voxlight.dims))
        assert (px[..., 3][inside] == 1).mean() > 0.99, tag
        assert inside.all() or (px[..., 3][~inside] == 0).mean() > 0.99, tag
        assert px[..., :3][inside].max() > 0.2, tag  # the ball's bright core
        return px, inside

    a, in_a = check("centre")
    assert in_a.all()  # made to cover the volume's section exactly
    plane.location.x += 0.3   # half out of the volume: the image follows
    plane.rotation_euler.y = 0.4
    b, in_b = check("moved")
    assert 0.2 < in_b.mean() < 0.95 and not np.array_equal(a, b)
    # The material shows it: the plane's first material uses the image.
    mat = plane.data.materials[0]
    assert any(n.type == "TEX_IMAGE" and n.image is not None and n.image.name.startswith(
        sp.IMAGE_PREFIX) for n in mat.node_tree.nodes)


@test
def slice_plane_shows_in_f12_and_follows_animation():
    scene, ob = _scene()
    sp = _mod("slice_planes")
    assert bpy.ops.voxlight.add_slice_plane() == {"FINISHED"}
    plane = next(o for o in scene.objects if o.type == "MESH" and o.voxlight_slice.volume == ob)
    plane.rotation_euler.x = np.pi / 2   # facing the camera (on -Y)
    ob.hide_render = True                # only the slice in the picture
    # No volume to composite: compositor nodes an earlier test left (the
    # muted Alpha Over) are not this test's subject.
    _mod("compositor").remove_nodes(scene)
    # Animated: the plane slides out of the volume by frame 10.
    plane.location = (0.0, 0.0, 0.0)
    plane.keyframe_insert("location", frame=1)
    plane.location = (0.0, 0.0, 2.0)
    plane.keyframe_insert("location", frame=10)
    scene.frame_set(1)
    tex = bpy.data.images[sp.IMAGE_PREFIX + plane.name]
    w, h = tex.size
    px = np.empty(w * h * 4, np.float32)
    tex.pixels.foreach_get(px)  # the slice at frame 1
    # An animation render: each frame's slice comes from the render's own
    # depsgraph at that frame (frame_change_post), not from the frame shown.
    scene.frame_start, scene.frame_end, scene.frame_step = 1, 10, 9
    scene.render.filepath = os.path.join(u.TMP, "slice_anim_####")
    scene.render.image_settings.file_format = "PNG"
    bpy.ops.render.render(animation=True)
    img = u.load_png(os.path.join(u.TMP, "slice_anim_0001.png"))
    img10 = u.load_png(os.path.join(u.TMP, "slice_anim_0010.png"))
    assert scene.frame_current == 1
    c = SIZE // 2
    px = px.reshape(h, w, 4)
    centre = px[h // 2, w // 2]
    assert centre[3] == 1 and centre[:3].max() > 0.2, centre
    # Standard view: the emission (scene-linear) comes out as the library's
    # sRGB colour, within the colours the texture has around the centre
    # (the pixel filter blends about a pixel of the picture).
    near = px[h // 2 - 3:h // 2 + 4, w // 2 - 3:w // 2 + 4, :3].reshape(-1, 3)
    srgb = np.where(near <= 0.0031308, near * 12.92, 1.055 * near ** (1 / 2.4) - 0.055)
    assert (img[c, c, :3] > srgb.min(0) - 0.02).all() and (img[c, c, :3] < srgb.max(0) + 0.02).all(), \
        (img[c, c], img10[c, c], srgb.min(0), srgb.max(0))
    assert img[2, 2, :3].max() < 0.02
    assert img10[c, c, :3].max() < 0.02, img10[c, c]  # the plane left the volume: transparent


@test
def render_mode_and_matcap_change_f12():
    scene, ob = _scene()
    dvr = _f12(scene, "mode_dvr")
    ob.voxlight.render_mode = "mip"
    mip = _f12(scene, "mode_mip")
    area = (dvr[..., :3].max(-1) > 0.05) | (mip[..., :3].max(-1) > 0.05)
    assert area.sum() > 100 and _rows_with_volume(mip).size > 10
    # MIP shows the flat maximum, DVR a shaded ball: they differ over the volume
    assert np.abs(mip[..., :3] - dvr[..., :3])[area].mean() > 0.03
    ob.voxlight.render_mode = "dvr"
    cutaway = _mod("cutaway")
    names = sorted(s.name for s in bpy.context.preferences.studio_lights if s.type == "MATCAP")
    # Blender 5.0's MatCaps are mostly multi-layer EXRs Python cannot read:
    # choosing one is reported; a readable one (every 3.x/4.x MatCap) shades.
    readable = [n for n in names if cutaway.matcap_pixels(n) is not None]
    assert readable, names
    unreadable = [n for n in names if n not in readable]
    if unreadable:
        ob.voxlight.matcap = unreadable[0]
        same = _f12(scene, "matcap_unreadable")
        assert any("multi-layer" in m for m in cutaway.problems(ob)), cutaway.problems(ob)
        assert np.abs(same - dvr).max() < 0.02  # the material and lights, as before
    ob.voxlight.matcap = readable[0]
    mc = _f12(scene, "matcap")
    assert cutaway.problems(ob) == [], cutaway.problems(ob)
    assert np.abs(mc[..., :3] - dvr[..., :3])[area].mean() > 0.02


@test
def crop_box_and_cutter_mesh_cut_in_f12():
    scene, ob = _scene()
    whole = _rows_with_volume(_f12(scene, "crop_uncut"))
    assert bpy.ops.voxlight.add_crop_box() == {"FINISHED"}
    box = ob.voxlight.crop_box
    assert box is not None and box.empty_display_type == "CUBE"
    same = _rows_with_volume(_f12(scene, "crop_whole"))  # made around the volume: nothing cut
    assert abs(same.min() - whole.min()) <= 1 and abs(same.max() - whole.max()) <= 1
    # Only the box's upper half: z from 0 to the top.
    half = box.scale.z / 2.0
    box.scale.z = half
    box.location.z = half
    top = _rows_with_volume(_f12(scene, "crop_top"))
    assert top.min() >= SIZE // 2 - 2 and abs(top.max() - whole.max()) <= 1, (top.min(), top.max())
    ob.voxlight.crop_box = None
    # A cube mesh over the upper half removes it (its inside).
    bpy.ops.mesh.primitive_cube_add(size=2.0, location=(0.0, 0.0, 1.0))
    cube = bpy.context.object
    cube.hide_render = True  # only as a cutter
    bpy.context.view_layer.objects.active = ob
    slot = ob.voxlight.cutters.add()
    slot.object = cube
    low = _rows_with_volume(_f12(scene, "cutter_inside"))
    assert low.max() <= SIZE // 2 + 2 and abs(low.min() - whole.min()) <= 1, (low.min(), low.max())
    slot.remove_outside = True  # keep only its inside: the upper half
    high = _rows_with_volume(_f12(scene, "cutter_outside"))
    assert high.min() >= SIZE // 2 - 2 and abs(high.max() - whole.max()) <= 1, (high.min(), high.max())


class _Recorder:
    """Stands in for a UILayout: records the properties and operators drawn."""

    def __init__(self, log):
        self.__dict__["log"] = log

    def __getattr__(self, name):
        def call(*args, **kw):
            if name == "prop" and len(args) >= 2:
                self.log.append(args[1])
            elif name in ("operator", "label"):
                self.log.append(args[0] if args else kw.get("text"))
            return _Recorder(self.log)
        return call

    def __setattr__(self, name, value):
        pass


def _draw(panel, ob):
    log = []

    class Ctx:
        object = ob
        scene = bpy.context.scene
    getattr(bpy.types, panel).draw(type("P", (), {"layout": _Recorder(log)})(), Ctx)
    return log


@test
def the_panels_show_the_settings_and_the_problems():
    scene, ob = _scene()
    assert "render_mode" in _draw("VOXLIGHT_PT_volume_mode", ob)
    ob.voxlight.render_mode = "iso"
    drawn = _draw("VOXLIGHT_PT_volume_mode", ob)
    assert "iso_value" in drawn and "matcap" in drawn
    _clip_empty(ob)
    ob.voxlight.cutters.add()
    bpy.context.view_layer.update()
    _mod("params").look_kwargs(ob.voxlight)  # what a frame does: files the problems
    drawn = _draw("VOXLIGHT_PT_volume_cutaway", ob)
    for want in ("object", "thickness", "remove_outside", "crop_box", "caps",
                 "voxlight.add_clip_plane", "voxlight.add_crop_box", "voxlight.add_cutter",
                 "voxlight.add_slice_plane"):
        assert want in drawn, (want, drawn)
    assert any(isinstance(t, str) and t.startswith("Cutter 1: no object") for t in drawn), drawn
    assert bpy.ops.voxlight.add_slice_plane() == {"FINISHED"}
    plane = next(o for o in scene.objects if o.type == "MESH" and o.voxlight_slice.volume == ob)
    drawn = _draw("VOXLIGHT_PT_slice_plane", plane)
    assert {"volume", "interpolation", "resolution", "voxlight.update_slice"} <= set(drawn), drawn
    # Removing a slot through the panel's operator.
    bpy.context.view_layer.objects.active = ob
    assert bpy.ops.voxlight.remove_cut(collection="cutters", index=0) == {"FINISHED"}
    assert len(ob.voxlight.cutters) == 0 and len(ob.voxlight.clip_planes) == 1


@test
def the_new_properties_take_keyframes():
    scene, ob = _scene()
    _clip_empty(ob)
    p = ob.voxlight
    assert bpy.ops.voxlight.add_cutter() == {"FINISHED"}
    for path, frames in (("voxlight.clip_planes[0].thickness", (0.0, 0.4)),
                         ("voxlight.iso_value", (10.0, 90.0)),
                         ("voxlight.caps", (True, False)),
                         ("voxlight.cutters[0].remove_outside", (False, True)),
                         ("voxlight.render_mode", ("dvr", "mip"))):
        for f, v in zip((1, 10), frames):
            ob.path_resolve(path.rsplit(".", 1)[0]).__setattr__(path.rsplit(".", 1)[1], v)
            assert ob.keyframe_insert(path, frame=f), path
    scene.frame_set(10)
    assert abs(p.clip_planes[0].thickness - 0.4) < 1e-6 and abs(p.iso_value - 90) < 1e-4
    assert p.caps is False and p.cutters[0].remove_outside and p.render_mode == "mip"
    scene.frame_set(1)
    assert p.clip_planes[0].thickness == 0.0 and p.render_mode == "dvr" and p.caps


@test
def missing_or_wrong_objects_are_reported_not_a_crash():
    scene, ob = _scene()
    cutaway = _mod("cutaway")
    e = _clip_empty(ob)
    p = ob.voxlight
    p.clip_planes.add()  # left empty
    cam_slot = p.cutters.add()
    cam_slot.object = scene.camera  # not a mesh
    p.crop_box = e
    bpy.data.objects.remove(e)  # deleted: the pointers go empty
    assert p.clip_planes[0].object is None and p.crop_box is None
    img = _f12(scene, "reported")
    msgs = cutaway.problems(ob)
    assert any("Clip plane 1" in m for m in msgs) and any("Clip plane 2" in m for m in msgs), msgs
    assert any("not a mesh" in m for m in msgs), msgs
    assert _rows_with_volume(img).size > 10  # rendered without the broken cuts
    # A slice plane whose volume is gone says so.
    sp = _mod("slice_planes")
    assert bpy.ops.voxlight.add_slice_plane() == {"FINISHED"}
    plane = next(o for o in scene.objects if o.type == "MESH" and o.voxlight_slice.volume == ob)
    bpy.data.objects.remove(ob)
    assert plane.voxlight_slice.volume is None and not sp.is_slice(plane)
    sp.update_all(scene)  # nothing to do, no error
    # Flattened to nothing: reported.
    plane.voxlight_slice.volume = None
    u.import_volume(u.ball_file())
    vol = next(o for o in scene.objects if o.voxlight.is_volume)
    plane.voxlight_slice.volume = vol
    plane.scale = (0.0, 1.0, 1.0)
    bpy.context.view_layer.update()
    sp.update_all(scene)
    assert "nothing" in sp.error(plane) or "no area" in sp.error(plane), sp.error(plane)


u.run("test_cutaway")
