"""The importer's worker (plugin/core/import_job.py) and runtime.open_volume
without Blender: a load on a thread, errors as messages, and cancelling
before, during and after the load keeps nothing alive or registered."""

import os
import sys
import threading

import numpy as np
import pytest

from voxlight.core import import_job, native, runtime
from nifti_write import phantom, write_nifti


@pytest.fixture()
def ball(tmp_path):
    return str(write_nifti(tmp_path / "ball.nii.gz", phantom(16), np.diag([2.0, 2.0, 2.0, 1.0])))


@pytest.fixture()
def renderers(monkeypatch):
    """Every Renderer made during the test, to check that each is closed."""
    made = []
    real = native.Renderer.__init__

    def init(self, *a, **kw):
        real(self, *a, **kw)
        made.append(self)
    monkeypatch.setattr(native.Renderer, "__init__", init)
    return made


def test_job_loads_on_a_thread_without_registering(ball):
    job = import_job.ImportJob(ball)
    assert job.wait(120) and job.done
    assert job.error is None and job.progress == 1.0
    entry = job.take()
    try:
        assert entry.info["dims"] == (16, 16, 16)
        assert runtime.find_entry(ball) is None  # the importer adopts it after creating the object
        runtime.adopt(entry)
        assert runtime.find_entry(ball) is entry
    finally:
        runtime.release_all()


def test_job_error_is_the_library_message(tmp_path, renderers):
    bad = tmp_path / "bad.nrrd"
    bad.write_bytes(b"NRRD0004\ntype: float\ndimension: 3\nsizes: 100000 100000 100000\nencoding: raw\nendian: little\n\n")
    job = import_job.ImportJob(str(bad))
    assert job.wait(60)
    assert job.take() is None and "bad.nrrd" in job.error and "memory budget" in job.error
    assert renderers == []  # nothing was made for a file that did not load


def test_voxel_size_reaches_the_library(tmp_path):
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "cli"))
    from test_cli_formats import write_tiff
    path = tmp_path / "pages.tif"
    write_tiff(path, [np.full((5, 4), k, np.uint16) for k in range(3)])
    job = import_job.ImportJob(str(path), voxel_size=(0.5, 0.25, 2.0))
    assert job.wait(120) and job.error is None
    entry = job.take()
    try:
        assert entry.info["spacing"] == (0.5, 0.25, 2.0)
        assert np.allclose(np.diag(entry.info["affine"]), [0.5, 0.25, 2.0, 1.0])
    finally:
        entry.close()


def test_cancel_between_steps_closes_everything(ball, renderers):
    assert runtime.open_volume(ball, cancelled=lambda: True) is None
    calls = []

    def after_renderer():  # cancelled once the renderer exists
        calls.append(1)
        return len(calls) >= 2
    assert runtime.open_volume(ball, cancelled=after_renderer) is None
    assert len(renderers) == 1 and renderers[0]._handle is None


def test_cancel_during_the_load_discards_the_late_result(ball, renderers, monkeypatch):
    gate = threading.Event()
    real_load = native.Volume.load

    def slow_load(*a, **kw):
        gate.wait(60)
        return real_load(*a, **kw)
    monkeypatch.setattr(native.Volume, "load", slow_load)
    job = import_job.ImportJob(ball)
    job.cancel()  # returns at once, the load is still blocked
    assert not job.done and job.cancelled
    gate.set()
    assert job.wait(120)
    assert job.take() is None and job.error is None
    assert all(r._handle is None for r in renderers)
    assert runtime.find_entry(ball) is None


def test_cancel_after_the_load_closes_the_result(ball, renderers):
    job = import_job.ImportJob(ball)
    assert job.wait(120)
    job.cancel()
    assert job.take() is None
    assert len(renderers) == 1 and renderers[0]._handle is None


def test_names_and_filter():
    assert import_job.display_name("/d/brain.nii.gz") == "brain"
    assert import_job.display_name("/d/ct.NRRD") == "ct"
    assert import_job.display_name("/d/series/") == "series"
    assert import_job.display_name("/d/DICOMDIR") == "DICOMDIR"
    for pattern in ("*.nii.gz", "*.nhdr", "*.mhd", "*.tiff", "*.png", "*.vdb", "*.dcm", "DICOMDIR"):
        assert pattern in import_job.FILTER_GLOB.split(";")
    assert import_job.is_vdb("/x/Smoke.VDB") and not import_job.is_vdb("/x/a.nii")


INFO = {"dims": (4, 3, 2), "dtype": "int16", "streamed": False, "level_count": 1}


def test_import_report_names_what_the_reader_decided():
    notes = "PixelSpacing missing: 1 mm assumed; 2 slices interpolated where slices are missing"
    text = import_job.import_report("head", dict(INFO, notes=notes), "as an intensity volume")
    assert text == ("Voxlight: imported head (4 x 3 x 2, int16) as an intensity volume - reader notes: "
                    "PixelSpacing missing: 1 mm assumed; 2 slices interpolated where slices are missing")
    assert import_job.note_lines(notes) == ["PixelSpacing missing: 1 mm assumed",
                                            "2 slices interpolated where slices are missing"]


def test_import_report_without_notes_is_unchanged():
    for info in (INFO, dict(INFO, notes="")):  # an info from an older library has no notes
        assert import_job.import_report("head", info, "as an intensity volume") == \
            "Voxlight: imported head (4 x 3 x 2, int16) as an intensity volume"
    streamed = dict(INFO, streamed=True, level_count=3, notes="cut...")
    assert import_job.import_report("big", streamed, "as an intensity volume") == \
        "Voxlight: imported big (4 x 3 x 2, int16, streamed from disk (3 levels)) as an intensity volume" \
        " - reader notes: cut..."
    assert import_job.note_lines("") == [] and import_job.note_lines(None) == []
    assert import_job.note_lines("one;two; ; three") == ["one;two", "three"]


def test_a_load_without_decisions_has_empty_notes(ball):
    job = import_job.ImportJob(ball)
    assert job.wait(120) and job.error is None
    entry = job.take()
    try:
        assert entry.info["notes"] == ""
    finally:
        entry.close()
