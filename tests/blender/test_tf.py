"""Headless Blender: the transfer function has one editor, the ColorRamp
: presets load into it placed on the data, are named in the panel
and marked when edited; files and scripts using the old "Transfer Function"
enum keep working; classification modes and gradient opacity.

blender -b --factory-startup --python-exit-code 1 --python tests/blender/test_tf.py
"""

import os
import sys

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import _util as u  # noqa: E402  (also puts tests/python on sys.path)
from _util import test  # noqa: E402

vx = u.install_addon()
RES = (64, 64)


def _volume(name, lo=0.0, hi=120.0):
    """The phantom ball rescaled so 0 -> lo and 120 -> hi (data units)."""
    u.reset_scene()
    v = u.phantom(32) / 120.0
    aff = np.diag([2.0, 2.0, 2.0, 1.0])
    aff[:3, 3] = -31.0
    path = u.write_nifti(os.path.join(u.TMP, name), (lo + v * (hi - lo)).astype(np.float32),
                         aff)
    ob = u.import_volume(path)
    u.add_camera((0.0, -2.5, 0.3))
    ob.voxlight.jitter = False
    return ob


def _render(ob):
    return vx.render_volume(ob, resolution=RES)


def _diff(a, b):
    return float(np.abs(a - b).max())


def _load(ob, key):
    with bpy.context.temp_override(object=ob, active_object=ob):
        assert bpy.ops.voxlight.tf_preset(preset=key) == {"FINISHED"}


@test
def import_loads_a_fitted_preset_into_the_ramp():
    ob = _volume("hist.nii.gz")
    p = ob.voxlight
    tex = p.tf_texture
    assert tex is not None and tex.type == "BLEND" and tex.use_color_ramp
    assert tex.name.startswith(".VXL TF")
    h = np.array(p.histogram)
    assert h.sum() == 32 ** 3, h.sum()
    assert h[0] > h[-1] > 0  # mostly background zeros, some bright ball voxels
    # 0..120 float data: arbitrary units, the MRI preset, placed inside the data
    assert p.data_kind == "mr" and p.tf_preset == "MRI", (p.data_kind, p.tf_preset)
    assert vx.tf.preset_state(p) == ("MRI", False)
    assert p.data_min <= p.window_low < p.window_high <= p.data_max
    assert p.window_low > p.data_min  # the background zeros are left out
    assert _render(ob)[..., 3].max() > 0.2


@test
def ct_range_imports_as_ct_with_hounsfield_window():
    ob = _volume("ct.nii.gz", -1024.0, 2000.0)
    p = ob.voxlight
    assert p.data_kind == "ct" and p.tf_preset == "CT"
    lo, hi, _stops = vx.core.tf_fit.place("CT", "ct", vx.tf.stats_of(ob))
    assert abs(p.window_low - lo) < 1e-3 and p.window_high == 2000.0


@test
def every_preset_round_trips_through_the_colorramp():
    """Loading a preset into the ramp and sampling the ramp (what the
    library gets) gives the preset's own table, placed on the data."""
    for name, lo, hi in (("rt_mr.nii.gz", 0.0, 130.0), ("rt_ct.nii.gz", -1024.0, 2500.0)):
        ob = _volume(name, lo, hi)
        p = ob.voxlight
        stats = vx.tf.stats_of(ob)
        for key in vx.core.tf_presets.PRESETS:
            _load(ob, key)
            wlo, whi, stops = vx.core.tf_fit.place(key, p.data_kind, stats)
            assert abs(p.window_low - wlo) < 1e-3 * max(1.0, abs(wlo)), (key, p.window_low, wlo)
            assert abs(p.window_high - whi) < 1e-3 * max(1.0, abs(whi)), (key, p.window_high, whi)
            # the ramp holds the preset's (sRGB) colours scene-linear
            want = vx.core.tf_presets.stops_table(vx.tf.preset_stops(stops))
            got = vx.tf.table(p)
            err = float(np.abs(got - want).max())
            assert err < 0.01, (key, err)
            assert len(p.tf_texture.color_ramp.elements) == len(stops), key
            assert vx.tf.preset_state(p) == (vx.core.tf_presets.PRESETS[key].name, False), key
        # built-in presets on CT reproduce the library's own table over its window
        if p.data_kind == "ct":
            _load(ob, "BONE")
            lib_ct = vx.core.tf_presets.builtin_table("ct")
            _load(ob, "CT")
            wlo, whi = p.window_low, p.window_high
            hu = np.linspace(-1000.0, 2000.0, 301)
            ramp = p.tf_texture.color_ramp
            got = np.array([ramp.evaluate(float(np.clip((v - wlo) / (whi - wlo), 0, 1)))
                            for v in hu])
            x = np.linspace(0.0, 1.0, len(lib_ct))
            ref = np.stack([np.interp((hu + 1000.0) / 3000.0, x, lib_ct[:, c])
                            for c in range(4)], 1)
            ref[:, :3] = vx.core.colour_space.srgb_to_linear(ref[:, :3])
            assert float(np.abs(got - ref).max()) < 0.02, float(np.abs(got - ref).max())


@test
def editing_the_ramp_marks_the_preset_modified_and_rerenders():
    ob = _volume("ramp.nii.gz")
    p = ob.voxlight
    p.window_low, p.window_high = 0.0, 120.0
    _load(ob, "GRAY")
    ramp = p.tf_texture.color_ramp
    prev = _render(ob)
    for what, edit in (("colour", lambda: setattr(ramp.elements[1], "color", (1, 0, 0, 1))),
                       ("alpha", lambda: setattr(ramp.elements[1], "alpha", 0.1)),
                       ("position", lambda: setattr(ramp.elements[0], "position", 0.5)),
                       ("new stop", lambda: setattr(ramp.elements.new(0.8), "color",
                                                    (0, 0, 1, 1)))):
        edit()
        assert vx.tf.preset_state(p) == ("Gray", True), what
        img = _render(ob)
        assert _diff(img, prev) > 1e-3, "ramp %s edit did not change the image" % what
        prev = img
    assert img[..., 0].max() > 0.2  # red stop: red where the ball is
    # The sampled table is part of the viewport's frame key.
    view, proj = np.eye(4), np.eye(4)
    k1 = vx.core.native.params_digest(vx.params.build(ob, 8, 8, view, proj), "id")
    ramp.elements[0].color = (0, 1, 0, 0.5)
    k2 = vx.core.native.params_digest(vx.params.build(ob, 8, 8, view, proj), "id")
    k3 = vx.core.native.params_digest(vx.params.build(ob, 8, 8, view, proj), "id")
    assert k1 != k2 and k2 == k3
    # Fit Window on an edited ramp keeps the stops and spans the foreground.
    before = vx.tf.table(p)
    with bpy.context.temp_override(object=ob, active_object=ob):
        assert bpy.ops.voxlight.tf_fit_window() == {"FINISHED"}
    assert np.array_equal(vx.tf.table(p), before)
    assert p.data_min < p.window_low < p.window_high <= p.data_max


@test
def old_enum_and_use_colorramp_still_work_from_scripts():
    ob = _volume("legacy_script.nii.gz")
    p = ob.voxlight
    p.preset = "hot"  # the old "Transfer Function" enum loads that preset
    assert p.tf_preset == "HOT" and vx.tf.preset_state(p) == ("Hot", False)
    hot = _render(ob)
    p.preset = "bone"
    assert p.tf_preset == "BONE" and _diff(_render(ob), hot) > 1e-3
    p.tf_texture.color_ramp.elements[0].color = (0, 0, 1, 1)
    p.use_color_ramp = False  # "use the library preset" = load it again
    assert vx.tf.preset_state(p) == ("Bone", False)
    p.use_color_ramp = True
    assert p.tf_preset == "BONE"


@test
def old_files_open_looking_the_same():
    """A volume saved before the single editor (library preset, no custom
    window) is converted when the file opens: its preset's table goes into
    the ramp and the library's window becomes explicit."""
    for preset, lo, hi in (("bone", 0.0, 120.0), ("auto", -1024.0, 2000.0)):
        ob = _volume("legacy_%s.nii.gz" % preset, lo, hi)
        p = ob.voxlight
        vx.tf._quiet = True  # write the old state without the legacy callbacks
        try:
            p.tf_version = 0
            p.use_color_ramp = False
            p.use_window = False
            p.preset = preset
            p.window_low, p.window_high = 12.0, 34.0  # ignored without use_window
        finally:
            vx.tf._quiet = False
        p.filter = "central"  # the filter's default then
        before = _render(ob)  # the library's preset and window, as before
        del p["filter"]  # a default is not stored in the file
        name = ob.name
        path = os.path.join(u.TMP, "legacy_%s.blend" % preset)
        bpy.ops.wm.save_as_mainfile(filepath=path)
        vx.core.runtime.release_all()
        bpy.ops.wm.open_mainfile(filepath=path)
        ob = bpy.data.objects[name]
        p = ob.voxlight
        assert p.tf_version == vx.tf.TF_VERSION and p.use_color_ramp and p.use_window
        key = {"bone": "BONE", "auto": "CT"}[preset]
        assert p.tf_preset == key, (preset, p.tf_preset)
        want = (-1000.0, 2000.0) if key == "CT" else (p.data_min, p.data_max)
        assert abs(p.window_low - want[0]) < 1e-3 and abs(p.window_high - want[1]) < 1e-3
        assert p.filter == "central", p.filter
        after = _render(ob)
        assert _diff(after, before) < 0.02, (preset, _diff(after, before))


@test
def files_from_before_the_sobel8_default_keep_their_filter():
    """tf_version 1 volumes saved with the old default filter (central,
    never set, so not stored) open with central; a filter the artist chose
    stays; new volumes get sobel8."""
    old_default = _volume("v1_default.nii.gz")
    assert old_default.voxlight.filter == "sobel8"  # a new volume's
    chosen = u.import_volume(bpy.path.abspath(old_default.voxlight.filepath))
    chosen.voxlight.filter = "sobel26"
    for ob in (old_default, chosen):
        ob.voxlight.tf_version = 1
    assert old_default.voxlight.get("filter") is None
    old_default, chosen = u.reopen((old_default, chosen), "tf_v1.blend")
    assert old_default.voxlight.filter == "central", old_default.voxlight.filter
    assert chosen.voxlight.filter == "sobel26", chosen.voxlight.filter
    assert old_default.voxlight.tf_version == chosen.voxlight.tf_version == vx.tf.TF_VERSION


@test
def files_from_before_linear_colour_have_their_colours_decoded():
    """Before tf_version 4 the library took the ramp's and the labels'
    colours as display (sRGB) values; the add-on now renders scene-linear,
    as Blender holds colours. A file from before opens with those colours
    decoded, so it looks as it did; an unedited preset stays unedited."""
    ob = _volume("v3_colours.nii.gz")
    p = ob.voxlight
    ramp = p.tf_texture.color_ramp
    display = [tuple(e.color) for e in ramp.elements]
    assert any(0.05 < c < 0.95 for rgba in display for c in rgba[:3]), display
    lab = ob.voxlight_labels.labels.add()
    lab.label_id, lab.color = 7, (0.5, 0.25, 1.0, 0.8)
    p.tf_version = 3
    p.tf_preset_signature = vx.tf.ramp_signature(ramp)  # the preset as loaded then
    ob = u.reopen((ob,), "tf_v3.blend")[0]
    p = ob.voxlight
    assert p.tf_version == vx.tf.TF_VERSION
    got = [tuple(e.color) for e in p.tf_texture.color_ramp.elements]
    want = [vx.core.colour_space.rgba_to_linear(c) for c in display]
    assert np.abs(np.array(got) - np.array(want)).max() < 1e-6, (got, want)
    assert vx.tf.preset_state(p)[1] is False  # still the unedited preset
    c = tuple(ob.voxlight_labels.labels[0].color)
    assert np.abs(np.array(c) - np.array((0.2140, 0.0508, 1.0, 0.8))).max() < 1e-3, c
    # opening it again changes nothing more
    ob = u.reopen((ob,), "tf_v4.blend")[0]
    again = [tuple(e.color) for e in ob.voxlight.tf_texture.color_ramp.elements]
    assert np.abs(np.array(again) - np.array(got)).max() == 0


@test
def dicom_modality_decides_the_kind_of_data():
    """Values 76..87 look like arbitrary units, but a DICOM series that says
    CT is CT (Hounsfield units, CT preset); its MR sibling is MR."""
    from dicom_write import write_dicom
    u.reset_scene()
    d = os.path.join(u.TMP, "modality")
    os.makedirs(d, exist_ok=True)
    px = np.arange(12, dtype=np.uint16).reshape(3, 4) + 1100  # 76..87 after the -1024 intercept
    for k in range(4):
        write_dicom(os.path.join(d, "c%d.dcm" % k), "1.2.9.1", px, 2.0 * k)
    for k in range(2):
        write_dicom(os.path.join(d, "m%d.dcm" % k), "1.2.9.2", px, 2.0 * k, modality="MR")
    ct = u.import_volume(os.path.join(d, "c0.dcm"))  # the file's series, by its size
    mr = u.import_volume(os.path.join(d, "m0.dcm"), series="1.2.9.2")
    assert (ct.voxlight.data_kind, ct.voxlight.tf_preset) == ("ct", "CT")
    assert (mr.voxlight.data_kind, mr.voxlight.tf_preset) == ("mr", "MRI")
    assert vx.core.tf_fit.guess_kind(76.0, 87.0) == "mr"  # what the range alone would say


# Each Slicer preset on a volume whose values lie where the preset shows something.
PRESET_DATA = {"CT_BONE": (-1000.0, 1000.0), "CT_SOFT_TISSUE": (-1000.0, 400.0),
               "CT_LUNG": (-1000.0, -500.0), "MR_DEFAULT": (0.0, 300.0),
               "MR_ANGIO": (0.0, 300.0)}


@test
def slicer_presets_render():
    assert set(PRESET_DATA) == set(vx.tf.SLICER_PRESETS)
    for key, (lo, hi) in PRESET_DATA.items():
        ob = _volume("preset_%s.nii.gz" % key.lower(), lo, hi)
        _load(ob, key)
        img = _render(ob)
        assert img[..., 3].max() > 0.05, (key, img[..., 3].max())
        assert img[0, 0, 3] < 0.05, key


@test
def classification_and_gradient_opacity_change_the_render():
    ob = _volume("classify.nii.gz")
    p = ob.voxlight
    p.window_low, p.window_high = 20.0, 110.0
    ramp = p.tf_texture.color_ramp
    vx.tf.set_ramp(ramp, [(0.55, (1, 0.5, 0.2, 0.0)), (0.6, (1, 1, 1, 0.8))])  # sharp
    prev = _render(ob)
    for name, value in (("classify", "pre"), ("classify", "preint"), ("classify", "post"),
                        ("gradient_opacity", "boundary"), ("gradient_ref", 0.5),
                        ("gradient_exp", 3.0), ("gradient_opacity", "iso"),
                        ("iso_value", 90.0), ("iso_thickness", 3.0)):
        setattr(p, name, value)
        img = _render(ob)
        assert np.isfinite(img).all()
        assert _diff(img, prev) > 1e-3, "%s=%r did not change the image" % (name, value)
        prev = img
    assert img[..., 3].max() > 0.05


@test
def f12_uses_the_ramp():
    """F12 (bpy.ops.render.render) composites the ColorRamp's colours."""
    ob = _volume("f12.nii.gz")
    scene = bpy.context.scene
    scene.render.resolution_x = scene.render.resolution_y = 48
    scene.render.engine = "BLENDER_WORKBENCH"
    p = ob.voxlight
    p.window_low, p.window_high = 0.0, 120.0
    ramp = p.tf_texture.color_ramp
    vx.tf.set_ramp(ramp, [(0.0, (0, 1, 0, 0)), (1.0, (0, 1, 0, 1))])
    out = os.path.join(u.TMP, "f12_ramp.png")
    scene.render.filepath = out
    scene.render.image_settings.file_format = "PNG"
    bpy.ops.render.render(write_still=True)
    img = u.load_png(out)
    centre = img[20:28, 20:28, :3].mean(axis=(0, 1))
    assert centre[1] > centre[0] + 0.1 and centre[1] > centre[2] + 0.1, centre


def _box_pixels(ob, camera, w, h):
    """Mask of the pixels the volume's box covers on screen (convex hull of
    its projected corners)."""
    depsgraph = bpy.context.evaluated_depsgraph_get()
    view, proj = vx.offline.camera_matrices(camera, depsgraph, w, h, bpy.context.scene)
    model = vx.params.model_matrix(ob)
    c = np.c_[vx.core.native.voxel_box_corners(tuple(ob.voxlight.dims)), np.ones(8)]
    clip = (proj @ view @ model @ c.T).T
    pts = (clip[:, :2] / clip[:, 3:4] * 0.5 + 0.5) * [w, h]
    pts = sorted(map(tuple, pts))

    def cross(u, v):  # 2D: numpy 2 refuses np.cross of 2-vectors
        return u[0] * v[1] - u[1] * v[0]

    def half(ps):  # Andrew's monotone chain
        out = []
        for q in ps:
            while len(out) >= 2 and cross(np.subtract(out[-1], out[-2]), np.subtract(q, out[-2])) <= 0:
                out.pop()
            out.append(q)
        return out[:-1]
    hull = np.array(half(pts) + half(pts[::-1]))
    yy, xx = np.mgrid[0:h, 0:w] + 0.5
    inside = np.ones((h, w), bool)
    for a, b in zip(hull, np.roll(hull, -1, axis=0)):
        inside &= (b[0] - a[0]) * (yy - a[1]) - (b[1] - a[1]) * (xx - a[0]) >= 0
    return inside


@test
def default_import_of_arbitrary_units_covers_part_of_the_box():
    """ch2better (values 0..130): the default import's window lies inside
    the data and its render covers between 5% and 60% of the box's screen
    area (not fog filling the box, not nothing)."""
    scene = u.reset_scene()
    ob = u.import_volume(u.CH2)
    p = ob.voxlight
    assert p.data_kind == "mr" and p.tf_preset == "MRI"
    assert p.data_min <= p.window_low < p.window_high <= p.data_max
    cam = u.add_camera((0.0, -4.0, 0.5))
    w, h = 96, 96
    scene.render.resolution_x, scene.render.resolution_y = w, h
    img = vx.render_volume(ob, camera=cam, resolution=(w, h))
    box = _box_pixels(ob, cam, w, h)
    assert box.sum() > 0.1 * w * h
    coverage = float(img[..., 3][box].sum() / box.sum())
    print("ch2better default import: window %.1f..%.1f, alpha coverage %.1f%% of the box"
          % (p.window_low, p.window_high, 100 * coverage))
    assert 0.05 <= coverage <= 0.60, coverage
    # A preset that does not fit (CT Bone on MR) is placed by the histogram too.
    _load(ob, "CT_BONE")
    assert p.data_min <= p.window_low < p.window_high <= p.data_max


class _AnyLayout:
    """Stands in for a UILayout: accepts every call and records (call, name
    or text) pairs, and the property-split settings."""

    def __init__(self, log, split):
        self.__dict__["log"] = log
        self.__dict__["split"] = split

    def __getattr__(self, name):
        def call(*args, **kw):
            self.log.append((name, args[1] if len(args) > 1 else kw.get("text")))
            if "text" in kw and name in ("prop", "menu", "operator", "label"):
                self.log.append((name + ":text", kw["text"]))
            return _AnyLayout(self.log, self.split)
        return call

    def __setattr__(self, name, value):
        if name == "use_property_split":
            self.split.append(value)


def _draw_panels(ob):
    log, split = [], []

    class Ctx:
        object = ob
        region = None
        preferences = bpy.context.preferences
    for name in ("VOXLIGHT_PT_volume", "VOXLIGHT_PT_volume_rendering", "VOXLIGHT_PT_volume_tf",
                 "VOXLIGHT_PT_volume_lighting", "VOXLIGHT_PT_volume_advanced",
                 "VOXLIGHT_PT_volume_stats"):
        panel = getattr(bpy.types, name)
        fake = type("P", (), {"layout": _AnyLayout(log, split)})()
        for fn in ("draw_header", "draw_header_preset", "draw"):
            if hasattr(panel, fn):
                getattr(panel, fn)(fake, Ctx)
    return log, split


@test
def panel_has_subpanels_ramp_picture_and_preset_name():
    ob = _volume("panel.nii.gz")
    p = ob.voxlight
    subs = [c for c in bpy.types.Panel.__subclasses__()
            if getattr(c, "bl_parent_id", "") == "VOXLIGHT_PT_volume"]
    labels = {c.bl_label: c for c in subs}
    assert set(labels) == {"Rendering", "Transfer Function", "Lighting", "Render Mode",
                           "Cutaway", "Labels", "Overlays", "Channels", "Advanced",
                           "Statistics"}, set(labels)
    for name in ("Advanced", "Statistics"):
        assert "DEFAULT_CLOSED" in labels[name].bl_options
    for gop in ("off", "boundary", "iso"):
        p.gradient_opacity = gop
        log, split = _draw_panels(ob)
        names = {n for _f, n in log}
        assert {"classify", "gradient_opacity", "window_low", "window_high", "filter",
                "step", "shading", "ambient", "opacity_scale"} <= names, names
        assert ("template_color_ramp", "color_ramp") in log
        assert any(f == "template_icon" for f, _n in log)  # the histogram picture
        assert ("menu:text", "MRI") in log, [x for x in log if x[0] == "menu:text"]
        assert ("iso_value" in names) == (gop == "iso")
        assert split and all(split), split  # property-split layout everywhere
        assert "preset" not in names and "use_color_ramp" not in names
    p.tf_texture.color_ramp.elements[0].position = 0.3
    log, _split = _draw_panels(ob)
    assert ("menu:text", "MRI (modified)") in log
    # every property of the volume and of the scene settings has a tooltip
    for owner in (bpy.types.Object, bpy.types.Scene):
        props = owner.bl_rna.properties["voxlight"].fixed_type.properties
        missing = [q.identifier for q in props
                   if q.identifier != "rna_type" and not q.is_hidden
                   and not q.description.strip()]
        assert not missing, (owner, missing)
    rna = bpy.types.Object.bl_rna.properties["voxlight"].fixed_type
    filt = rna.properties["filter"].enum_items
    assert filt["central"].description.startswith("Central: fast, good on clean data")
    assert filt["sobel26"].description.startswith("Sobel 26: smooth normals on noisy scans")
    # the default avoids central's lattice stripes on scans (tests/test_stripes.c)
    assert rna.properties["filter"].default == "sobel8"
    assert filt["sobel8"].description.startswith("Sobel 8: the default")


@test
def histogram_picture_follows_the_window():
    ob = _volume("picture.nii.gz")
    p = ob.voxlight
    a = vx.panels.histogram_icon(ob)
    pv = vx.panels._previews[ob.name]
    assert tuple(pv.image_size) == vx.panels.PICTURE_SIZE
    px1 = np.array(pv.image_pixels_float[:])
    assert px1.size == 4 * vx.panels.PICTURE_SIZE[0] * vx.panels.PICTURE_SIZE[1]
    assert vx.panels.histogram_icon(ob) == a  # unchanged: no new picture
    p.window_high = p.window_high * 0.5
    vx.panels.histogram_icon(ob)
    px2 = np.array(vx.panels._previews[ob.name].image_pixels_float[:])
    assert np.abs(px2 - px1).max() > 0.1


@test
def unregister_removes_the_handlers():
    u.disable()
    for lst in (bpy.app.handlers.depsgraph_update_post, bpy.app.handlers.load_post):
        assert not [h for h in lst if u.is_ours(getattr(h, "__module__", ""))]
    assert "VOXLIGHT_MT_tf_presets" not in dir(bpy.types)
    u.enable()


u.run("test_tf")
