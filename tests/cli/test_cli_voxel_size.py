"""`--voxel-size X,Y,Z` (or one value) for `voxlight info|render`: it sets
the geometry of inputs that carry none (TIFF/PNG stacks), leaves files with
geometry alone and refuses malformed values with one error line. Also the
CLI on an OpenVDB file written by pyopenvdb."""
import sys
from pathlib import Path

import numpy as np
import pytest

from test_cli_formats import blob, run, write_nrrd, write_tiff

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "python"))
from vdb_write import write_vdb  # noqa: E402


def info(*args):
    r = run("info", *args)
    assert r.returncode == 0, r.stderr
    return r.stdout


def affine_rows(out):
    rows = [l.strip().strip("[]").split() for l in out.splitlines() if l.startswith("  [")]
    return np.array(rows, dtype=np.float64)


def test_info_voxel_size_sets_stack_geometry(tmp_path):
    p = tmp_path / "pages.tif"
    write_tiff(p, list(blob(dtype=np.uint16)))
    assert "spacing:     1 x 1 x 1 mm" in info(p)
    out = info(p, "--voxel-size", "0.5,0.25,2")
    assert "spacing:     0.5 x 0.25 x 2 mm" in out
    assert np.allclose(affine_rows(out), np.diag([0.5, 0.25, 2.0, 1.0]))
    out = info("--voxel-size", "0.3", p)  # one value for all three, before INPUT
    assert "spacing:     0.3 x 0.3 x 0.3 mm" in out


def test_files_with_geometry_ignore_it(tmp_path):
    p = tmp_path / "ball.nrrd"
    write_nrrd(p, blob(), extra="spacings: 2 3 4\n")
    assert "spacing:     2 x 3 x 4 mm" in info(p, "--voxel-size", "0.5")


def test_render_follows_the_voxel_size(tmp_path):
    p = tmp_path / "ball.tif"
    write_tiff(p, list(blob((24, 24, 24), np.int16).astype(np.float32)))
    images = []
    for extra in ([], ["--voxel-size", "1,1,1"], ["--voxel-size", "1,1,3"]):
        out = tmp_path / ("out%d.png" % len(images))
        r = run("render", p, "-o", out, "--size", "48x48", "--no-jitter", *extra)
        assert r.returncode == 0, r.stderr
        images.append(out.read_bytes())
    assert images[0] == images[1]  # 1 mm is the default
    assert images[0] != images[2]  # a stretched volume looks different


@pytest.mark.parametrize("value", ["0", "1,2", "1,2,3,4", "a", "-1,1,1", "1,,2", "nan", "1,2,3,"])
def test_bad_values_give_one_error_line(tmp_path, value):
    p = tmp_path / "pages.tif"
    write_tiff(p, list(blob(dtype=np.uint16)))
    for cmd in (["info", p], ["render", p, "-o", tmp_path / "x.png", "--size", "16x16"]):
        r = run(*cmd, "--voxel-size", value)
        assert r.returncode == 1
        lines = [l for l in r.stderr.splitlines() if l.startswith("voxlight: error:")]
        assert len(lines) == 1 and "--voxel-size" in lines[0] and value in lines[0], r.stderr
    r = run("info", p, "--voxel-size")
    assert r.returncode == 1 and "--voxel-size needs a value" in r.stderr


def test_vdb_info_and_render(tmp_path):
    a = np.ones((6, 5, 4), np.float32)
    a[2:4, 1:4, 1:3] = 3.0
    aff = np.diag([0.5, 0.5, 0.5, 1.0])
    aff[:3, 3] = [1.0, 2.0, 3.0]
    p = write_vdb(tmp_path / "smoke.vdb", [{"name": "density", "array": a, "ijk": (2, 0, -4), "affine": aff}])
    out = info(p)
    assert "dimensions:  6 x 5 x 4" in out and "value range: 1 .. 3" in out
    assert np.allclose(affine_rows(out)[:3, 3], [2.0, 2.0, 1.0])  # index (2, 0, -4) in world
    r = run("render", p, "-o", tmp_path / "smoke.png", "--size", "32x32")
    assert r.returncode == 0, r.stderr
