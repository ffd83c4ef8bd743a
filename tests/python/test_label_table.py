"""Label lookup tables through the binding (native_volume.load_label_table,
vxl_label_table_load) and the bpy-free finder of lookup files beside a
label image (plugin/core/label_files.py)."""
import os

import pytest

from voxlight.core import label_files
from voxlight.core.native_abi import VoxlightError
from voxlight.core.native_volume import load_label_table

MRICRON = "/usr/share/mricron/templates"


def close(a, b):
    return all(abs(x - y) < 1e-6 for x, y in zip(a, b))


def test_freesurfer_lut_reads_transparency_as_255_minus_alpha(tmp_path):
    p = tmp_path / "FreeSurferColorLUT.txt"
    p.write_text("#No. Label Name: R G B A\n17 Left-Hippocampus 220 216 20 0\n0 Unknown 0 0 0 0\n"
                 "4 Left-Lateral-Ventricle 120 18 134 255\n")
    labels = load_label_table(str(p))
    assert [e["id"] for e in labels] == [0, 4, 17]
    assert labels[2]["name"] == "Left-Hippocampus"
    assert close(labels[2]["color"], (220 / 255, 216 / 255, 20 / 255, 1.0))
    assert labels[1]["color"][3] == 0.0
    assert all(e["visible"] for e in labels)


def test_slicer_ctbl_and_itksnap_opacity_and_visibility(tmp_path):
    ctbl = tmp_path / "seg.ctbl"
    ctbl.write_text("# Color table file x\n# 2 values\n0 Background 0 0 0 0\n1 liver 221 130 101 128\n")
    liver = load_label_table(str(ctbl))[1]
    assert liver["name"] == "liver" and close(liver["color"], (221 / 255, 130 / 255, 101 / 255, 128 / 255))
    snap = tmp_path / "seg.label"
    snap.write_text("# ITK-SnAP Label Description File\n"
                    '    0     0    0    0        0  0  0    "Clear Label"\n'
                    '    3    10   20   30     0.25  0  1    "Right kidney"\n')
    labels = load_label_table(str(snap))
    assert [(e["id"], e["name"], e["visible"]) for e in labels] == [(0, "Clear Label", False),
                                                                   (3, "Right kidney", False)]
    assert close(labels[1]["color"], (10 / 255, 20 / 255, 30 / 255, 0.25))


def test_mricron_pair_and_names_alone(tmp_path):
    palette = bytes(range(256)) + bytes(255 - i for i in range(256)) + bytes((3 * i) & 255 for i in range(256))
    (tmp_path / "atlas.nii.lut").write_bytes(palette)
    (tmp_path / "atlas.nii.txt").write_text("5 Five 9005\r\n9\tNine\r\n")
    for name in ("atlas.nii.lut", "atlas.nii.txt"):
        labels = load_label_table(str(tmp_path / name))
        assert [(e["id"], e["name"]) for e in labels] == [(5, "Five"), (9, "Nine")]
        assert close(labels[0]["color"], (5 / 255, 250 / 255, 15 / 255, 1.0))
    (tmp_path / "alone.txt").write_text("0 Zero\n")
    zero = load_label_table(str(tmp_path / "alone.txt"))[0]
    assert close(zero["color"], (0.95, 0.3325, 0.3325, 1.0))  # the documented default palette


def test_bad_files_raise_with_the_file_and_line(tmp_path):
    dup = tmp_path / "dup.txt"
    dup.write_text("1 A 1 2 3 0\n1 B 1 2 3 0\n")
    with pytest.raises(VoxlightError) as err:
        load_label_table(str(dup))
    assert "dup.txt" in str(err.value) and "line 2 repeats line 1" in str(err.value)
    cut = tmp_path / "cut.lut"
    cut.write_bytes(bytes([0, 1, 2, 200]) * 100)
    with pytest.raises(VoxlightError, match="768"):
        load_label_table(str(cut))
    with pytest.raises(VoxlightError, match="no_such"):
        load_label_table(str(tmp_path / "no_such.txt"))


def test_real_aal_atlas_found_and_read():
    image = os.path.join(MRICRON, "aal.nii.gz")
    assert os.path.isfile(image), "mricron-data is installed by build.sh"
    found = label_files.find_lookup_files(image)
    assert found[:2] == [os.path.join(MRICRON, "aal.nii.lut"), os.path.join(MRICRON, "aal.nii.txt")]
    labels = load_label_table(found[0])
    assert len(labels) == 116 and labels[0]["name"] == "Precentral_L" and labels[-1]["id"] == 116
    assert labels[0]["color"] == labels[1]["color"]  # left and right share a colour in aal.nii.lut


def test_image_stems():
    assert label_files.image_stems("/d/aal.nii.gz") == ["aal.nii", "aal"]
    assert label_files.image_stems("/d/aseg.mgz") == ["aseg.mgz", "aseg"]
    assert label_files.image_stems("Seg.seg.nrrd") == ["Seg.seg.nrrd", "Seg.seg", "Seg"]
    assert label_files.image_stems("/d/LABELS.NII") == ["LABELS.NII", "LABELS"]


def test_candidates_in_priority_order(tmp_path):
    image = tmp_path / "seg.nii.gz"
    names = [os.path.basename(p) for p in label_files.candidate_lookup_files(str(image))]
    # the most specific stem first, .lut before .txt, folder-wide tables last
    assert names[:4] == ["seg.nii.lut", "seg.nii.txt", "seg.nii.ctbl", "seg.nii.label"]
    assert names.index("seg.nii.label") < names.index("seg.lut") < names.index("segLUT.txt")
    assert names.index("seg_ColorTable.ctbl") < names.index("FreeSurferColorLUT.txt")
    assert names[-5:] == list(label_files.FOLDER_NAMES)
    assert len(names) == len(set(names))
    assert all(os.path.dirname(p) == str(tmp_path) for p in label_files.candidate_lookup_files(str(image)))


def test_find_keeps_only_existing_files_in_order(tmp_path):
    image = tmp_path / "aseg.mgz"
    image.write_bytes(b"")
    for name in ("FreeSurferColorLUT.txt", "aseg.ctbl", "aseg_LUT.txt", "unrelated.lut"):
        (tmp_path / name).write_text("1 A 1 2 3 0\n")
    found = [os.path.basename(p) for p in label_files.find_lookup_files(str(image))]
    assert found == ["aseg.ctbl", "aseg_LUT.txt", "FreeSurferColorLUT.txt"]
    assert label_files.find_lookup_files(str(tmp_path / "none.nii")) == \
        [str(tmp_path / "FreeSurferColorLUT.txt")]
    assert label_files.find_lookup_files(str(image), exists=lambda p: False) == []
