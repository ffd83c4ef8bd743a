"""Headless Blender: install the built zip, import NIfTI volumes, drive
every panel property, bad files, lights, transforms, animation and
unregister/re-register.

blender -b --factory-startup --python-exit-code 1 --python tests/blender/test_headless.py
"""

import os
import sys

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import _util as u  # noqa: E402
from _util import test  # noqa: E402

vx = u.install_addon()
RES = (64, 64)


def _scene_with_ball():
    scene = u.reset_scene()
    ob = u.import_volume(u.ball_file())
    u.add_camera((0.0, -2.5, 0.3))
    return scene, ob


def _render(ob):
    return vx.render_volume(ob, resolution=RES)


def _diff(a, b):
    return float(np.abs(a - b).max())


def _is_our_menu(f):
    return getattr(f, "__name__", "") == "menu_import" and \
        u.is_ours(getattr(f, "__module__", ""))


@test
def registered_ui():
    assert hasattr(bpy.types.Object, "voxlight") and hasattr(bpy.types.Scene, "voxlight")
    assert hasattr(bpy.ops.voxlight, "import_volume")
    assert "VOXLIGHT_PT_volume" in dir(bpy.types)
    funcs = bpy.types.TOPBAR_MT_file_import._dyn_ui_initialize()
    assert any(_is_our_menu(f) for f in funcs)


@test
def import_synthetic_bounds_match_affine():
    u.reset_scene()
    path = u.ball_file("aniso.nii", n=32, spacing=(1.0, 2.0, 3.0))
    ob = u.import_volume(path, unit_scale=0.01, center=True)
    assert ob.type == "EMPTY" and ob.empty_display_type == "CUBE"
    assert ob.voxlight.is_volume and tuple(ob.voxlight.dims) == (32, 32, 32)
    # Drawn cube [-1, 1]^3 spans 32 voxels * spacing mm * 0.01 units/mm.
    assert np.allclose(np.array(ob.scale) * 2, [0.32, 0.64, 0.96], atol=1e-5), ob.scale
    assert np.allclose(ob.location, bpy.context.scene.cursor.location, atol=1e-6)
    # Without centring and turning, scanner coordinates are kept (mm -> units).
    ob2 = u.import_volume(path, unit_scale=0.001, center=False, anatomical_views=False)
    corner = ob2.matrix_world @ __import__("mathutils").Vector((-1, -1, -1))
    assert np.allclose(corner, [-0.0155 - 0.0005, -0.031 - 0.001, -0.0465 - 0.0015], atol=1e-6)
    assert bpy.context.view_layer.objects.active == ob2


@test
def import_ch2better():
    u.reset_scene()
    ob = u.import_volume(u.CH2)
    p = ob.voxlight
    assert tuple(p.dims) == (301, 370, 316)
    assert p.data_min == 0.0 and p.data_max > 100.0
    # 301 voxels of 0.5 mm at 0.01 units/mm = 1.505 units.
    assert abs(ob.scale[0] * 2 - 1.505) < 1e-4
    u.add_camera((0.0, -4.0, 0.5))
    img = _render(ob)
    assert img.shape == (64, 64, 4) and np.isfinite(img).all()
    assert img[..., 3].max() > 0.9 and img[0, 0, 3] < 0.01


@test
def bad_file_reports_and_creates_nothing():
    u.reset_scene()
    bad = os.path.join(u.TMP, "broken.nii")
    with open(bad, "wb") as f:
        f.write(b"\x5c\x01\x00\x00" + b"garbage" * 20)
    for path in (bad, os.path.join(u.TMP, "does-not-exist.nii.gz")):
        before = set(bpy.data.objects)
        try:
            bpy.ops.voxlight.import_volume(filepath=path)
        except RuntimeError as e:  # background mode turns ERROR reports into exceptions
            msg = str(e)
        else:
            raise AssertionError("no error report for %s" % path)
        assert "Voxlight: cannot import" in msg and os.path.basename(path) in msg, msg
        assert set(bpy.data.objects) == before


@test
def every_panel_property_changes_the_render():
    scene, ob = _scene_with_ball()
    p = ob.voxlight
    p.jitter = False
    ref = _render(ob)
    changes = [
        ("filter", "sobel26"), ("filter", "forward3"), ("filter", "sobel8"),
        ("filter", "sobel14"), ("filter", "precomputed"), ("gradient_16f", True),
        ("filter", "cubic"), ("filter", "central"), ("sample_distance", 2.5),
        ("reuse_gradients", True),
        ("step", 1.5), ("jitter", True), ("preset", "hot"), ("preset", "bone"),
        ("window_low", 40.0), ("window_high", 90.0), ("window_low", 20.0),
        ("window_high", 70.0),
        ("opacity_scale", 0.4), ("ambient", 0.8), ("diffuse", 0.2), ("specular", 0.9),
        ("shininess", 4.0), ("shading", False),
    ]
    prev = ref
    for name, value in changes:
        setattr(p, name, value)
        img = _render(ob)
        assert _diff(img, prev) > 1e-3, "%s=%r did not change the image" % (name, value)
        prev = img


@test
def filter_choices_come_from_the_library():
    """The panel's filter enum is the library's list (vxl_filter_name), with
    the library's VXL_FILTER_* numbers, so 'cubic' (6) is there."""
    lib = vx.core.native.load_library()
    prop = bpy.types.Object.bl_rna.properties["voxlight"].fixed_type.properties["filter"]
    items = [(i.identifier, i.value) for i in prop.enum_items]
    assert items == [(n, i) for i, n in enumerate(lib.filter_names())], items
    assert ("cubic", 6) in items and len(items) == len(vx.core.native.FILTERS)
    assert ("cubic-smooth", 7) in items  # the approximating B-spline
    assert {"cubic", "cubic-smooth"} <= vx.properties.FIXED_TAP_FILTERS  # sampleDistance greyed out


@test
def renders_skip_volumes_nobody_can_see():
    """F12 and scripted renders make no library call for a volume outside
    the camera's frustum, hidden from renders or in an excluded collection."""
    scene, ob = _scene_with_ball()
    ob.voxlight.jitter = False
    w, h = 32, 32
    rt = vx.core.runtime

    def f12_layers():
        dg = bpy.context.evaluated_depsgraph_get()
        calls = rt.call_count
        res = vx.offline.render(scene, dg, scene.camera, w, h, for_render=True)
        return res, rt.call_count - calls

    res, calls = f12_layers()
    assert calls == 1 and res[0][..., 3].max() > 0.5
    cam = scene.camera
    cam.rotation_euler.z += 3.14159  # looking away from the volume
    res, calls = f12_layers()
    assert calls == 0 and res is not None and not res[0][..., 3].any(), calls
    before = rt.call_count
    img = vx.render_volume(ob, resolution=(w, h))
    assert rt.call_count == before and img.shape == (h, w, 4) and not img.any()
    cam.rotation_euler.z -= 3.14159
    ob.hide_render = True
    res, calls = f12_layers()
    assert calls == 0 and res is None
    ob.hide_render = False
    coll = bpy.data.collections.new("Hidden volumes")
    scene.collection.children.link(coll)
    for c in list(ob.users_collection):
        c.objects.unlink(ob)
    coll.objects.link(ob)
    bpy.context.view_layer.layer_collection.children[coll.name].exclude = True
    res, calls = f12_layers()
    assert calls == 0 and res is None
    bpy.context.view_layer.layer_collection.children[coll.name].exclude = False
    res, calls = f12_layers()
    assert calls == 1 and res[0][..., 3].max() > 0.5


@test
def properties_are_animatable():
    scene, ob = _scene_with_ball()
    p = ob.voxlight
    p.jitter = False
    p.opacity_scale = 1.0
    p.keyframe_insert("opacity_scale", frame=1)
    p.opacity_scale = 0.2
    p.keyframe_insert("opacity_scale", frame=10)
    p.filter = "central"
    p.keyframe_insert("filter", frame=1)
    scene.frame_set(1)
    a = _render(ob)
    scene.frame_set(10)
    assert abs(ob.voxlight.opacity_scale - 0.2) < 1e-6
    b = _render(ob)
    assert a[..., 3].sum() > b[..., 3].sum() * 1.1


@test
def render_follows_object_transform():
    scene, ob = _scene_with_ball()
    ob.voxlight.jitter = False
    a = _render(ob)
    ob.location.x += 0.3
    b = _render(ob)
    # The ball moved right: alpha's centre of mass moves to larger x.
    xs = np.arange(RES[0])
    cx = lambda img: (img[..., 3].sum(axis=0) * xs).sum() / img[..., 3].sum()  # noqa: E731
    assert cx(b) > cx(a) + 3
    ob.scale *= 0.5
    c = _render(ob)
    assert c[..., 3].sum() < b[..., 3].sum() * 0.5


@test
def scene_lights_light_the_volume():
    scene, ob = _scene_with_ball()
    ob.voxlight.jitter = False
    head = _render(ob)
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    scene.collection.objects.link(sun)
    sun.rotation_euler = (0.0, 1.2, 0.0)  # from +X
    lit = _render(ob)
    assert _diff(lit, head) > 1e-2
    # Lit from +X: the right half is brighter than the left.
    lum = lit[..., :3].sum(axis=2)
    assert lum[:, 36:].sum() > lum[:, :28].sum() * 1.2
    sun.rotation_euler = (0.0, -1.2, 0.0)  # moving the light relights
    moved = _render(ob)
    lum = moved[..., :3].sum(axis=2)
    assert lum[:, :28].sum() > lum[:, 36:].sum() * 1.2
    sun.data.color = (1.0, 0.0, 0.0)
    red = _render(ob)
    assert red[..., 0].sum() > red[..., 2].sum() * 1.2
    point = bpy.data.objects.new("Point", bpy.data.lights.new("Point", "POINT"))
    scene.collection.objects.link(point)
    point.location = (0.0, -1.0, 1.5)
    assert _diff(_render(ob), red) > 1e-3
    scene.voxlight.use_scene_lights = False
    assert _diff(_render(ob), head) < 1e-5
    scene.voxlight.use_scene_lights = True


@test
def default_camera_when_scene_has_none():
    u.reset_scene()
    ob = u.import_volume(u.ball_file())
    img = vx.render_volume(ob, resolution=(40, 30))
    assert img.shape == (30, 40, 4) and img[..., 3].max() > 0.5


@test
def render_volume_writes_file():
    scene, ob = _scene_with_ball()
    out = os.path.join(u.TMP, "api.png")
    img = vx.render_volume(ob, resolution=(32, 24), filepath=out)
    px = u.load_png(out)
    assert px.shape == (24, 32, 4)
    assert abs(float(px[..., 3].mean()) - float(img[..., 3].mean())) < 0.02


@test
def survives_save_and_reload():
    scene, ob = _scene_with_ball()
    ob.voxlight.jitter = False
    ob.voxlight.preset = "hot"
    a = _render(ob)
    name = ob.name
    path = os.path.join(u.TMP, "scene.blend")
    bpy.ops.wm.save_as_mainfile(filepath=path)
    vx.core.runtime.release_all()  # as after a restart: no live renderer
    bpy.ops.wm.open_mainfile(filepath=path)
    ob = bpy.data.objects[name]
    assert ob.voxlight.preset == "hot"
    assert _diff(vx.render_volume(ob, resolution=RES), a) < 1e-5


@test
def large_phantom_renders_bricked_within_the_budget():
    """A generated volume over the 2048 texture limit imports by name,
    renders bricked under the default 2 GiB budget, and the panel's storage
    line says so (the full 2500x1500x400 run is in docs/storage.md)."""
    u.reset_scene()
    spec = "phantom:large-sparse:2200x300x90"
    ob = u.import_volume(spec)
    assert ob.voxlight.filepath == spec and tuple(ob.voxlight.dims) == (2200, 300, 90)
    img = vx.render_volume(ob, resolution=(96, 48))
    assert img[..., 3].max() > 0.1, img[..., 3].max()
    frame = vx.core.runtime.find_entry(spec).last_frame
    assert frame["storage_name"] == "bricked" and 0 < frame["resident_bytes"] < 2 << 30, frame
    assert frame["pages_constant"] > 0 and frame["pages_resident"] < frame["pages_total"]
    text = vx.panels.storage_text(frame)
    assert text.startswith("Storage: bricked") and "constant" in text, text
    assert vx.panels.lod_text(frame) == ""
    # sparse storage under half the memory it wants: a coarser level, said in the panel
    s = bpy.context.scene.voxlight
    s.storage = "sparse"
    vx.render_volume(ob, resolution=(96, 48))
    frame = vx.core.runtime.find_entry(spec).last_frame
    assert frame["storage_name"] == "sparse" and frame["lod_level"] == 0, frame
    s.memory_budget_mib = max(1, int(frame["resident_bytes"] / 2 / 1048576))
    img = vx.render_volume(ob, resolution=(96, 48))
    frame = vx.core.runtime.find_entry(spec).last_frame
    assert frame["lod_level"] >= 1 and frame["resident_bytes"] <= s.memory_budget_mib << 20, frame
    assert vx.panels.lod_text(frame).startswith("LOD fallback"), frame
    assert img[..., 3].max() > 0.05
    s.storage = "auto"
    s.memory_budget_mib = 2048
    before = set(bpy.data.objects)
    try:
        bpy.ops.voxlight.import_volume(filepath="phantom:no-such-thing")
        raise AssertionError("an unknown phantom imported")
    except RuntimeError as e:
        assert "unknown phantom" in str(e), e
    assert set(bpy.data.objects) == before


@test
def unregister_and_register_again():
    import addon_utils
    u.disable()
    assert not hasattr(bpy.types.Object, "voxlight")
    assert not hasattr(bpy.types.Scene, "voxlight")
    assert "VOXLIGHT_PT_volume" not in dir(bpy.types)
    for lst in (bpy.app.handlers.render_pre, bpy.app.handlers.render_init,
                bpy.app.handlers.frame_change_post, bpy.app.handlers.load_pre):
        assert not [h for h in lst if u.is_ours(getattr(h, "__module__", ""))], lst
    funcs = bpy.types.TOPBAR_MT_file_import._dyn_ui_initialize()
    assert not any(_is_our_menu(f) for f in funcs)
    voxlight = u.enable()
    assert addon_utils.check(u.MODULE)[1]
    scene = u.reset_scene()
    ob = u.import_volume(u.ball_file())
    u.add_camera((0.0, -2.5, 0.3))
    assert voxlight.render_volume(ob, resolution=(32, 32))[..., 3].max() > 0.5
    # And once more, to be sure the second unregister is as clean as the first.
    u.disable()
    u.enable()
    assert hasattr(bpy.types.Object, "voxlight")


u.run("test_headless")
