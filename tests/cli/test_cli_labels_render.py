"""`voxlight render INPUT --labels LABELS`: the label image drawn
with its lookup file (given, found beside it, or a palette), --label-mode,
--hide-labels and --label-opacity; their errors. Through an orthographic
view down z with one pixel per voxel (--view z --ortho --size NXxNY), a
pixel is a voxel column, so each label's columns can be read off the image."""
import numpy as np
import pytest

from test_cli import assert_clean_error, png_rgba, run, write_nifti

NX, NY, NZ = 24, 20, 16
VIEW = ["--preset", "gray", "--window", "0:255", "--no-jitter", "--ortho", "--view", "z",
        "--size", "%dx%d" % (NX, NY), "--no-shading"]


def column_ids():
    """(y, x) the label of each column: 3 x 4 blocks of 6 x 5 voxels, id 1..12; x >= 18 unlabelled."""
    y, x = np.mgrid[0:NY, 0:NX]
    ids = 1 + x // 6 + 3 * (y // 5)
    ids[x >= 18] = 0
    return ids


@pytest.fixture
def files(tmp_path):
    vol = tmp_path / "ct.nii"
    write_nifti(vol, np.full((NZ, NY, NX), 200, np.uint8))
    lab = np.zeros((NZ, NY, NX), np.int16)
    lab[4:12] = column_ids()[None]
    labels = tmp_path / "seg.nii"
    write_nifti(labels, lab)
    return vol, labels


def render(tmp_path, vol, *args, name="out.png"):
    out = tmp_path / name
    res = run("render", vol, "-o", out, *VIEW, *args)
    assert res.returncode == 0, res.stderr
    return png_rgba(out)[::-1].astype(int)  # (y, x, 4), row 0 = bottom = voxel y 0


def inner(ids):
    """Columns away from block edges (the smooth boundary rounds the corners)."""
    y, x = np.mgrid[0:NY, 0:NX]
    return (x % 6 != 0) & (x % 6 != 5) & (y % 5 != 0) & (y % 5 != 4)


def test_palette_draws_every_nonzero_label(tmp_path, files):
    img = render(tmp_path, *files[:1], "--labels", files[1])
    ids = column_ids()
    keep = inner(ids)
    assert (img[..., 3][keep & (ids > 0)] == 255).all()
    assert (img[..., 3][ids == 0] == 0).all()
    # neighbouring labels get different colours
    c1, c2 = img[2, 2, :3], img[2, 8, :3]
    assert np.abs(c1 - c2).max() > 30


def test_hide_labels_and_label_opacity(tmp_path, files):
    ids = column_ids()
    keep = inner(ids)
    img = render(tmp_path, files[0], "--labels", files[1], "--hide-labels", "2,5", "--label-opacity", "3:0.5")
    a = img[..., 3]
    assert (a[keep & np.isin(ids, [2, 5])] == 0).all()
    assert (abs(a[keep & (ids == 3)] - 128) <= 1).all()
    assert (a[keep & np.isin(ids, [1, 4, 6, 12])] == 255).all()


def test_lookup_file_beside_the_labels_gives_the_colours(tmp_path, files):
    lut = files[1].with_suffix(".label")  # seg.label beside seg.nii
    lut.write_text('    1   255    0    0  1  1  1  "red"\n    2     0    0  255  1  1  1  "blue"\n')
    img = render(tmp_path, files[0], "--labels", files[1])
    ids, keep = column_ids(), inner(column_ids())
    assert (img[keep & (ids == 1)][:, :4] == [255, 0, 0, 255]).all()
    assert (img[keep & (ids == 2)][:, :4] == [0, 0, 255, 255]).all()
    assert (img[..., 3][np.isin(ids, [0, 3, 4, 5])] == 0).all()  # not in the table: hidden
    # --label-lut wins over the file beside
    other = tmp_path / "other.label"
    other.write_text('    3     0  255    0  1  1  1  "green"\n')
    img = render(tmp_path, files[0], "--labels", files[1], "--label-lut", other, name="o.png")
    assert (img[keep & (ids == 3)][:, :4] == [0, 255, 0, 255]).all()
    assert (img[..., 3][ids == 1] == 0).all()


def test_mask_and_tint_modes(tmp_path, files):
    lut = tmp_path / "t.label"
    lut.write_text('    1   255    0    0  1  1  1  "red"\n    2     0  255    0  1  0  1  "hidden"\n')
    ids, keep = column_ids(), inner(column_ids())
    mask = render(tmp_path, files[0], "--labels", files[1], "--label-lut", lut, "--label-mode", "mask")
    assert (mask[..., 3][keep & (ids == 1)] > 0).all()
    assert (mask[..., 3][keep & (ids != 1)] == 0).all()
    tint = render(tmp_path, files[0], "--labels", files[1], "--label-lut", lut, "--label-mode", "tint", name="t.png")
    px = tint[keep & (ids == 1)]
    assert (px[:, 1] == 0).all() and (px[:, 2] == 0).all() and (px[:, 0] > 0).all()


@pytest.mark.parametrize("args, words", [
    (["--label-mode", "glow"], ["glow"]),
    (["--hide-labels", "99"], ["--hide-labels", "99"]),
    (["--label-opacity", "3:2"], ["--label-opacity"]),
    (["--label-opacity", "3"], ["--label-opacity"]),
])
def test_bad_label_options_are_one_clean_error(tmp_path, files, args, words):
    res = run("render", files[0], "-o", tmp_path / "x.png", *VIEW, "--labels", files[1], *args)
    assert_clean_error(res, *words)


def test_label_options_need_labels_and_an_integer_image(tmp_path, files):
    assert_clean_error(run("render", files[0], "-o", tmp_path / "x.png", *VIEW, "--hide-labels", "1"), "--labels")
    res = run("render", files[0], "-o", tmp_path / "x.png", *VIEW, "--labels", tmp_path / "missing.nii")
    assert_clean_error(res, "missing.nii")
    fl = tmp_path / "float.nii"
    write_nifti(fl, np.zeros((NZ, NY, NX), np.float32))
    assert_clean_error(run("render", files[0], "-o", tmp_path / "x.png", *VIEW, "--labels", fl), "integers")
