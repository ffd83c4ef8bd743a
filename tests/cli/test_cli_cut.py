"""The CLI's cutaway options: --clip-plane A,B,C,D[,T], --crop
X0:X1,Y0:Y1,Z0:Z1 and --no-caps; their errors. Through an orthographic view
down z whose pixels are one voxel wide (--view z --ortho --size NXxNY), a
pixel is a voxel column, so what a cut keeps can be read off the alpha."""
import numpy as np
import pytest

from test_cli import assert_clean_error, png_rgba, run, write_nifti

NX, NY, NZ = 24, 20, 16
GREY = ["--preset", "gray", "--window", "0:255", "--no-jitter", "--ortho", "--view", "z", "--size", "%dx%d" % (NX, NY)]


@pytest.fixture
def block(tmp_path):
    """A solid block of 200 over the whole volume: every column is opaque."""
    path = tmp_path / "block.nii"
    write_nifti(path, np.full((NZ, NY, NX), 200, np.uint8))
    return path


def covered(tmp_path, path, *args, name="cut.png"):
    out = tmp_path / name
    res = run("render", path, "-o", out, *GREY, *args)
    assert res.returncode == 0, res.stderr
    return png_rgba(out)[::-1, :, 3] > 0  # (y, x), row 0 = bottom = voxel y 0; anything drawn


def test_uncut_block_covers_every_pixel(tmp_path, block):
    assert covered(tmp_path, block).all()


def test_crop_keeps_exactly_the_cropped_voxels(tmp_path, block):
    got = covered(tmp_path, block, "--crop", "3:9,2:12,0:15")
    want = np.zeros((NY, NX), bool)
    want[2:13, 3:10] = True
    assert (got == want).all(), np.argwhere(got != want)
    # a crop along z alone (8 of the 16 slices) keeps every column
    assert covered(tmp_path, block, "--crop", "0:23,0:19,4:11", name="z.png").all()


def test_clip_plane_keeps_its_side(tmp_path, block):
    # the affine is the identity (spacing 1, no orientation): world x = voxel x
    got = covered(tmp_path, block, "--clip-plane", "1,0,0,-9.5")
    want = np.zeros((NY, NX), bool)
    want[:, 10:] = True
    assert (got == want).all()
    # two planes: the other side of x = 15.5 and above y = 4.5
    got = covered(tmp_path, block, "--clip-plane", "-1,0,0,15.5", "--clip-plane", "0,2,0,-9", name="two.png")
    want = np.zeros((NY, NX), bool)
    want[5:, :16] = True
    assert (got == want).all()
    # a slab 3 mm thick from x = 4.5: columns 5, 6, 7
    got = covered(tmp_path, block, "--clip-plane", "1,0,0,-4.5,3", name="slab.png")
    want = np.zeros((NY, NX), bool)
    want[:, 5:8] = True
    assert (got == want).all()


def test_caps_shade_the_cut_face(tmp_path, block):
    """The block cut at z = 7.5 facing the eye (keep z <= 7.5, the eye on
    +z), opaque white (bone preset), a light from +x, across the cut face.
    With caps the first sample is shaded by the face's normal (+z): only the
    ambient term lights it, the same on every pixel. With --no-caps it takes
    the data gradient, zero inside the block: left unlit, full white."""
    args = ["--preset", "bone", "--window", "0:200", "--no-jitter", "--ortho", "--view", "z", "--size", "24x20",
            "--clip-plane", "0,0,-1,7.5", "--light", "dir:1,0,0"]
    red = {}
    for caps in ["on", "off"]:
        out = tmp_path / ("%s.png" % caps)
        res = run("render", block, "-o", out, *args, *(["--no-caps"] if caps == "off" else []))
        assert res.returncode == 0, res.stderr
        red[caps] = png_rgba(out)[2:-2, 2:-2, 0].astype(float)  # away from the block's sides
    assert red["on"].max() - red["on"].min() <= 1, red["on"]
    assert red["on"].max() < red["off"].min() - 30, (red["on"].max(), red["off"].min())


@pytest.mark.parametrize("args,words", [
    (["--clip-plane", "1,0,0"], ["--clip-plane", "four numbers"]),
    (["--clip-plane", "1,0,x,0"], ["--clip-plane", "A,B,C,D"]),
    (["--clip-plane", "1,0,0,0,1,2"], ["--clip-plane", "A,B,C,D"]),
    (["--clip-plane", "1,0,0,nan"], ["--clip-plane", "A,B,C,D"]),
    (["--clip-plane", "0,0,0,1"], ["--clip-plane", "normal", "zero"]),
    (["--clip-plane", "1,0,0,0,-1"], ["--clip-plane", "thickness"]),
    (["--clip-plane", "1,0,0,0"] * 7, ["more than 6 --clip-plane"]),
    (["--clip-plane"], ["--clip-plane needs a value"]),
    (["--crop", "1:2,3:4"], ["--crop", "X0:X1,Y0:Y1,Z0:Z1"]),
    (["--crop", "1-2,3:4,5:6"], ["--crop", "X0:X1,Y0:Y1,Z0:Z1"]),
    (["--crop", "1:2,3:4,5:6,7:8"], ["--crop", "X0:X1,Y0:Y1,Z0:Z1"]),
    (["--crop", "-1:2,3:4,5:6"], ["--crop", "from 0"]),
    (["--crop", "5:2,0:4,0:6"], ["--crop", "X0 5 is after X1 2"]),
    (["--crop", "0:24,0:4,0:6"], ["--crop", "X1 = 24 is outside the volume", "0..23"]),
    (["--crop", "0:2,0:4,0:16"], ["Z1 = 16", "0..15"]),
    (["--crop"], ["--crop needs a value"]),
])
def test_bad_cut_options(tmp_path, block, args, words):
    assert_clean_error(run("render", block, "-o", tmp_path / "x.png", "--size", "8x8", *args), *words)


def test_usage_lists_the_cut_options():
    res = run("--help")
    assert res.returncode == 0
    for w in ["--clip-plane A,B,C,D[,T]", "--crop X0:X1,Y0:Y1,Z0:Z1", "--no-caps"]:
        assert w in res.stdout
