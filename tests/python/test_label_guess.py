"""The importer's Detect (AUTO) guess between an intensity volume and a
label map (core/label_import.guess): labels only when integer data meet a
lookup file that names most of their values, a file named after the image
counting for more than a folder-wide table. Files are real NIfTIs read by
the library, lookup files real tables read by vxl_label_table_load."""

import os

import numpy as np

from nifti_write import write_nifti
from voxlight.core import label_import, native


def _sphere(n=48):
    """An intensity uint8 ball: values fall from 255 at the centre to 0 at
    radius n/2 - 2, so it has well over a hundred distinct values."""
    c = (n - 1) / 2.0
    x, y, z = np.meshgrid(*[np.arange(n) - c] * 3, indexing="ij")
    r = np.sqrt(x * x + y * y + z * z)
    rad = n / 2.0 - 2
    return (np.clip(255 * (1 - r / rad), 0, 255) * (r < rad)).astype(np.uint8)


def _segmentation(n=32, labels=6):
    data = np.zeros((n, n, n), np.uint8)
    for i in range(labels):
        data[4 + 4 * i:8 + 4 * i, 4:28, 4:28] = i + 1
    return data


def _table(path, ids):
    with open(path, "w") as f:
        for i in ids:
            f.write("%d region_%d\n" % (i, i))
    return path


def _guess(image, chosen=""):
    with native.Volume.load(image) as vol:
        info = vol.info
        ids = label_import.distinct_ids(info, vol.histogram)
    return label_import.guess(info["dtype"], ids, label_import.candidates(image, chosen),
                              _read_ids)


def _read_ids(path):
    try:
        return [t["id"] for t in native.load_label_table(path)]
    except native.VoxlightError:
        return None


def test_an_intensity_volume_beside_a_small_folder_wide_labels_txt_is_intensity(tmp_path):
    image = write_nifti(str(tmp_path / "sphere.nii.gz"), _sphere())
    _table(str(tmp_path / "labels.txt"), (1, 2, 3))  # a table for another image
    kind, lookup, why = _guess(image)
    assert (kind, lookup) == ("intensity", ""), why
    assert "labels.txt (folder-wide) names 3 of its" in why and "under 90%" in why, why


def test_a_segmentation_named_by_a_folder_wide_table_is_a_label_map(tmp_path):
    image = write_nifti(str(tmp_path / "aseg.nii.gz"), _segmentation())
    table = _table(str(tmp_path / "labels.txt"), range(1, 40))
    assert _guess(image)[:2] == ("new", table)


def test_a_file_named_after_the_image_needs_only_most_of_its_ids(tmp_path):
    """Five of six ids named: enough for aseg.txt, not for labels.txt."""
    image = write_nifti(str(tmp_path / "aseg.nii.gz"), _segmentation())
    folder = _table(str(tmp_path / "labels.txt"), range(1, 6))
    kind, _lookup, why = _guess(image)
    assert kind == "intensity" and "names 5 of its 6 values" in why, why
    own = _table(str(tmp_path / "aseg.txt"), range(1, 6))
    kind, lookup, why = _guess(image)
    assert (kind, lookup) == ("new", own), why
    assert "named after it" in why
    os.remove(own)
    # A table the user chose counts as made for the image.
    assert _guess(image, chosen=folder)[:2] == ("new", folder)


def test_float_data_and_no_table_are_intensity_and_say_why(tmp_path):
    image = write_nifti(str(tmp_path / "ball.nii.gz"), _sphere().astype(np.float32))
    _table(str(tmp_path / "ball.txt"), range(1, 256))
    kind, _lookup, why = _guess(image)
    assert kind == "intensity" and "float32" in why, why
    os.remove(str(tmp_path / "ball.txt"))
    image = write_nifti(str(tmp_path / "seg.nii.gz"), _segmentation())
    kind, _lookup, why = _guess(image)
    assert kind == "intensity" and why == "no lookup file beside it", why


def test_distinct_ids_are_the_values_present():
    seen = {}

    def histogram(bins, lo, hi):
        seen["args"] = (bins, lo, hi)
        counts = np.zeros(bins, np.int64)
        counts[[0, 3, 9]] = 7
        return counts

    info = {"dtype": "uint16", "value_min": 10, "value_max": 19}
    assert label_import.distinct_ids(info, histogram) == [10, 13, 19]
    assert seen["args"] == (10, 9.5, 19.5)
    assert label_import.distinct_ids(dict(info, dtype="float32"), histogram) is None
    assert label_import.distinct_ids(dict(info, value_min=-1), histogram) is None
