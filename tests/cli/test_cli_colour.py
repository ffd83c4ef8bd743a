"""Colour volumes in the CLI (docs/colour.md): `info` prints the components
and the reader's note for a NIfTI RGB24 written here (header by hand, no
nibabel); `render` draws it in the data's colour by default, so an axis view
of a cube whose x faces are red shows pure red at the centre; --color-source
tf gives the grey image of the luminance; --opacity-source picks the scalar;
bad values are clean errors."""
import struct

import numpy as np
import pytest

from test_cli import assert_clean_error, png_rgba, run, write_nifti

N = 16


def cube():
    """(z, y, x, 4) uint8: x faces red, then y faces green, then z faces blue, inside black (the
    C test's cube); alpha a ramp along x."""
    z, y, x = np.indices((N, N, N))
    face = lambda a: (a == 0) | (a == N - 1)  # noqa: E731
    c = np.zeros((N, N, N, 4), np.uint8)
    c[..., 0] = 255 * face(x)
    c[..., 1] = 255 * (face(y) & ~face(x))
    c[..., 2] = 255 * (face(z) & ~face(x) & ~face(y))
    c[..., 3] = 16 * x
    return c


def write_rgb_nifti(path, rgb, datatype=128):
    """A NIfTI-1 RGB24 (128, 3 bytes a voxel) or RGBA32 (2304) single file of rgb (z, y, x, c) uint8."""
    hdr = bytearray(348)
    struct.pack_into("<i", hdr, 0, 348)
    struct.pack_into("<8h", hdr, 40, 3, N, N, N, 1, 1, 1, 1)
    struct.pack_into("<hh", hdr, 70, datatype, 8 * rgb.shape[3])
    struct.pack_into("<8f", hdr, 76, 1, 1, 1, 1, 1, 1, 1, 1)
    struct.pack_into("<f", hdr, 108, 352.0)
    hdr[344:348] = b"n+1\0"
    path.write_bytes(bytes(hdr) + b"\0" * 4 + rgb.tobytes())


@pytest.fixture
def rgb(tmp_path):
    path = tmp_path / "rgb.nii"
    write_rgb_nifti(path, np.ascontiguousarray(cube()[..., :3]))
    return path


VIEW = ["--size", "%dx%d" % (N, N), "--ortho", "--no-jitter", "--no-shading", "--preset", "gray", "--window", "0:10"]


def centre(path, *args, view="x"):
    out = path.parent / ("out_%s_%d.png" % (view, abs(hash(args)) % 10000))
    res = run("render", path, "-o", out, "--view", view, *VIEW, *args)
    assert res.returncode == 0, res.stderr
    return png_rgba(out)[N // 2, N // 2]


def test_info_prints_the_components_and_the_note(rgb):
    res = run("info", rgb)
    assert res.returncode == 0, res.stderr
    assert "components:  3 (RGB: colour from the data" in res.stdout
    assert "NIfTI RGB24: colour from the data, opacity and gradients from luminance" in res.stdout
    grey = rgb.parent / "grey.nii"
    write_nifti(grey, np.zeros((4, 4, 4), np.uint8))
    res = run("info", grey)
    assert "components:  1 (grey)" in res.stdout


@pytest.mark.parametrize("view,channel", [("x", 0), ("y", 1), ("z", 2)])
def test_render_draws_the_data_colour_by_default(rgb, view, channel):
    px = centre(rgb, view=view)
    assert px[channel] > 0 and px[3] > 0
    assert all(px[c] == 0 for c in range(3) if c != channel), px


def test_color_source_tf_draws_grey(rgb):
    px = centre(rgb, "--color-source", "tf")
    assert px[0] == px[1] == px[2] > 0, px
    assert list(centre(rgb, "--color-source", "data")) == list(centre(rgb))


def test_opacity_source_alpha_and_channel(tmp_path):
    path = tmp_path / "rgba.nii"
    write_rgb_nifti(path, cube(), datatype=2304)
    res = run("info", path, "--opacity-source", "alpha")
    assert res.returncode == 0, res.stderr
    assert "components:  4 (RGBA" in res.stdout and "from alpha" in res.stdout
    assert "value range: 0 .. 240" in res.stdout
    res = run("info", path, "--opacity-source", "channel:2")
    assert "blue channel" in res.stdout and "value range: 0 .. 255" in res.stdout
    # opacity from green: the red x faces are transparent, so the x view shows nothing red
    px = centre(path, "--opacity-source", "channel:1")
    assert px[0] == 0, px


@pytest.mark.parametrize("args,words", [
    (["--color-source", "paint"], ["--color-source", "paint", "auto|data|tf"]),
    (["--opacity-source", "channel:9"], ["channel:N"]),
    (["--opacity-source", "hue"], ["--opacity-source", "hue"]),
])
def test_bad_values_are_clean_errors(rgb, args, words):
    assert_clean_error(run("render", rgb, "-o", rgb.parent / "x.png", *args), *words)


def test_alpha_of_rgb_and_data_colour_of_grey_are_clean_errors(rgb, tmp_path):
    assert_clean_error(run("render", rgb, "-o", tmp_path / "x.png", "--opacity-source", "alpha"), "alpha", "RGBA")
    grey = tmp_path / "grey.nii"
    write_nifti(grey, np.full((4, 4, 4), 100, np.uint8))
    assert_clean_error(run("render", grey, "-o", tmp_path / "y.png", "--color-source", "data"), "no colour")


def test_color_space_linear_decodes_the_data_and_writes_display_png(tmp_path):
    """--color-space linear: the file's sRGB bytes are decoded, the image is
    scene-linear, and a PNG gets it encoded again: an opaque orange voxel
    comes back as its own bytes. A lit render differs (the light is linear
    there); a bad name is a clean error."""
    rgb = np.zeros((N, N, N, 3), np.uint8)
    rgb[...] = (200, 90, 30)
    path = tmp_path / "orange.nii"
    write_rgb_nifti(path, rgb)
    for space in ("display", "linear"):
        px = centre(path, "--color-space", space)
        assert abs(int(px[0]) - 200) <= 1 and abs(int(px[1]) - 90) <= 1 and abs(int(px[2]) - 30) <= 1, (space, px)
    cube_path = tmp_path / "cube.nii"
    write_rgb_nifti(cube_path, np.ascontiguousarray(cube()[..., :3]))
    lit = []
    for space in ("display", "linear"):
        out = tmp_path / ("lit_%s.png" % space)
        res = run("render", cube_path, "-o", out, "--size", "24x24", "--color-space", space, "--no-jitter")
        assert res.returncode == 0, res.stderr
        lit.append(png_rgba(out).astype(int))
    assert np.abs(lit[0] - lit[1]).max() > 3
    assert_clean_error(run("render", path, "-o", tmp_path / "x.png", "--color-space", "srgb"), "--color-space", "linear")
