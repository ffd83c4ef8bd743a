"""The bpy-free add-on parts: the importer's label decisions
(core/label_import.py), the label volume on a renderer
(core/label_runtime.py) and the params digest seeing the label list
(native_tiles.params_digest)."""
import ctypes

import numpy as np

from nifti_write import write_nifti
from voxlight.core import label_import, label_runtime, native
from voxlight.core.native_abi import LabelEntry, LabelStyle, _sized


def _exists_only(*names):
    return lambda p: any(p.endswith("/" + n) for n in names)


def test_auto_imports_labels_only_with_a_lookup_file_beside():
    assert label_import.plan("AUTO", "/d/aal.nii.gz", exists=_exists_only("aal.nii.txt")) == \
        ("new", "/d/aal.nii.txt")
    assert label_import.plan("AUTO", "/d/ct.nii.gz", exists=_exists_only()) == ("intensity", "")
    assert label_import.plan("INTENSITY", "/d/aal.nii", exists=_exists_only("aal.nii.txt")) == \
        ("intensity", "")


def test_explicit_choices_and_a_chosen_lookup_file():
    assert label_import.plan("ATTACH", "/d/seg.nii", exists=_exists_only("seg_LUT.txt")) == \
        ("attach", "/d/seg_LUT.txt")
    assert label_import.plan("NEW", "/d/seg.nii", "/x/my.ctbl", exists=_exists_only()) == \
        ("new", "/x/my.ctbl")
    assert label_import.plan("NEW", "/d/seg.nii", exists=_exists_only()) == ("new", "")


def test_check_reports_float_data_negative_ids_and_a_missing_lookup_file():
    yes = _exists_only("seg.txt")
    assert label_import.check("new", "NEW", "uint16", "/d/seg.txt", "/d/seg.nii", yes) == ("new", "")
    kind, err = label_import.check("new", "NEW", "float32", "/d/seg.txt", "/d/seg.nii", yes)
    assert "float32" in err and "not label ids" in err
    # AUTO quietly falls back to an intensity volume instead.
    assert label_import.check("new", "AUTO", "float32", "/d/seg.txt", "/d/seg.nii", yes) == ("intensity", "")
    kind, err = label_import.check("new", "NEW", "int16", "/d/seg.txt", "/d/seg.nii", yes,
                                   value_range=(-1024, 3000))
    assert "-1024" in err
    assert label_import.check("new", "AUTO", "int16", "/d/seg.txt", "/d/seg.nii", yes,
                              value_range=(-1024, 3000)) == ("intensity", "")
    kind, err = label_import.check("attach", "ATTACH", "uint8", "", "/d/seg.nii", yes)
    assert "no lookup file beside seg.nii" in err
    kind, err = label_import.check("new", "NEW", "uint8", "/d/gone.txt", "/d/seg.nii", yes)
    assert "gone.txt not found" in err
    assert label_import.check("intensity", "AUTO", "float32", "", "/d/x.nii") == ("intensity", "")


class _Renderer:
    def __init__(self):
        self.calls = []

    def set_labels(self, vol):
        self.calls.append(None if vol is None else tuple(vol.info["dims"]))


class _Entry:
    def __init__(self):
        self.renderer = _Renderer()


def test_show_sets_the_label_volume_once_and_removes_it(tmp_path):
    p = str(tmp_path / "seg.nii")
    write_nifti(p, np.arange(4 * 5 * 6, dtype=np.uint8).reshape(4, 5, 6) % 3)
    e = _Entry()
    assert label_runtime.show(e, "") == "" and e.renderer.calls == []  # no labels: untouched
    assert label_runtime.show(e, p) == ""
    assert label_runtime.show(e, p) == ""  # already there
    assert e.renderer.calls == [(4, 5, 6)] and e.label_key[0] == p
    label_runtime.show(e, "")
    assert e.renderer.calls == [(4, 5, 6), None] and e.label_key is None


def test_a_missing_label_file_is_remembered_and_not_drawn(tmp_path):
    p = str(tmp_path / "missing.nii")
    e = _Entry()
    err = label_runtime.show(e, p)
    assert err and "missing.nii" in err
    assert label_runtime.failure(p) == err and not label_runtime.usable(p)
    assert e.renderer.calls == [] and e.label_key is None
    assert label_runtime.show(e, p) == err  # not retried every redraw
    write_nifti(p, np.ones((3, 3, 3), np.uint8))
    assert label_runtime.usable(p)  # the file appeared: tried again
    assert label_runtime.show(e, p) == "" and e.renderer.calls == [(3, 3, 3)]


def _with_labels(p, entries, mode=0):
    arr = (LabelEntry * len(entries))()
    for a, (i, rgba, vis) in zip(arr, entries):
        a.struct_size = ctypes.sizeof(LabelEntry)
        a.id, a.color[:], a.visible = i, rgba, int(vis)
    style = _sized(LabelStyle)
    style.mode, style.entry_count, style.entries = mode, len(entries), arr
    p._label_keep = (arr, style)
    p.labels = ctypes.pointer(style)
    return p


def test_the_digest_sees_the_label_list_not_its_address():
    base = native.params_digest(native.make_params(width=8, height=8))
    rows = [(1, (1, 0, 0, 1), True), (2, (0, 1, 0, 1), True)]
    a = native.params_digest(_with_labels(native.make_params(width=8, height=8), rows))
    b = native.params_digest(_with_labels(native.make_params(width=8, height=8), list(rows)))
    hidden = native.params_digest(_with_labels(native.make_params(width=8, height=8),
                                               [rows[0], (2, (0, 1, 0, 1), False)]))
    faded = native.params_digest(_with_labels(native.make_params(width=8, height=8),
                                              [rows[0], (2, (0, 1, 0, 0.5), True)]))
    tint = native.params_digest(_with_labels(native.make_params(width=8, height=8), rows, mode=2))
    assert a == b
    assert len({base, a, hidden, faded, tint}) == 5


def test_the_info_line_of_a_label_map_counts_its_labels():
    assert label_import.values_line(0, 116, "MR (arbitrary units)", 116) == "label map, 116 labels"
    assert label_import.values_line(0, 1, "MR (arbitrary units)", 1) == "label map, 1 label"
    assert label_import.values_line(-1024, 3071, "CT (Hounsfield units)") == "Values -1024 .. 3071, CT (Hounsfield units)"
    assert label_import.values_line(0, 1.5, "") == "Values 0 .. 1.5"
    # AAL: 116 non-zero ids beside the background, or 116 entries listed
    assert label_import.label_count(0, ids=list(range(117))) == 116
    assert label_import.label_count(116) == 116
    assert label_import.label_count(0, data_max=116) == 116
