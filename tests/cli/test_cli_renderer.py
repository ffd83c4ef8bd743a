"""`voxlight render --renderer`: the slicing comparison modes
(docs/slicing.md) render what the ray caster renders, through every storage
that samples like dense storage, and an unknown renderer is one clear line
naming the choices."""
from test_cli import assert_clean_error, png_alpha_mean, png_size, run

BALL = "phantom:sphere:32x32x32"


def render(tmp_path, name, *extra):
    out = tmp_path / f"{name}.png"
    res = run("render", BALL, "-o", out, "--size", "48x40", "--no-jitter", *extra)
    assert res.returncode == 0, res.stderr
    assert png_size(out) == (48, 40)
    return png_alpha_mean(out)


def test_every_renderer_draws_the_phantom(tmp_path):
    ray = render(tmp_path, "ray", "--renderer", "raycast")
    assert ray > 0.05
    assert render(tmp_path, "default") == ray  # raycast is the default
    for name in ("slices2d", "slices3d", "SLICES3D"):
        # the same coverage up to where the samples lie (tests/test_slices.c bounds the images)
        alpha = render(tmp_path, name, "--renderer", name)
        assert abs(alpha - ray) < 0.03 * ray, (name, alpha, ray)


def test_slices_sample_bricked_storage_like_dense(tmp_path):
    dense = render(tmp_path, "dense", "--renderer", "slices3d", "--storage", "dense")
    bricked = render(tmp_path, "bricked", "--renderer", "slices3d", "--storage", "bricked", "--page-brick", "8")
    assert abs(dense - bricked) < 1e-3 * max(dense, 1e-6), (dense, bricked)


def test_bad_renderer_options(tmp_path):
    res = run("render", BALL, "-o", tmp_path / "x.png", "--renderer", "splat")
    assert_clean_error(res, "--renderer")
    assert "raycast, slices2d, slices3d" in res.stderr
    res = run("render", BALL, "-o", tmp_path / "x.png", "--renderer", "slices2d", "--classify", "preint")
    assert_clean_error(res, "slices2d")
