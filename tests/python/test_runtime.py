"""The viewport's background worker (plugin/core/runtime.py) against the real
library: newest frame wins, stale frames are dropped between bands, the
renderer is free again within one band, close() joins the thread."""

import threading
import time

import numpy as np
import pytest

from voxlight.core import native, runtime
from nifti_write import phantom, write_nifti


@pytest.fixture()
def entry(tmp_path):
    path = tmp_path / "ball.nii.gz"
    write_nifti(path, phantom(48), np.diag([2.0, 2.0, 2.0, 1.0]))
    e = runtime.load_volume(str(path))
    yield e
    runtime.release_all()


def _params(entry, w=96, h=96, **kw):
    r = entry.renderer
    view, proj = r.default_camera(width=w, height=h)
    return native.make_params(width=w, height=h, view=view, proj=proj, **kw)


def _wait(pred, timeout=60.0):
    t = time.monotonic()
    while not pred():
        if time.monotonic() - t > timeout:
            raise AssertionError("timed out")
        time.sleep(0.005)


def test_job_renders_what_a_direct_render_gives(entry):
    p = _params(entry, filter="sobel26")
    frames = runtime.render_count
    job = entry.worker.submit(runtime.Job("owner", "k1", p))
    _wait(lambda: job.done)
    assert job.result is not None and job.error is None and not job.cancelled
    direct, _ = entry.renderer.render(p)
    assert np.abs(job.result[0] - direct).max() < 5e-3
    assert runtime.render_count == frames + 1  # direct Renderer calls are no frames
    assert entry.last_frame["kind"] == "refined" and not entry.busy()


def test_newest_job_wins_and_stale_jobs_are_dropped(entry):
    big = _params(entry, w=320, h=320, filter="sobel26", step=0.1)
    dropped = runtime.cancelled_count
    first = entry.worker.submit(runtime.Job("owner", "k1", big))
    _wait(lambda: first.done or entry.worker._running is first)
    # Built before the counter is read: default_camera is a library call that
    # waits for the renderer, so building it afterwards would let the first
    # job render more bands (the lock is not fair) before it is cancelled.
    small = _params(entry)
    calls_at_cancel = runtime.call_count
    second = entry.worker.submit(runtime.Job("owner", "k2", small))
    _wait(lambda: second.done)
    assert first.done and first.cancelled and first.result is None
    assert second.result is not None
    # The first job stopped after at most the band that was running (and one
    # that may have started between reading the counter and submitting).
    assert runtime.call_count - calls_at_cancel <= 2 + second.result[2]["calls"]
    assert runtime.cancelled_count == dropped + 1
    # A queued job that is replaced before it starts is never rendered.
    blocker = entry.worker.submit(runtime.Job("a", "k3", big))
    queued = entry.worker.submit(runtime.Job("b", "k4", big))
    newer = entry.worker.submit(runtime.Job("b", "k5", _params(entry)))
    entry.worker.cancel(blocker)
    _wait(lambda: newer.done)
    assert queued.cancelled and queued.result is None and newer.result is not None


def test_renderer_is_free_within_a_band(entry):
    """A synchronous render on another thread waits for the band in flight
    only, never for the whole slow frame, once the job is cancelled.

    Counted in library calls, not seconds (a wall-clock ratio failed on a
    loaded 2-core CI runner): after the cancel, the job renders at most the
    band in flight and one that passed its stop check just before."""
    slow = _params(entry, w=400, h=400, filter="sobel26", step=0.05)
    start = runtime.call_count
    job = entry.worker.submit(runtime.Job("owner", "slow", slow))
    _wait(lambda: runtime.call_count >= start + 2)  # mid-frame: some bands done
    calls_at_cancel = runtime.call_count
    entry.worker.cancel(job)
    entry.renderer.render(_params(entry, w=32, h=32))  # waits for the renderer
    _wait(lambda: job.done)
    assert job.cancelled and job.result is None
    job_bands_after_cancel = runtime.call_count - calls_at_cancel - 1  # minus our render
    assert 0 <= job_bands_after_cancel <= 2, job_bands_after_cancel
    # and the frame really was long: far more bands than the job got to render
    full = entry.renderer.render_tiled(slow, target_seconds=entry.worker.target_seconds)
    assert full[2]["calls"] > calls_at_cancel - start + job_bands_after_cancel + 2, full[2]["calls"]


def test_close_stops_the_thread(entry):
    worker = entry.worker
    job = worker.submit(runtime.Job("owner", "k", _params(entry, w=256, h=256, step=0.05)))
    thread = worker._thread
    runtime.release_all()
    assert not thread.is_alive() and job.done
    assert threading.active_count() >= 1
