"""The CLI's lighting options: --light, --shading,
--ambient-occlusion, --anisotropy; their errors, and that shadows show on the
two-blobs phantom (blobs at world x = +0.45 and -0.45; the default camera
looks from +Y, so the +x blob is on the image's left half)."""
import pytest

from test_cli import assert_clean_error, png_rgba, png_size, run

BLOBS = "phantom:two-blobs:24x24x24"
# Opaque ivory blobs: the bone preset over their edge
SCENE = ["--size", "96x96", "--preset", "bone", "--window", "0.2:0.5"]


@pytest.mark.parametrize("args,words", [
    (["--light", "spot:1,2,3"], ["--light", "dir:X,Y,Z"]),
    (["--light", "dir:1,2"], ["--light", "three numbers"]),
    (["--light", "dir:1,2,3,4,5"], ["--light", "three numbers"]),
    (["--light", "point:1,x,3"], ["--light", "three numbers"]),
    (["--light", "dir:1,2,inf"], ["--light", "three numbers"]),
    (["--light", "dir:0,0,0"], ["--light", "zero"]),
    (["--light", "point:0,0,0,-1"], ["intensity"]),
    (["--light", "point:0,0,0,0"], ["intensity"]),
    (["--light"], ["--light needs a value"]),
    (["--light", "dir:1,0,0"] * 9, ["more than 8"]),
    (["--shading", "raytraced"], ["unknown --shading 'raytraced'", "phong, shadowed, scatter"]),
    (["--ambient-occlusion", "-2"], ["--ambient-occlusion"]),
    (["--ambient-occlusion", "far"], ["--ambient-occlusion"]),
    (["--ambient-occlusion", "100"], ["ambient_occlusion", "64"]),  # the library's range
    (["--anisotropy", "1"], ["--anisotropy"]),
    (["--anisotropy", "0.995"], ["anisotropy", "0.99"]),  # the library's range
])
def test_bad_lighting_options(tmp_path, args, words):
    assert_clean_error(run("render", BLOBS, "-o", tmp_path / "x.png", "--size", "8x8", *args), *words)


def test_usage_lists_the_shading_models():
    res = run("--help")
    assert res.returncode == 0
    assert "--shading phong|shadowed|scatter" in res.stdout
    assert "--light dir:X,Y,Z[,INTENSITY] | point:X,Y,Z[,INTENSITY]" in res.stdout


def test_every_option_together(tmp_path):
    """Eight lights of both kinds, each model, occlusion and anisotropy at
    their limits: an image, no error."""
    lights = []
    for i in range(4):
        lights += ["--light", "dir:%d,1,0.5" % (i - 2), "--light", "point:0,%d,0,%g" % (i - 2, 0.5 + i)]
    for model in ["phong", "shadowed", "SCATTER"]:
        out = tmp_path / ("%s.png" % model)
        res = run("render", BLOBS, "-o", out, "--size", "24x16", *lights, "--shading", model,
                  "--ambient-occlusion", "64", "--anisotropy", "-0.99")
        assert res.returncode == 0, res.stderr
        assert png_size(out) == (24, 16)


def blob_brightness(path):
    """Mean colour of the opaque pixels on the image's left and right halves."""
    rgba = png_rgba(path).astype(float) / 255
    half = rgba.shape[1] // 2
    means = []
    for part in (rgba[:, :half], rgba[:, half:]):
        opaque = part[..., 3] > 0.5
        assert opaque.sum() > 50, "a blob covers the half"
        means.append(part[..., :3].mean(axis=2)[opaque].mean())
    return means


def render_blobs(tmp_path, name, *args):
    out = tmp_path / name
    res = run("render", BLOBS, "-o", out, *SCENE, *args)
    assert res.returncode == 0, res.stderr
    return blob_brightness(out)


def test_shadowed_darkens_the_blob_behind(tmp_path):
    """A sun from +x: without shadows the blobs are lit alike; with them the
    -x blob (right half) lies in the other's shadow. From -x the roles
    swap. The GL path renders this (the reference's own tests are
    tests/test_reference_light.c)."""
    left, right = render_blobs(tmp_path, "phong.png", "--light", "dir:1,0,0")
    assert abs(left - right) < 0.1 * left, (left, right)
    s_left, s_right = render_blobs(tmp_path, "shadowed.png", "--light", "dir:1,0,0", "--shading", "shadowed")
    assert s_right < 0.85 * s_left, (s_left, s_right)
    assert s_right < 0.8 * right, (s_right, right)
    w_left, w_right = render_blobs(tmp_path, "swapped.png", "--light", "dir:-1,0,0", "--shading", "shadowed")
    assert w_left < 0.85 * w_right, (w_left, w_right)
    # --no-shading still turns every light off: the same image either way
    a = tmp_path / "flat_phong.png"
    b = tmp_path / "flat_shadowed.png"
    assert run("render", BLOBS, "-o", a, *SCENE, "--no-shading").returncode == 0
    assert run("render", BLOBS, "-o", b, *SCENE, "--no-shading", "--shading", "shadowed",
               "--light", "dir:1,0,0").returncode == 0
    assert a.read_bytes() == b.read_bytes()
