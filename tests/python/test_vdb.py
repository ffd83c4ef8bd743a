"""The OpenVDB loader (csrc/io/vdb.cpp) against files written by pyopenvdb:
dims from the active box, the affine from the grid transform, values and
their placement (rendered against the same array handed over from memory),
grid choice and errors."""

import numpy as np
import pytest

from voxlight.core import native
from vdb_write import write_vdb

# a rotation about z, anisotropic voxels and a translation: catches any
# transpose or row/column mix-up of OpenVDB's row-vector matrix
AFFINE = np.array([[0.0, -0.5, 0.0, 10.0],
                   [0.5, 0.0, 0.0, 20.0],
                   [0.0, 0.0, 2.0, 30.0],
                   [0.0, 0.0, 0.0, 1.0]])
OFFSET = (3, -9, 17)  # index of voxel (0, 0, 0): crosses a leaf boundary


def _blob(shape=(13, 10, 7)):
    """Positive everywhere (so every voxel is active) and asymmetric."""
    i, j, k = np.meshgrid(*[np.arange(n, dtype=np.float64) for n in shape], indexing="ij")
    c = (np.asarray(shape) - 1) * np.array([0.35, 0.5, 0.6])
    r2 = ((i - c[0]) / 3.0) ** 2 + ((j - c[1]) / 2.5) ** 2 + ((k - c[2]) / 2.0) ** 2
    return (0.05 + np.exp(-r2) + 0.01 * i).astype(np.float32)


@pytest.fixture(scope="module")
def blob_vdb(tmp_path_factory):
    d = tmp_path_factory.mktemp("vdb")
    a = _blob()
    path = write_vdb(d / "blob.vdb", [
        {"name": "velocity", "vec3": True},
        {"name": "temperature", "array": np.full((2, 2, 2), 7.0, np.float32)},
        {"name": "density", "array": a, "ijk": OFFSET, "affine": AFFINE},
    ])
    return path, a


def test_dims_affine_and_values(lib, blob_vdb):
    path, a = blob_vdb
    with native.Volume.load(path, lib=lib) as v:
        info = v.info
        hist = v.histogram(16)
    assert info["dims"] == a.shape
    expected = AFFINE.copy()
    expected[:3, 3] = (AFFINE @ np.append(OFFSET, 1.0))[:3]  # voxel 0 is index OFFSET
    assert np.allclose(info["affine"], expected, atol=1e-12)
    assert np.allclose(info["spacing"], [0.5, 0.5, 2.0])
    assert info["dtype"] == "float32"
    assert info["value_min"] == pytest.approx(a.min()) and info["value_max"] == pytest.approx(a.max())
    ref, _ = np.histogram(a, bins=16, range=(a.min(), a.max()))
    assert np.abs(hist - ref).sum() <= 2, (hist, ref)


def test_voxels_land_where_they_were_written(lib, blob_vdb):
    """The file and the same array from memory render identically: every
    value sits at its own voxel, not transposed or shifted."""
    path, a = blob_vdb
    with native.Renderer(lib=lib) as r:
        with native.Volume.load(path, lib=lib) as v:
            r.set_volume(v)
        from_file, _ = r.render(width=40, height=32, azimuth=30, elevation=20, jitter=False)
        with native.Volume.from_array(a, affine=AFFINE, lib=lib) as v:
            r.set_volume(v)
        from_memory, _ = r.render(width=40, height=32, azimuth=30, elevation=20, jitter=False)
        flipped = np.ascontiguousarray(a[::-1])
        with native.Volume.from_array(flipped, affine=AFFINE, lib=lib) as v:
            r.set_volume(v)
        wrong, _ = r.render(width=40, height=32, azimuth=30, elevation=20, jitter=False)
    assert from_file[..., 3].max() > 0.1
    assert np.abs(from_file - from_memory).max() < 1e-6
    assert np.abs(from_file - wrong).max() > 0.02  # the comparison can see a flip


def test_inactive_voxels_get_the_background(lib, tmp_path):
    a = np.full((4, 4, 4), 5.0, np.float32)
    a[1:3, 1:3, 1:3] = 0.25  # equal to the background: inactive in the file
    path = write_vdb(tmp_path / "holes.vdb", [{"name": "density", "array": a, "background": 0.25}])
    with native.Volume.load(path, lib=lib) as v:
        assert v.info["dims"] == (4, 4, 4)
        assert v.info["value_min"] == pytest.approx(0.25) and v.info["value_max"] == pytest.approx(5.0)
        h = v.histogram(2)
    assert list(h) == [8, 56]


def test_first_scalar_grid_without_density(lib, tmp_path):
    path = write_vdb(tmp_path / "t.vdb", [
        {"name": "vel", "vec3": True},
        {"name": "heat", "array": np.full((3, 2, 1), 4.0, np.float32), "ijk": (-5, 0, 2)},
    ])
    with native.Volume.load(path, lib=lib) as v:
        assert v.info["dims"] == (3, 2, 1)
        assert np.allclose(v.info["affine"][:3, 3], [-5, 0, 2])


def test_errors_name_the_file_and_the_problem(lib, tmp_path):
    empty = write_vdb(tmp_path / "empty.vdb", [{"name": "density"}])
    with pytest.raises(native.VoxlightError, match=r"empty\.vdb.*grid 'density' is empty"):
        native.Volume.load(empty, lib=lib)
    vec = write_vdb(tmp_path / "vec.vdb", [{"name": "v", "vec3": True}])
    with pytest.raises(native.VoxlightError, match=r"vec\.vdb.*no scalar float grid"):
        native.Volume.load(vec, lib=lib)
    big = write_vdb(tmp_path / "big.vdb", [{"name": "density", "array": np.ones((64, 64, 64), np.float32)}])
    with pytest.raises(native.VoxlightError, match=r"memory budget of 0\.5 MiB"):
        native.Volume.load(big, memory_budget=1 << 19, lib=lib)
    cut = tmp_path / "cut.vdb"
    cut.write_bytes(open(big, "rb").read()[:300])
    with pytest.raises(native.VoxlightError, match=r"cut\.vdb"):
        native.Volume.load(str(cut), lib=lib)


def test_magic_without_extension(lib, blob_vdb, tmp_path):
    path, a = blob_vdb
    other = tmp_path / "blob.data"
    other.write_bytes(open(path, "rb").read())
    with native.Volume.load(str(other), lib=lib) as v:
        assert v.info["dims"] == a.shape
