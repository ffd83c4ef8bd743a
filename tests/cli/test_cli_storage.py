"""Storage options of `voxlight render`: bricked and sparse storage say what
they hold, a phantom over the 2048 texture limit renders bricked, and what
bricked storage cannot do fails with one clear line."""
import re

from test_cli import assert_clean_error, png_alpha_mean, png_size, run

# over llvmpipe's 2048 texture limit in x, small enough for CI (~60 MB of 8-bit voxels)
OVER_LIMIT = "phantom:large-sparse:2200x300x90"


def storage_line(stderr):
    m = re.search(r"storage (\w+), ([0-9.]+) MiB resident(?:, (\d+) of (\d+) bricks)?", stderr)
    assert m, stderr
    return m.group(1), float(m.group(2)), m.group(3) and int(m.group(3))


def test_large_phantom_renders_bricked_within_a_budget(tmp_path):
    out = tmp_path / "large.png"
    res = run("render", OVER_LIMIT, "-o", out, "--size", "96x48", "--elevation", "60", "--memory-budget", "64M")
    assert res.returncode == 0, res.stderr
    storage, mib, resident = storage_line(res.stderr)
    assert storage == "bricked" and 0 < mib <= 64
    assert png_size(out) == (96, 48) and png_alpha_mean(out) > 0.002
    sparse = run("render", OVER_LIMIT, "-o", tmp_path / "s.png", "--size", "96x48", "--elevation", "60",
                 "--storage", "sparse", "--window", "0.5:1")
    assert sparse.returncode == 0, sparse.stderr
    s_storage, s_mib, s_resident = storage_line(sparse.stderr)
    assert s_storage == "sparse" and s_resident < resident


def test_dense_over_the_texture_limit_is_a_clear_error(tmp_path):
    assert_clean_error(run("render", OVER_LIMIT, "-o", tmp_path / "x.png", "--storage", "dense"), "texture limit")


def test_budget_and_unsupported_filters_are_clear_errors(tmp_path):
    # auto over the texture limit and far over the budget: sparse, then 8x
    # coarser, and it says so; below even that, a clear error naming the budget
    res = run("render", OVER_LIMIT, "-o", tmp_path / "x.png", "--size", "64x32", "--memory-budget", "1M")
    assert res.returncode == 0, res.stderr
    assert "storage sparse" in res.stderr and "LOD fallback: level 3" in res.stderr, res.stderr
    assert_clean_error(run("render", OVER_LIMIT, "-o", tmp_path / "x.png", "--memory-budget", "16K"), "budget")
    # the derived filters page with bricked and sparse storage; compressed
    # storage keeps the values only as codes on the GL side and says so
    for storage in ("bricked", "sparse"):
        res = run("render", "phantom:sphere:24x24x24", "-o", tmp_path / "x.png", "--storage", storage,
                  "--filter", "cubic")
        assert res.returncode == 0, res.stderr
    assert_clean_error(run("render", "phantom:sphere:24x24x24", "-o", tmp_path / "x.png", "--storage", "compressed",
                           "--filter", "cubic"), "compressed")


def test_bad_storage_options(tmp_path):
    assert_clean_error(run("render", "phantom:sphere", "-o", tmp_path / "x.png", "--storage", "paged"), "storage")
    assert_clean_error(run("render", "phantom:sphere", "-o", tmp_path / "x.png", "--page-brick", "12"),
                       "--page-brick")
    assert_clean_error(run("render", "phantom:nothing", "-o", tmp_path / "x.png"), "phantom")
    assert_clean_error(run("render", "phantom:sphere:2x", "-o", tmp_path / "x.png"), "phantom size")


def test_lod_fallback_is_reported(tmp_path):
    """Sparse storage over its budget renders a coarser level and says so."""
    base = ["render", OVER_LIMIT, "-o", tmp_path / "x.png", "--size", "64x32", "--storage", "sparse",
            "--window", "0.001:0.01", "--page-brick", "16"]
    full = run(*base)
    assert full.returncode == 0, full.stderr
    assert "LOD fallback" not in full.stderr
    _, mib, _ = storage_line(full.stderr)
    res = run(*base, "--memory-budget", "%dK" % int(mib * 1024 * 0.5))
    assert res.returncode == 0, res.stderr
    m = re.search(r"LOD fallback: level (\d+) \((\d+)x coarser per axis\): the visible bricks need ([0-9.]+) MiB", res.stderr)
    assert m and int(m.group(1)) >= 1 and abs(float(m.group(3)) - mib) < 0.2, res.stderr


def test_compressed_storage_reports_its_decode(tmp_path):
    """--storage compressed renders and says what it holds and how long decoding took."""
    out = tmp_path / "c.png"
    res = run("render", "phantom:marschner-lobb:40x40x40", "-o", out, "--size", "48x48", "--storage", "compressed",
              "--page-brick", "16")
    assert res.returncode == 0, res.stderr
    storage, mib, resident = storage_line(res.stderr)
    assert storage == "compressed" and mib > 0 and resident > 0
    assert re.search(r"compressed bricks decoded into the cache in [0-9.]+ ms", res.stderr), res.stderr
    assert png_alpha_mean(out) > 0.002
    assert_clean_error(run("render", "phantom:sphere:24x24x24", "-o", tmp_path / "x.png", "--storage", "compressed",
                           "--filter", "precomputed"), "compressed")
