"""runtime.Worker runs Jobs with `run` (the viewport's scene shadows) on the renderer's thread like banded frames: the result comes
back, a newer job of the same owner replaces a queued one, and a job
cancelled while it runs ends with no result."""

import threading
import time
import types

from voxlight.core import runtime


def _wait(pred, timeout=120.0):  # a bound on a hang, not a speed check: the 2-core CI machine may be busy
    end = time.monotonic() + timeout
    while not pred():
        assert time.monotonic() < end, "timed out"
        time.sleep(0.005)


def _worker():
    # run() never touches the entry's renderer: a stand-in is enough.
    return runtime.Worker(types.SimpleNamespace(renderer=None, last_frame=None))


def test_a_run_job_gives_its_return_value():
    w = _worker()
    try:
        job = runtime.Job("owner", "key", None)
        job.run = lambda stop: ("shadow", stop())
        w.submit(job)
        _wait(lambda: job.done)
        assert job.result == ("shadow", False) and job.error is None and not job.cancelled
    finally:
        w.close()


def test_a_run_job_cancelled_while_running_has_no_result():
    w = _worker()
    started, release = threading.Event(), threading.Event()

    def slow(stop):
        started.set()
        release.wait(5.0)
        return None if stop() else "stale"
    try:
        job = runtime.Job("owner", "key", None)
        job.run = slow
        w.submit(job)
        assert started.wait(5.0)
        newer = runtime.Job("owner", "key2", None)
        newer.run = lambda stop: "fresh"
        w.submit(newer)   # cancels the running one of the same owner
        release.set()
        _wait(lambda: job.done and newer.done)
        assert job.result is None and job.cancelled
        assert newer.result == "fresh"
    finally:
        w.close()


def test_errors_are_kept_for_the_main_thread():
    w = _worker()
    try:
        job = runtime.Job("owner", "key", None)
        job.run = lambda stop: 1 / 0
        w.submit(job)
        _wait(lambda: job.done)
        assert isinstance(job.error, ZeroDivisionError) and job.result is None
    finally:
        w.close()


class _Renderer:
    closed = False

    def close(self):
        self.closed = True


def test_closing_waits_for_a_stuck_job_only_as_long_as_its_bound():
    """A job that does not let go (a hung library call) must not freeze the
    caller of close(): the wait ends after its bound, and the renderer the
    call still uses stays open; once the job ends, closing completes."""
    release = threading.Event()
    entry = runtime.VolumeEntry("/data/scan.nii.gz", _Renderer(), info={})
    job = runtime.Job("owner", "key", None)
    job.run = lambda stop: release.wait(600)  # ignores stop(), as a hung call would
    entry.worker.submit(job)
    _wait(lambda: entry.worker.busy() and not entry.worker._queue)
    msg = entry.close(timeout=0.2)
    assert "scan.nii.gz" in msg and "still busy after 0 s" in msg and "left open" in msg, msg
    assert not entry.renderer.closed
    release.set()
    assert entry.close(timeout=60.0) == ""
    assert entry.renderer.closed
