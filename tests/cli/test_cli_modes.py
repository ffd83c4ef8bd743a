"""The CLI's options: --mode, --iso-value, --matcap, --ortho and
--view. Through an orthographic axis view whose pixels are one voxel wide
(--view z --ortho --size NXxNY), MIP, MinIP and average equal numpy's max,
min and mean along that axis; ISO covers exactly the ball it should; a MatCap
colours each side of it by its half of the picture; bad values are clean
errors."""
import struct
import zlib

import numpy as np
import pytest

from test_cli import assert_clean_error, ball, png_rgba, run, write_nifti  # noqa: F401 (ball: a fixture)

NZ, NY, NX = 10, 12, 14


def write_png(path, rgb):
    """An 8-bit RGB PNG of rgb (h, w, 3) uint8, the first row on top."""
    h, w, _ = rgb.shape
    raw = b"".join(b"\0" + rgb[y].astype(np.uint8).tobytes() for y in range(h))

    def chunk(typ, data):
        return struct.pack(">I", len(data)) + typ + data + struct.pack(">I", zlib.crc32(typ + data))

    path.write_bytes(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
                     + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))


@pytest.fixture
def noise(tmp_path):
    """uint8 noise, (z, y, x), identity affine (voxel = world)."""
    data = (np.random.default_rng(19).integers(1, 64, (NZ, NY, NX)) * 4).astype(np.uint8)
    path = tmp_path / "noise.nii"
    write_nifti(path, data)
    return path, data.astype(float)


# test_cli's ball: 200 / (1 + exp(r - 8)) about the centre of 24^3 voxels, so
# 100 at r = 8; RHO[y, x] is a pixel's distance from the axis of a z view.
RHO = np.hypot(*np.mgrid[0:24, 0:24] - 11.5)


# The grey preset's colour is the windowed value: with the window 0:255 an
# 8-bit voxel's value comes back as the pixel's (straight) red.
GREY = ["--preset", "gray", "--window", "0:255", "--no-jitter", "--step", "0.5", "--ortho"]


def project(tmp_path, path, mode, view, w, h):
    out = tmp_path / ("%s_%s.png" % (mode, view.replace("-", "m")))
    res = run("render", path, "-o", out, "--size", "%dx%d" % (w, h), "--mode", mode, "--view", view, *GREY)
    assert res.returncode == 0, res.stderr
    return png_rgba(out)[::-1, :, 0].astype(float)  # row 0 = bottom: image y = world up


@pytest.mark.parametrize("mode", ["mip", "minip", "average"])
def test_projections_equal_numpy_along_the_axis(tmp_path, noise, mode):
    path, data = noise
    reduce = {"mip": np.max, "minip": np.min, "average": np.mean}[mode]
    # view z: +x right, +y up, looking down z; view x: +y right, +z up
    for view, axis, w, h in [("z", 0, NX, NY), ("x", 2, NY, NZ)]:
        got = project(tmp_path, path, mode, view, w, h)
        want = reduce(data, axis=axis)  # z: (y, x); x: (z, y), rows up the image, columns to its right
        tol = 1.01
        if mode == "average":  # step-0.5 samples weigh the end voxels by 3/4 and 1/4 (docs/modes.md)
            n = data.shape[axis]
            ends = np.abs(np.take(data, 0, axis=axis) - np.take(data, n - 1, axis=axis))
            tol = tol + ends / (4 * n)
        err = np.abs(got - want)
        assert np.all(err <= tol), (view, mode, err.max())


def test_iso_covers_the_ball(tmp_path, ball):
    path, rho = ball, RHO
    out = tmp_path / "iso.png"
    res = run("render", path, "-o", out, "--size", "24x24", "--mode", "iso", "--iso-value", "100", "--view", "z",
              "--ortho")
    assert res.returncode == 0, res.stderr
    alpha = png_rgba(out)[::-1, :, 3]
    assert np.all(alpha[rho < 7.5] == 255)
    assert np.all(alpha[rho > 8.5] == 0)


def test_a_matcap_png_colours_each_side(tmp_path, ball):
    path, rho = ball, RHO
    cap = np.zeros((32, 32, 3), np.uint8)
    cap[:, :16, 0] = 255  # red left
    cap[:, 16:, 1] = 255  # green right
    write_png(tmp_path / "cap.png", cap)
    out = tmp_path / "matcap.png"
    res = run("render", path, "-o", out, "--size", "24x24", "--mode", "iso", "--iso-value", "100", "--view", "z",
              "--ortho", "--matcap", tmp_path / "cap.png")
    assert res.returncode == 0, res.stderr
    rgba = png_rgba(out)[::-1].astype(float)
    x = np.arange(24) - 11.5
    left = (rho < 7) & (x[None, :] < -4)
    right = (rho < 7) & (x[None, :] > 4)
    assert rgba[left][:, 0].mean() > 4 * rgba[left][:, 1].mean() + 20
    assert rgba[right][:, 1].mean() > 4 * rgba[right][:, 0].mean() + 20


def test_ortho_alone_changes_the_projection(tmp_path, ball):
    path = ball
    imgs = []
    for extra in [[], ["--ortho"]]:
        out = tmp_path / ("o%d.png" % len(extra))
        res = run("render", path, "-o", out, "--size", "32x32", "--mode", "mip", *extra)
        assert res.returncode == 0, res.stderr
        imgs.append(png_rgba(out))
    assert imgs[0][..., 3].any() and imgs[1][..., 3].any()
    assert not np.array_equal(imgs[0], imgs[1])


def test_usage_lists_the_modes():
    res = run("--help")
    assert res.returncode == 0
    assert "--mode dvr|mip|minip|average|iso" in res.stdout
    assert "--view x|-x|y|-y|z|-z" in res.stdout


@pytest.mark.parametrize("args,words", [
    (["--mode", "xray"], ["unknown --mode 'xray'", "dvr, mip, minip, average, iso"]),
    (["--mode"], ["--mode needs a value"]),
    (["--iso-value", "bone"], ["bad --iso-value 'bone'"]),
    (["--iso-value", "nan"], ["bad --iso-value 'nan'"]),
    (["--view", "w"], ["bad --view 'w'", "x, -x, y, -y, z, -z"]),
    (["--matcap", "/nonexistent/cap.png"], ["MatCap", "/nonexistent/cap.png"]),
    (["--mode", "mip", "--classify", "pre"], ["classify pre", "mode dvr only"]),  # the library's rule
    (["--mode", "iso", "--gradient-opacity", "boundary"], ["gradient_opacity", "mode dvr only"]),
])
def test_bad_mode_options(tmp_path, ball, args, words):
    path = ball
    assert_clean_error(run("render", path, "-o", tmp_path / "x.png", "--size", "8x8", *args), *words)


def test_a_matcap_that_is_not_a_png(tmp_path, ball):
    path = ball
    bad = tmp_path / "cap.png"
    bad.write_bytes(b"not a png at all")
    assert_clean_error(run("render", path, "-o", tmp_path / "x.png", "--size", "8x8", "--matcap", bad), "not a PNG")
