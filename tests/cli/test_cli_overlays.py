"""`voxlight render INPUT --overlay FILE[:PRESET][:LO:HI]`: up to
three more volumes, each in its own grid and affine, in the base's ray
march, with --overlay-blend and --overlay-opacity for the overlay given
last; their errors. Through an orthographic view down z with one pixel per
world millimetre (--view z --ortho --size NXxNY over a base of 1 mm voxels
at the origin), an overlay's box covers exactly the pixels its affine
says."""
import sys
from pathlib import Path

import numpy as np
import pytest

from test_cli import assert_clean_error, png_rgba, run, write_nifti

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "python"))
from nifti_write import write_nifti as write_nifti_affine  # noqa: E402  (with an sform)

NX, NY, NZ = 24, 20, 16
VIEW = ["--preset", "gray", "--window", "0:255", "--no-jitter", "--ortho", "--view", "z",
        "--size", "%dx%d" % (NX, NY), "--no-shading"]


def footprint(x0, x1, y0, y1):
    """(h, w) mask of pixel columns x0..x1 and rows y0..y1 (inclusive), row 0 = bottom."""
    m = np.zeros((NY, NX), bool)
    m[y0:y1 + 1, x0:x1 + 1] = True
    return m


def affine(tx, ty, tz, scale=1.0):
    a = np.diag([scale, scale, scale, 1.0])
    a[:3, 3] = tx, ty, tz
    return a


@pytest.fixture
def files(tmp_path):
    """An empty base (zeros: clear under the grey preset), a uniform base
    (value 60), and a 4^3 block with 2 mm voxels from world (6.5, 4.5, 5): its
    box covers x 5.5..13.5 and y 3.5..11.5, pixel columns 6..13, rows 4..11.
    Its far half along z is 255, the near half 0, so every column of the view
    down z sees both and the auto preset has a data range to work with."""
    empty = tmp_path / "empty.nii"
    write_nifti(empty, np.zeros((NZ, NY, NX), np.uint8))
    grey = tmp_path / "grey.nii"
    write_nifti(grey, np.full((NZ, NY, NX), 60, np.uint8))
    block = tmp_path / "block.nii"
    data = np.zeros((4, 4, 4), np.uint8)  # [i, j, k]
    data[:, :, 2:] = 255
    write_nifti_affine(str(block), data, affine(6.5, 4.5, 5.0, 2.0))
    return empty, grey, block


def render(tmp_path, base, *args, name="out.png"):
    out = tmp_path / name
    res = run("render", base, "-o", out, *VIEW, *args)
    assert res.returncode == 0, res.stderr
    return png_rgba(out)[::-1].astype(int)  # (y, x, 4), row 0 = bottom = world y 0


def test_an_overlay_lands_where_its_affine_says(tmp_path, files):
    empty, _grey, block = files
    without = render(tmp_path, empty, name="without.png")
    assert without[..., 3].max() == 0
    img = render(tmp_path, empty, "--overlay", "%s:gray:0:255" % block)
    a = img[..., 3]
    assert (a[footprint(6, 13, 4, 11)] > 50).all(), a
    assert (a[~footprint(5, 14, 3, 12)] == 0).all()  # nothing beyond its box's edge pixels


def test_preset_and_window_choose_the_overlays_colours(tmp_path, files):
    empty, _grey, block = files
    inside = footprint(7, 12, 5, 10)
    grey = render(tmp_path, empty, "--overlay", "%s:gray:0:255" % block, name="g.png")
    px = grey[inside]
    assert (np.abs(px[:, 0] - px[:, 1]) <= 2).all()  # grey
    hot = render(tmp_path, empty, "--overlay", "%s:hot" % block, name="h.png")
    assert np.abs(hot[inside] - grey[inside]).max() > 20
    # a window above the data: the block classifies as the table's first entry
    faint = render(tmp_path, empty, "--overlay", "%s:gray:1000:2000" % block, name="f.png")
    assert (faint[..., 3] < grey[..., 3]).any() or np.abs(faint - grey).max() > 20
    # the window alone, with the auto preset
    alone = render(tmp_path, empty, "--overlay", "%s:0:255" % block, name="w.png")
    assert (alone[..., 3][inside] > 0).all()


def test_blends_and_opacity_reach_the_frame(tmp_path, files):
    _empty, grey, block = files
    inside = footprint(7, 12, 5, 10)
    plain = render(tmp_path, grey, name="plain.png")
    imgs = {b: render(tmp_path, grey, "--overlay", "%s:hot" % block, "--overlay-blend", b, name=b + ".png")
            for b in ("over", "add", "max")}
    for b, img in imgs.items():
        assert np.abs(img[inside] - plain[inside]).max() > 20, b
        assert np.abs(img[~footprint(5, 14, 3, 12)] - plain[~footprint(5, 14, 3, 12)]).max() <= 1, b
    assert np.abs(imgs["add"][inside] - imgs["max"][inside]).max() > 10
    assert np.array_equal(render(tmp_path, grey, "--overlay", "%s:hot" % block, name="d.png"), imgs["over"])
    faint = render(tmp_path, grey, "--overlay", "%s:hot" % block, "--overlay-opacity", "0.05", name="o.png")
    assert np.abs(faint[inside] - plain[inside]).mean() < np.abs(imgs["over"][inside] - plain[inside]).mean()


def test_three_overlays_each_with_its_own_blend(tmp_path, files):
    empty, _grey, block = files
    other = tmp_path / "other.nii"
    data = np.zeros((2, 2, 2), np.uint8)
    data[:, :, 1] = 255
    write_nifti_affine(str(other), data, affine(18.5, 14.5, 5.0))
    img = render(tmp_path, empty, "--overlay", block, "--overlay-blend", "max",
                 "--overlay", "%s:hot" % other, "--overlay-opacity", "2",
                 "--overlay", block, "--overlay-blend", "add")
    a = img[..., 3]
    assert (a[footprint(6, 13, 4, 11)] > 0).all()
    assert (a[footprint(18, 19, 14, 15)] > 0).all()
    assert (a[~(footprint(5, 14, 3, 12) | footprint(17, 20, 13, 16))] == 0).all()


def test_a_file_name_with_a_colon_is_taken_whole(tmp_path, files):
    empty, _grey, block = files
    odd = tmp_path / "scan:2.nii"
    odd.write_bytes(block.read_bytes())
    a = render(tmp_path, empty, "--overlay", odd)[..., 3]
    b = render(tmp_path, empty, "--overlay", block, name="b.png")[..., 3]
    assert np.array_equal(a, b) and a.max() > 0


@pytest.mark.parametrize("spec, words", [
    ("{block}:glow", ["unknown preset 'glow'", "hot"]),
    ("{block}:hot:5:5", ["bad window", "LO != HI"]),
    ("{block}:hot:a:9", ["bad window"]),
    ("{block}:hot:1:2:3", ["FILE[:PRESET][:LO:HI]"]),
    ("{tmp}/missing.nii", ["missing.nii"]),
    ("{tmp}/missing.nii:hot", ["missing.nii"]),
])
def test_bad_overlays_are_one_clean_error(tmp_path, files, spec, words):
    spec = spec.format(block=files[2], tmp=tmp_path)
    assert_clean_error(run("render", files[0], "-o", tmp_path / "x.png", *VIEW, "--overlay", spec), *words)
    assert not (tmp_path / "x.png").exists()


@pytest.mark.parametrize("args, words", [
    (["--overlay-blend", "add"], ["--overlay-blend", "must follow"]),
    (["--overlay-opacity", "0.5"], ["--overlay-opacity", "must follow"]),
    (["--overlay", "{block}", "--overlay-blend", "glow"], ["glow", "over, add, max"]),
    (["--overlay", "{block}", "--overlay-opacity", "0"], ["--overlay-opacity"]),
    (["--overlay", "{block}", "--overlay-opacity", "x"], ["--overlay-opacity"]),
    (["--overlay", "{block}"] * 4, ["more than 3 --overlay"]),
    (["--overlay"], ["--overlay needs a value"]),
    (["--overlay", "{block}", "--mode", "mip"], ["overlay"]),
])
def test_bad_overlay_options_are_one_clean_error(tmp_path, files, args, words):
    args = [a.format(block=files[2]) for a in args]
    assert_clean_error(run("render", files[0], "-o", tmp_path / "x.png", *VIEW, *args), *words)


def test_usage_names_the_overlay_options():
    res = run("--help")
    assert res.returncode == 0
    for w in ("--overlay FILE[:PRESET][:LO:HI]", "--overlay-blend", "--overlay-opacity"):
        assert w in res.stdout, w
