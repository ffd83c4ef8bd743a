"""In Blender: an atlas (a label NIfTI with a FreeSurfer-style
LUT.txt beside it) imports as a labels object with the lookup file's names
and colours; hiding one region in F12 changes exactly that region's pixels;
the label colours and visibility take keyframes; hiding a label changes the
viewport's frame digest; a missing lookup file or a non-integer file is
reported, not a crash; labels attach to an existing volume.

blender -b --factory-startup --python-exit-code 1 --python tests/blender/test_labels.py
"""

import contextlib
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
DIMS = (40, 24, 24)
CENTRES = (7.0, 20.0, 33.0)  # voxel x of labels 1, 2, 3 (spheres of radius 5.5 voxels)
LUT = ("#No. Label Name:                R   G   B   A\n"
       "0   Unknown                     0   0   0   0\n"
       "1   Left-Red                  255   0   0   0\n"
       "2   Middle-Green                0 255   0   0\n"
       "3   Right-Blue                  0   0 255   0\n")
NAMES = ["Left-Red", "Middle-Green", "Right-Blue"]


def _mod(name):
    return sys.modules[u.MODULE + "." + name]


def _atlas(folder="atlas", lut=True, dtype=np.uint8, name="atlas.nii.gz"):
    """Three balls of labels 1, 2, 3 side by side along x, centred at the
    scanner origin (2 mm voxels); the LUT beside it unless lut is False."""
    d = os.path.join(u.TMP, folder)
    os.makedirs(d, exist_ok=True)
    i, j, k = np.meshgrid(*[np.arange(n, dtype=np.float64) for n in DIMS], indexing="ij")
    data = np.zeros(DIMS, dtype)
    for label, cx in enumerate(CENTRES, 1):
        r2 = (i - cx) ** 2 + (j - (DIMS[1] - 1) / 2) ** 2 + (k - (DIMS[2] - 1) / 2) ** 2
        data[r2 <= 5.5 ** 2] = label
    aff = np.diag([2.0, 2.0, 2.0, 1.0])
    aff[:3, 3] = [-(n - 1) for n in DIMS]
    path = u.write_nifti(os.path.join(d, name), data, aff)
    if lut:
        with open(os.path.join(d, "atlas_LUT.txt"), "w") as f:
            f.write(LUT)
    return path


def _scene(path=None):
    """The atlas (or `path`) at the origin, the camera on -Y; the import
    leaves the volume active."""
    scene = u.black_cycles_scene(SIZE)
    u.add_camera((0.0, -1.6, 0.0))
    ob = u.import_volume(path or _atlas())
    ob.voxlight.jitter = False
    return scene, ob


def _f12(scene, name):
    scene.render.filepath = os.path.join(u.TMP, name + ".png")
    bpy.ops.render.render(write_still=True)
    return u.load_png(scene.render.filepath)[..., :3]


@contextlib.contextmanager
def _reported(needle):
    """The operator run inside reports an ERROR saying `needle` (background
    mode turns ERROR reports into RuntimeError)."""
    with_error = []
    try:
        yield
    except RuntimeError as e:
        with_error.append(str(e))
    assert with_error and needle in with_error[0], with_error or "no error report"


@test
def an_atlas_imports_with_its_lookup_files_names_and_colours():
    scene, ob = _scene()
    s = ob.voxlight_labels
    assert s.enabled and s.mode == "surface", (s.enabled, s.mode)
    assert os.path.basename(s.lookup_file) == "atlas_LUT.txt", s.lookup_file
    assert [lab.name for lab in s.labels] == NAMES
    assert [lab.label_id for lab in s.labels] == [1, 2, 3]
    cols = np.array([tuple(lab.color) for lab in s.labels])
    assert np.allclose(cols, [(1, 0, 0, 1), (0, 1, 0, 1), (0, 0, 1, 1)]), cols
    assert all(lab.visible for lab in s.labels)
    assert _mod("label_ui").visible_count(s) == 3


@test
def hiding_a_region_in_f12_changes_exactly_its_pixels():
    scene, ob = _scene()
    before = _f12(scene, "labels_all")
    lit = before.max(axis=2) > 0.05
    hue = before.argmax(axis=2)  # 0 red, 1 green, 2 blue: the label's colour
    regions = [lit & (hue == c) for c in range(3)]
    for c, reg in enumerate(regions):
        assert reg.sum() > 40, (NAMES[c], reg.sum())
    # Blender Views Match Anatomy turns the scan 180 degrees about Z, so
    # scanner +x is world -x: from -Y the labels run blue, green, red.
    xs = [np.nonzero(reg)[1].mean() for reg in regions]
    assert xs[0] > xs[1] > xs[2], xs
    ob.voxlight_labels.labels[1].visible = False
    after = _f12(scene, "labels_hidden")
    changed = np.abs(after - before).max(axis=2) > 0.02
    green = regions[1]
    grown = green.copy()  # the region and its 1-pixel rim (antialiased edge)
    grown[1:] |= green[:-1]
    grown[:-1] |= green[1:]
    grown[:, 1:] |= grown[:, :-1].copy()
    grown[:, :-1] |= grown[:, 1:].copy()
    assert changed[green].mean() > 0.9, changed[green].mean()
    assert not (changed & ~grown).any(), np.argwhere(changed & ~grown)[:10]
    assert after[green].max() < 0.05, after[green].max()  # gone: the black world shows
    for c in (0, 2):  # the others stay within noise
        assert np.abs(after[regions[c]] - before[regions[c]]).max() < 0.02
    ob.voxlight_labels.labels[1].visible = True
    again = _f12(scene, "labels_shown")
    assert np.abs(again - before).max() < 0.02


@test
def a_labels_own_material_relights_only_its_region_in_f12():
    scene, ob = _scene()
    before = _f12(scene, "material_before")
    lit = before.max(axis=2) > 0.05
    hue = before.argmax(axis=2)
    regions = [lit & (hue == c) for c in range(3)]
    lab = ob.voxlight_labels.labels[0]  # Left-Red
    lab.use_material = True
    lab.ambient, lab.diffuse, lab.specular, lab.shininess = 1.0, 0.0, 0.0, 1.0
    lab.keyframe_insert("ambient", frame=1)  # animatable like every setting
    kw = _mod("params").look_kwargs(ob.voxlight)
    assert kw["labels"][1][0][3] == (1.0, 0.0, 0.0, 1.0), kw["labels"][1][0]
    after = _f12(scene, "material_flat")
    red = after[regions[0]][:, 0]
    # pure ambient: every pixel of the red ball at its colour, no shading left
    assert red.min() > 0.9 and red.max() - red.min() < 0.1, (red.min(), red.max())
    assert before[regions[0]][:, 0].max() - before[regions[0]][:, 0].min() > 0.2  # it was lit before
    for c in (1, 2):  # the other labels keep the volume's material
        assert np.abs(after[regions[c]] - before[regions[c]]).max() < 0.02
    lab.use_material = False
    ob.animation_data_clear()


@test
def labels_survive_save_and_reopen():
    scene, ob = _scene()
    ob.voxlight_labels.labels[0].visible = False
    before = _f12(scene, "reopen_before")
    (ob,) = u.reopen([ob], "labels.blend")
    s = ob.voxlight_labels
    assert [lab.name for lab in s.labels] == NAMES and not s.labels[0].visible
    after = _f12(bpy.context.scene, "reopen_after")
    assert before.max() > 0.3 and np.abs(after - before).max() < 0.02


@test
def hiding_a_label_changes_the_viewport_digest():
    scene, ob = _scene()
    params, native = _mod("params"), _mod("core.native")
    view, proj = np.eye(4), np.eye(4)
    proj[2, 3] = -1.0

    def digest():
        return native.params_digest(params.build(ob, 32, 32, view, proj))
    a, b = digest(), digest()
    assert a == b
    ob.voxlight_labels.labels[2].visible = False
    hidden = digest()
    ob.voxlight_labels.labels[2].visible = True
    ob.voxlight_labels.labels[2].color[3] = 0.5
    faded = digest()
    assert len({a, hidden, faded}) == 3
    ob.voxlight_labels.enabled = False
    assert "labels" not in params.look_kwargs(ob.voxlight)


@test
def label_colours_and_visibility_take_keyframes():
    scene, ob = _scene()
    lab = ob.voxlight_labels.labels[0]
    lab.color = (1.0, 0.0, 0.0, 1.0)
    lab.visible = True
    lab.keyframe_insert("color", frame=1)
    lab.keyframe_insert("visible", frame=1)
    lab.color = (0.0, 0.0, 1.0, 0.25)
    lab.visible = False
    lab.keyframe_insert("color", frame=10)
    lab.keyframe_insert("visible", frame=10)
    scene.frame_set(1)
    assert tuple(lab.color) == (1.0, 0.0, 0.0, 1.0) and lab.visible
    scene.frame_set(10)
    assert abs(lab.color[3] - 0.25) < 1e-6 and not lab.visible
    scene.frame_set(5)
    assert 0.25 < lab.color[3] < 1.0, lab.color[3]
    kw = _mod("params").look_kwargs(ob.voxlight)
    assert kw["labels"][1][0][1] == tuple(lab.color)
    ob.animation_data_clear()


@test
def a_missing_lookup_file_or_non_integer_file_is_reported_not_a_crash():
    u.reset_scene()
    bare = _atlas("bare", lut=False)
    n = len(bpy.data.objects)
    gone = os.path.join(u.TMP, "bare", "gone.txt")
    with _reported("no lookup file beside"):
        bpy.ops.voxlight.import_volume(filepath=bare, import_as="NEW")
    with _reported("gone.txt not found"):
        bpy.ops.voxlight.import_volume(filepath=bare, import_as="NEW", lookup_file=gone)
    floats = u.write_nifti(os.path.join(u.TMP, "atlas", "ct.nii"), u.phantom(16))
    with _reported("not label ids"):
        bpy.ops.voxlight.import_volume(filepath=floats, import_as="NEW",
                                       lookup_file=os.path.join(u.TMP, "atlas", "atlas_LUT.txt"))
    assert len(bpy.data.objects) == n, "a failed import left objects behind"
    # Without a lookup file, Detect imports an ordinary volume.
    ob = u.import_volume(bare)
    assert not ob.voxlight_labels.enabled
    # The panel's Load Lookup File with a missing file: reported, list kept.
    ob.voxlight_labels.lookup_file = gone
    with _reported("gone.txt not found"):
        bpy.ops.voxlight.load_label_lookup()
    assert ob.voxlight_labels.error and len(ob.voxlight_labels.labels) == 0
    # A label image that vanished: the frame renders without labels, the panel says why.
    s = ob.voxlight_labels
    s.filepath = os.path.join(u.TMP, "bare", "vanished.nii")
    s.enabled = True
    runtime = _mod("core.runtime")
    runtime.entry_for(ob.voxlight.filepath, ob.voxlight, 1)
    assert "vanished.nii" in _mod("core.label_runtime").failure(s.active_path)
    assert "labels" not in _mod("params").look_kwargs(ob.voxlight)


@test
def labels_attach_to_the_active_volume():
    scene, base = _scene(u.ball_file())
    plain = _f12(scene, "attach_before")
    n = len(bpy.data.objects)
    assert bpy.ops.voxlight.import_volume(filepath=_atlas(), import_as="ATTACH") == {"FINISHED"}
    assert len(bpy.data.objects) == n  # no new object
    s = base.voxlight_labels
    assert s.enabled and s.mode == "tint" and [lab.name for lab in s.labels] == NAMES
    tinted = _f12(scene, "attach_tint")
    assert np.abs(tinted - plain).max() > 0.05  # the label colours show
    s.enabled = False
    assert np.abs(_f12(scene, "attach_off") - plain).max() < 0.02


_Layout = u.Layout  # a stand-in UILayout that lists what a panel draws


def _draw_panel(ob):
    layout = _Layout()
    ctx = types.SimpleNamespace(object=ob, scene=bpy.context.scene)
    bpy.types.VOXLIGHT_PT_volume_labels.draw(types.SimpleNamespace(layout=layout), ctx)
    return layout.drawn


@test
def the_labels_panel_lists_them_and_show_hide_all_counts():
    scene, ob = _scene()
    drawn = _draw_panel(ob)
    for want in ("filepath", "lookup_file", "mode", "boundary", "VOXLIGHT_UL_labels", "voxlight.load_label_lookup",
                 "voxlight.label_visibility", "3 of 3 labels visible"):
        assert want in drawn, (want, drawn)
    layout = _Layout()
    bpy.types.VOXLIGHT_UL_labels.draw_item(None, bpy.context, layout, ob.voxlight_labels,
                                           ob.voxlight_labels.labels[1], 0, None, "", 1)
    row = layout.drawn
    assert row.count("color") == 2 and "visible" in row and "Middle-Green" in row, row
    # smooth boundaries by default, the raw voxels on request, passed to the library and animatable
    s = ob.voxlight_labels
    assert s.boundary == "smooth"
    assert _mod("label_props").look_kwargs(ob.voxlight)["labels"][2] == "smooth"
    s.boundary = "voxels"
    assert _mod("label_props").look_kwargs(ob.voxlight)["labels"][2] == "voxels"
    assert s.keyframe_insert("boundary", frame=1)
    s.boundary = "smooth"
    assert bpy.ops.voxlight.label_visibility(visible=False) == {"FINISHED"}
    assert "0 of 3 labels visible" in _draw_panel(ob)
    assert bpy.ops.voxlight.label_visibility(visible=True) == {"FINISHED"}
    assert all(lab.visible for lab in ob.voxlight_labels.labels)


u.run("test_labels")
