"""OME-Zarr through the add-on's native layer (plugin/core/native.py), the
way Blender loads it: level and channel in the path ("#level=N&c=N"), time
as frame, dims/affine/frame count, and the exact value distribution (one
histogram bin per 8-bit value). Stores come from tests/zarr_write.py; the
voxel-by-voxel check is tests/test_zarr.c."""
import sys
from pathlib import Path

import numpy as np
import pytest

from voxlight.core import import_job, native

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from zarr_write import pyramid, ramp, write_store  # noqa: E402

AXES = "tczyx"
SCALES = [[1, 1, 3.0, 0.5, 0.25], [1, 1, 6.0, 1.0, 0.5]]
TRANSLATION = [0, 0, -4.0, 5.0, 6.0]


@pytest.fixture(scope="module", params=[2, 3])
def store(request, tmp_path_factory):
    data = ramp((2, 3, 6, 7, 9), "uint8", 11)
    levels = pyramid(data, 2, AXES)
    root = write_store(tmp_path_factory.mktemp("zarr") / "cells.zarr", levels, AXES, version=request.param,
                       codec="blosc" if request.param == 2 else "gzip", chunks=[1, 2, 4, 4, 4], scales=SCALES,
                       translation=TRANSLATION)
    return root, levels


@pytest.mark.parametrize("level,c,t", [(0, 0, 0), (0, 2, 1), (1, 1, 1)])
def test_level_channel_frame_geometry_and_values(lib, store, level, c, t):
    root, levels = store
    with native.Volume.load(f"{root}#level={level}&c={c}", frame=t, lib=lib) as v:
        info = v.info
        hist = v.histogram(256, -0.5, 255.5)
    want = levels[level][t, c]  # (z, y, x)
    assert info["dims"] == want.shape[::-1]
    assert info["frame_count"] == 2 and info["frame"] == t
    sx, sy, sz = SCALES[level][4], SCALES[level][3], SCALES[level][2]
    expect = np.array([[sx, 0, 0, 6.0], [0, sy, 0, 5.0], [0, 0, sz, -4.0], [0, 0, 0, 1]])
    expect[:3] *= 1e-3  # the axes are in micrometers; the affine is in mm
    assert np.allclose(info["affine"], expect, atol=1e-12)
    assert info["dtype"] == "uint8"
    assert np.array_equal(hist, np.bincount(want.ravel(), minlength=256))


def test_errors_name_the_store(lib, store):
    root, _ = store
    with pytest.raises(native.VoxlightError, match="channel 3 asked for, the image has 3 channels"):
        native.Volume.load(f"{root}#c=3", lib=lib)
    with pytest.raises(native.VoxlightError, match="cells.zarr"):
        native.Volume.load(f"{root}#level=9", lib=lib)


def test_importer_names_a_store_after_its_folder():
    assert import_job.display_name("/data/cells.zarr") == "cells"
    assert "*.zarr" in import_job.FILTER_GLOB.split(";")
