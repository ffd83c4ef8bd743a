"""in the ctypes binding and the add-on's bpy-free runtime:
Volume.load(streaming=, cache_dir=, progress=), cancelling from the
progress callable (VoxlightError with code ERR_CANCELLED, no partial cache),
and one memory budget split between the volume and its renderer."""

import gc

import numpy as np
import pytest

from voxlight.core import budget_split, import_job, native, native_volume, runtime
from nifti_write import write_nifti


def blobs(n):
    """Soft balls on an empty background, x fastest as nifti_write wants."""
    i, j, k = np.mgrid[0:n, 0:n, 0:n].astype(np.float32)
    d = np.sqrt((i - n * 0.4) ** 2 + (j - n * 0.55) ** 2 + (k - n * 0.5) ** 2)
    return (220.0 / (1.0 + np.exp(np.clip(d - n * 0.25, -50, 50)))).astype(np.uint8)


@pytest.fixture()
def gz(tmp_path):
    """A .nii.gz: its first streamed open writes a bricked cache."""
    return str(write_nifti(tmp_path / "blobs.nii.gz", blobs(64), np.eye(4)))


@pytest.fixture()
def cache(tmp_path):
    d = tmp_path / "cache"
    d.mkdir()
    return d


@pytest.fixture()
def renderers(monkeypatch):
    """The memory_budget every Renderer was made with, in order."""
    budgets = []
    real = native.Renderer.__init__

    def init(self, *a, **kw):
        budgets.append(kw.get("memory_budget", 0))
        real(self, *a, **kw)
    monkeypatch.setattr(native.Renderer, "__init__", init)
    return budgets


def test_streaming_modes_reach_the_library(tmp_path):
    path = str(write_nifti(tmp_path / "blobs.nii", blobs(32), np.eye(4)))
    with native.Volume.load(path, streaming="on") as on, native.Volume.load(path, streaming="off") as off:
        assert on.info["streamed"] is True and on.info["level_count"] >= 1
        assert off.info["streamed"] is False and off.info["level_count"] == 1
        assert on.info["dims"] == off.info["dims"] == (32, 32, 32)
        assert on.info["value_max"] == off.info["value_max"]
    with pytest.raises(native.VoxlightError, match="streaming"):
        native.Volume.load(path, streaming="sometimes")


def test_progress_is_reported_and_the_cache_goes_to_cache_dir(gz, cache):
    seen = []

    def progress(fraction, stage):
        gc.collect()  # the callback object must survive a collection mid-load
        seen.append((fraction, stage))
        return False
    with native.Volume.load(gz, streaming="on", cache_dir=str(cache), progress=progress) as v:
        assert v.info["streamed"]
    assert seen, "no progress for a first open of a .nii.gz"
    assert all(0.0 <= f <= 1.0 and isinstance(s, str) for f, s in seen), seen
    assert any(s for _f, s in seen), seen  # what is being done, named
    assert max(f for f, _ in seen) == pytest.approx(1.0)
    assert list(cache.iterdir()), "no cache in cache_dir"


def test_a_true_return_cancels_with_err_cancelled_and_no_cache(gz, cache):
    calls = []

    def stop(fraction, stage):
        calls.append(fraction)
        return True
    with pytest.raises(native.VoxlightError) as err:
        native.Volume.load(gz, streaming="on", cache_dir=str(cache), progress=stop)
    assert err.value.code == native_volume.ERR_CANCELLED == 10  # VXL_ERR_CANCELLED
    assert len(calls) == 1  # the library stopped at the first answer
    assert list(cache.iterdir()) == []


def test_an_exception_in_progress_cancels_and_is_raised_again(gz, cache):
    class Boom(Exception):
        pass

    def progress(fraction, stage):
        raise Boom("from the callback")
    with pytest.raises(Boom):
        native.Volume.load(gz, streaming="on", cache_dir=str(cache), progress=progress)
    assert list(cache.iterdir()) == []


def test_budget_split_adds_up():
    for total in (1 << 20, 2 << 30, (3 << 30) + 1):
        vol = budget_split.volume_share(total)
        assert vol == total // 2
        assert vol + budget_split.renderer_share(total, streamed=True) == total
        assert budget_split.renderer_share(total, streamed=False) == total
    # 0 is the library's default of 2 GiB for both
    assert budget_split.volume_share(0) == 1 << 30
    assert budget_split.renderer_share(0, streamed=True) == 1 << 30
    assert budget_split.renderer_share(0, streamed=False) == 0


def test_open_volume_splits_the_budget(tmp_path, renderers, monkeypatch):
    path = str(write_nifti(tmp_path / "blobs.nii", blobs(32), np.eye(4)))
    total = 64 << 20
    monkeypatch.setitem(runtime.stream_settings, "streaming", "on")
    e = runtime.open_volume(path, memory_budget=total)
    try:
        assert e.info["streamed"] and renderers == [total - total // 2]
        assert e.load_kwargs["memory_budget"] == total // 2 and e.load_kwargs["streaming"] == "on"
    finally:
        e.close()
    monkeypatch.setitem(runtime.stream_settings, "streaming", "off")
    e = runtime.open_volume(path, memory_budget=total)
    try:
        assert not e.info["streamed"] and renderers[-1] == total  # freed once uploaded: all for the renderer
    finally:
        e.close()


def test_import_job_reports_and_cancels_the_first_pass(gz, cache, renderers, monkeypatch):
    monkeypatch.setitem(runtime.stream_settings, "streaming", "on")
    monkeypatch.setitem(runtime.stream_settings, "cache_dir", str(cache))
    stages = []
    job = import_job.ImportJob(gz, start=False)
    real = job._set_load_progress

    def note(fraction, stage):
        real(fraction, stage)
        stages.append((job.progress, job.stage))
        job.cancel()  # as Esc does, from the first report on
    job._set_load_progress = note
    job.run()
    assert stages and isinstance(stages[0][1], str) and 0.0 <= stages[0][0] <= import_job.ImportJob.LOAD_SHARE
    assert job.take() is None and job.error is None  # cancelled, not failed
    assert renderers == [] and list(cache.iterdir()) == []
    assert runtime.find_entry(gz) is None
