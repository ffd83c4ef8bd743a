"""Convert to Blender Volume without Blender: the classified grid of a
phantom through the binding (vxl_classified_grid), the helper
voxlight-write-vdb writing it (read back with pyopenvdb, an independent
reader), the stream's refusals, and the add-on's size, budget and platform
checks (plugin/core/vdb_export.py)."""

import os
import subprocess

import numpy as np
import pytest

from voxlight.core import native, platform_rules, vdb_export

openvdb = pytest.importorskip("pyopenvdb")

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
WRITER = os.path.join(ROOT, os.environ.get("BUILD", "build"), "voxlight-write-vdb")

# a rotation about z, anisotropic voxels and a translation: a transposed
# matrix or a row/column mix-up moves every cell
MODEL = np.array([[0.0, -0.5, 0.0, 10.0],
                  [0.5, 0.0, 0.0, 20.0],
                  [0.0, 0.0, 2.0, 30.0],
                  [0.0, 0.0, 0.0, 1.0]])


@pytest.fixture(scope="module")
def grid(lib):
    with native.Volume.phantom("phantom:sphere:12x10x8", lib=lib) as v:
        tf = np.array([[1.0, 0.2, 0.1, 0.0], [0.1, 0.4, 1.0, 0.6]], np.float32)
        p = native.make_params(model=MODEL, tf_rgba=tf, window=(v.info["value_min"], v.info["value_max"]),
                               lib=lib)
        return v.classified_grid(p)


def _read(path):
    grids, _meta = openvdb.readAll(str(path))
    return {g.name: g for g in grids}


def test_grid_info(grid):
    info, density, rgb = grid
    assert info["dims"] == (12, 10, 8)
    assert density.shape == (8, 10, 12) and rgb.shape == (8, 10, 12, 3)
    assert np.allclose(info["index_to_world"], MODEL)  # one cell per voxel
    assert info["voxel_length"] == pytest.approx(abs(np.linalg.det(MODEL[:3, :3])) ** (1 / 3))
    assert density.max() == pytest.approx(info["max_density"], rel=1e-6)
    assert density.min() >= 0 and density.max() > 0 and (density == 0).any()


def test_writer_round_trip(grid, tmp_path):
    info, density, rgb = grid
    out = tmp_path / "sub" / "ball.vdb"
    size = vdb_export.write(WRITER, str(out), info["dims"], info["index_to_world"], density, rgb)
    assert size == out.stat().st_size > 0
    g = _read(out)
    assert set(g) == {"density", "color"}
    d, c = g["density"], g["color"]
    assert d.activeVoxelCount() == int((density > 0).sum())
    back = np.zeros(density.shape[::-1], np.float32)  # pyopenvdb copies (i, j, k) order
    d.copyToArray(back, ijk=(0, 0, 0))
    assert np.array_equal(back.transpose(2, 1, 0), density)
    cb = np.zeros(density.shape[::-1] + (3,), np.float32)
    c.copyToArray(cb, ijk=(0, 0, 0))
    full = cb.transpose(2, 1, 0, 3)
    assert np.array_equal(full[density > 0], rgb[density > 0])
    for ijk in [(0, 0, 0), (11, 9, 7), (3, 4, 5)]:
        assert np.allclose(d.transform.indexToWorld(ijk), (MODEL @ np.append(ijk, 1.0))[:3])


def test_writer_refuses_bad_streams(tmp_path):
    out = str(tmp_path / "x.vdb")
    good = vdb_export.stream((2, 1, 1), np.eye(4), np.ones((1, 1, 2)), np.ones((1, 1, 2, 3)))
    for data, words in [(b"nope", "does not start"), (good[:-4], "cut short"), (good + b"!", "follow"),
                        (good[:8] + b"\0" * 12 + good[20:], "0 or over")]:
        res = subprocess.run([WRITER, out], input=data, stderr=subprocess.PIPE)
        assert res.returncode != 0 and words in res.stderr.decode(), (words, res.stderr)
    with pytest.raises(vdb_export.ExportError, match="cut short"):
        vdb_export.write(WRITER, out, (2, 1, 1), np.eye(4), np.ones((1, 1, 1)), np.ones((1, 1, 1, 3)))


def test_grid_dims_and_budget():
    assert vdb_export.grid_dims((100, 50, 20), 0) == (100, 50, 20)
    assert vdb_export.grid_dims((100, 50, 20), 10) == (10, 5, 2)
    assert vdb_export.grid_dims((100, 50, 1), 10) == (10, 5, 1)
    vdb_export.check_budget((64, 64, 64), 1 << 20, 64 << 20)
    with pytest.raises(vdb_export.ExportError, match="over the memory budget of 64 MiB"):
        vdb_export.check_budget((256, 256, 256), 0, 64 << 20)


def test_windows_refuses_clearly(tmp_path):
    with pytest.raises(vdb_export.ExportError, match="Windows build of Voxlight"):
        vdb_export.writer_path(str(tmp_path / "voxlight.dll"), platform_rules.WindowsRules())
    with pytest.raises(vdb_export.ExportError, match="missing beside"):
        vdb_export.writer_path(str(tmp_path / "libvoxlight.so"), platform_rules.PosixRules())
