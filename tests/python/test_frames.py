"""4D volumes and DICOM series in the add-on without Blender: the scene-frame
to volume-frame mapping, the byte-bounded LRU frame cache (frames.py), the
binding's frame/series arguments and series listing (native.py), and a
runtime entry stepping through frames (runtime.py)."""
import struct

import numpy as np
import pytest

from dicom_write import write_dicom
from nifti_write import nifti1_bytes
from voxlight.core import frames, native, runtime


def write_4d(path, frames_n=8, n=12):
    """Frame t: a cube of value 10*(t+1) whose x position moves with t."""
    data = np.zeros((n, n, n, frames_n), np.float32)
    for t in range(frames_n):
        data[1 + t: 4 + t, 4:8, 4:8, t] = 10.0 * (t + 1)
    raw = bytearray(nifti1_bytes(data))
    struct.pack_into("<h", raw, 40, 4)  # dim[0] = 4
    path.write_bytes(bytes(raw))
    return data


def test_volume_frame_follows_the_timeline_or_stays_fixed():
    vf = frames.volume_frame
    assert [vf(f, 5) for f in range(0, 8)] == [0, 0, 1, 2, 3, 4, 4, 4]  # offset 1: frame 1 shows 0
    assert vf(10, 5, offset=10) == 0 and vf(13, 5, offset=10) == 3
    assert vf(99, 5, frames.FIXED, fixed=2) == 2
    assert vf(1, 5, frames.FIXED, fixed=9) == 4
    assert vf(7, 1) == 0 and vf(7, 0) == 0


class FakeVolume:
    def __init__(self, size):
        self.info = {"storage_bytes": size}
        self.closed = False

    def close(self):
        self.closed = True


def test_cache_evicts_least_recently_used_within_its_budget():
    c = frames.FrameCache(budget_bytes=300)
    made = {}

    def get(k, size=100):
        return c.get(k, lambda: made.setdefault(k, FakeVolume(size)))

    for k in range(3):
        get(k)
    assert c.bytes == 300 and c.keys() == [0, 1, 2] and c.evictions == 0
    get(0)  # a hit makes 0 the newest
    assert c.hits == 1 and c.keys() == [1, 2, 0]
    get(3)
    assert c.keys() == [2, 0, 3] and made[1].closed and not made[0].closed
    assert c.bytes <= c.budget_bytes
    # one frame larger than the budget is still kept: it is what is shown
    get(9, size=1000)
    assert c.keys() == [9] and c.bytes == 1000 and all(made[k].closed for k in (2, 0, 3))
    c.set_budget(2000)
    get(10)
    assert c.keys() == [9, 10]
    c.drop(lambda k: k == 9)
    assert c.keys() == [10] and c.bytes == 100 and made[9].closed
    c.clear()
    assert c.bytes == 0 and made[10].closed


def test_binding_loads_one_frame_and_reports_the_count(tmp_path):
    p = tmp_path / "run.nii"
    data = write_4d(p)
    for t in (0, 3, 7):
        with native.Volume.load(str(p), frame=t) as v:
            assert v.info["frame_count"] == 8 and v.info["frame"] == t
            assert v.info["value_max"] == pytest.approx(10.0 * (t + 1))
            assert v.info["dims"] == data.shape[:3]
    with pytest.raises(native.VoxlightError, match="frame 8 requested"):
        native.Volume.load(str(p), frame=8)


def test_cache_of_real_frames_stays_in_budget(tmp_path):
    p = tmp_path / "run.nii"
    write_4d(p)
    one = native.Volume.load(str(p)).info["storage_bytes"]
    c = frames.FrameCache(budget_bytes=3 * one)
    for t in [0, 1, 2, 3, 1, 4, 5, 0]:
        v = c.get(t, lambda: native.Volume.load(str(p), frame=t))
        assert v.info["frame"] == t
        assert c.bytes <= c.budget_bytes
    assert c.keys() == [4, 5, 0] and c.hits == 1 and c.misses == 7
    c.clear()


def test_binding_lists_dicom_series_and_loads_the_chosen_one(tmp_path):
    d = tmp_path / "study"
    d.mkdir()
    px = np.arange(12, dtype=np.uint16).reshape(3, 4) + 1024
    for k in range(4):
        write_dicom(d / f"a{k}.dcm", "1.2.5.1", px + 100 * k, 2.0 * k)
    for k in range(2):
        write_dicom(d / f"b{k}.dcm", "1.2.5.2", px, 3.0 * k, modality="MR")
    s = native.list_dicom_series(str(d))
    assert [x["uid"] for x in s] == ["1.2.5.1", "1.2.5.2"]
    assert s[0]["dims"] == (4, 3, 4) and s[1]["modality"] == "MR" and s[0]["loadable"]
    assert native.list_dicom_series(str(tmp_path / "nothing.nii")) == []
    with pytest.raises(native.VoxlightError, match="2 DICOM series"):
        native.Volume.load(str(d))
    with native.Volume.load(str(d), series=1) as v:
        assert v.info["dims"] == (4, 3, 2)
    with native.Volume.load(str(d), series="1.2.5.1") as v:
        assert v.info["dims"] == (4, 3, 4) and v.info["value_max"] == pytest.approx(11 + 300)


def test_runtime_entry_steps_through_frames(tmp_path):
    p = tmp_path / "run.nii"
    write_4d(p)
    entry = runtime.load_volume(str(p))
    try:
        assert entry.frame == 0 and entry.frame_count == 8

        class Props:
            series = ""
            frame_mode = frames.FOLLOW_TIMELINE
            frame_offset = 1
            fixed_frame = 0

        images = {}
        for scene_frame in (1, 4, 4, 20):
            e = runtime.entry_for(str(p), Props, scene_frame)
            assert e is entry
            assert e.frame == min(scene_frame - 1, 7)
            prm = native.make_params(width=48, height=48, jitter=False, window=(0.0, 80.0))
            images[e.frame] = runtime.render(e, prm)[0]
        assert set(images) == {0, 3, 7}
        assert not np.allclose(images[0], images[3]) and not np.allclose(images[3], images[7])
        # frames seen stay cached: going back is a hit, not a read
        hits = runtime.frame_cache.hits
        runtime.entry_for(str(p), Props, 4)
        assert runtime.frame_cache.hits == hits + 1
        Props.frame_mode, Props.fixed_frame = frames.FIXED, 5
        assert runtime.entry_for(str(p), Props, 1).frame == 5
    finally:
        runtime.release_all()
