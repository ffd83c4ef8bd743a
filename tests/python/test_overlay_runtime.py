"""The add-on's overlay bookkeeping without Blender (core/overlay_runtime.py):
a slot is uploaded only when its source (file, series, frame, modification
time) changes; a file that fails is reported and not retried until it
changes; plan() draws every visible object exactly once, overlays inside
their base."""

import os

import numpy as np
import pytest

from voxlight.core import native, overlay_runtime

from nifti_write import write_nifti


class FakeRenderer:
    def __init__(self):
        self.calls = []   # (slot, dims or None)

    def set_overlay(self, slot, volume):
        self.calls.append((slot, None if volume is None else tuple(volume.info["dims"])))


class Entry:
    def __init__(self):
        self.renderer = FakeRenderer()


@pytest.fixture
def files(tmp_path):
    a = write_nifti(str(tmp_path / "a.nii"), np.ones((4, 5, 6), np.float32))
    b = write_nifti(str(tmp_path / "b.nii"), np.ones((3, 3, 3), np.uint8))
    return a, b


def test_slots_are_uploaded_only_when_their_source_changes(files):
    a, b = files
    e = Entry()
    assert overlay_runtime.show(e, [(a, "", 0)]) == ["", "", ""]
    assert e.renderer.calls == [(0, (4, 5, 6))]
    key = e.overlay_key
    overlay_runtime.show(e, [(a, "", 0)])
    assert e.renderer.calls == [(0, (4, 5, 6))] and e.overlay_key == key  # nothing again
    overlay_runtime.show(e, [(a, "", 0), (b, "", 0)])
    assert e.renderer.calls[1:] == [(1, (3, 3, 3))]  # only the new slot
    st = os.stat(a)
    os.utime(a, (st.st_atime, st.st_mtime + 5))  # the file changed on disk
    overlay_runtime.show(e, [(a, "", 0), (b, "", 0)])
    assert e.renderer.calls[2:] == [(0, (4, 5, 6))]
    assert e.overlay_key != key
    overlay_runtime.show(e, [None, (b, "", 0)])
    assert e.renderer.calls[3:] == [(0, None)]  # emptied
    overlay_runtime.show(e, [])
    assert e.renderer.calls[4:] == [(1, None)] and e.overlay_key is None


def test_a_file_that_fails_is_reported_and_not_retried_until_it_changes(tmp_path, files):
    bad = tmp_path / "bad.nii"
    bad.write_bytes(b"not a nifti file at all" * 20)
    e = Entry()
    errors = overlay_runtime.show(e, [(files[0], "", 0), (str(bad), "", 0)])
    assert errors[0] == "" and "bad.nii" in errors[1] or errors[1], errors
    assert errors[1] and overlay_runtime.failure(str(bad))
    assert e.renderer.calls == [(0, (4, 5, 6))]  # slot 1 stays empty
    again = overlay_runtime.show(e, [(files[0], "", 0), (str(bad), "", 0)])
    assert again[1] == errors[1] and e.renderer.calls == [(0, (4, 5, 6))]
    write_nifti(str(bad), np.zeros((2, 2, 2), np.float32))  # fixed: loads now
    st = os.stat(bad)
    os.utime(bad, (st.st_atime, st.st_mtime + 5))
    assert overlay_runtime.show(e, [(files[0], "", 0), (str(bad), "", 0)]) == ["", "", ""]
    assert e.renderer.calls[1:] == [(1, (2, 2, 2))]


def test_a_missing_file_is_an_error_naming_it(tmp_path):
    e = Entry()
    errors = overlay_runtime.show(e, [(str(tmp_path / "gone.nii"), "", 0)])
    assert "gone.nii" in errors[0]
    assert e.renderer.calls == [] and e.overlay_key is None


def test_phantoms_and_frames_are_sources_too():
    e = Entry()
    assert overlay_runtime.show(e, [("phantom:sphere:8x8x8", "", 0)]) == ["", "", ""]
    assert e.renderer.calls == [(0, (8, 8, 8))]
    assert overlay_runtime.source_key("phantom:sphere:8x8x8", "", 0) != overlay_runtime.source_key(
        "phantom:sphere:8x8x8", "", 1)


def plan(objects, lists):
    return [(b, list(o)) for b, o in overlay_runtime.plan(objects, lambda o: lists.get(o, []))]


def test_plan_fuses_overlays_into_their_base_once():
    assert plan("ABC", {"A": ["B"]}) == [("A", ["B"]), ("C", [])]
    # invisible overlays are not fused (the object list is the visible ones)
    assert plan("AC", {"A": ["B"]}) == [("A", []), ("C", [])]
    # an object never lists itself
    assert plan("A", {"A": ["A"]}) == [("A", [])]
    # a chain: C is listed by B, which is drawn inside A, so C is drawn alone
    assert plan("ABC", {"A": ["B"], "B": ["C"]}) == [("A", ["B"]), ("C", [])]
    # a cycle: every object still shows exactly once
    got = plan("AB", {"A": ["B"], "B": ["A"]})
    assert got == [("A", ["B"])]
    # two bases listing one overlay: the first takes it
    assert plan("ABX", {"A": ["X"], "B": ["X"]}) == [("A", ["X"]), ("B", [])]
    # more than MAX_OVERLAYS: the rest are drawn on their own
    many = "BCDE"[:native.MAX_OVERLAYS + 1]
    got = plan("A" + many, {"A": list(many)})
    assert got[0] == ("A", list(many[:native.MAX_OVERLAYS]))
    assert got[1:] == [(o, []) for o in many[native.MAX_OVERLAYS:]]
    shown = [b for b, _ in got] + [o for _, ovs in got for o in ovs]
    assert sorted(shown) == sorted("A" + many)
