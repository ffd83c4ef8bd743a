"""The CLI's path tracer: --shading path with --samples, --sample-offset,
--bounces and --seed; the same arguments give the same file, another seed
another one, more bounces a brighter thick sphere, and bad values a clean
error naming the option or the library's field."""
import pytest

from test_cli import assert_clean_error, png_rgba, run

SPHERE = "phantom:sphere:20x20x20"
SCENE = ["--size", "32x32", "--preset", "bone", "--window", "0.4:0.6", "--shading", "path"]


def render(tmp_path, name, *extra):
    out = tmp_path / name
    res = run("render", SPHERE, "-o", out, *SCENE, *extra)
    assert res.returncode == 0, res.stderr
    return out


def test_the_same_seed_gives_the_same_file_and_another_seed_another(tmp_path):
    a = render(tmp_path, "a.png", "--samples", "2", "--seed", "3")
    b = render(tmp_path, "b.png", "--samples", "2", "--seed", "3")
    c = render(tmp_path, "c.png", "--samples", "2", "--seed", "4")
    assert a.read_bytes() == b.read_bytes()
    assert (png_rgba(a) != png_rgba(c)).any()
    assert png_rgba(a)[..., 3].max() > 200  # the sphere is there


def test_more_bounces_brighten_the_sphere(tmp_path):
    one = png_rgba(render(tmp_path, "one.png", "--samples", "4", "--bounces", "1")).astype(float)
    many = png_rgba(render(tmp_path, "many.png", "--samples", "4", "--bounces", "6")).astype(float)
    opaque = one[..., 3] > 128
    assert opaque.sum() > 50
    assert many[..., :3][opaque].mean() > one[..., :3][opaque].mean() + 2  # 8-bit levels
    assert (many[..., :3] >= one[..., :3]).all()  # one seed: more bounces only add light


def test_a_later_sample_range_is_another_image(tmp_path):
    a = render(tmp_path, "a.png", "--samples", "1", "--sample-offset", "0")
    b = render(tmp_path, "b.png", "--samples", "1", "--sample-offset", "1")
    assert (png_rgba(a) != png_rgba(b)).any()


@pytest.mark.parametrize("args,words", [
    (["--samples", "-1"], ["--samples", "whole number"]),
    (["--samples", "x"], ["--samples"]),
    (["--bounces", "2.5"], ["--bounces"]),
    (["--seed"], ["--seed", "needs a value"]),
    (["--bounces", "65"], ["path_bounces"]),
    (["--samples", "70000"], ["path_samples"]),
    (["--gradient-opacity", "boundary"], ["path", "gradient_opacity"]),
])
def test_bad_path_values(tmp_path, args, words):
    assert_clean_error(run("render", SPHERE, "-o", tmp_path / "x.png", *SCENE, *args), *words)
