"""Label maps through the ctypes binding, without Blender:
Renderer.set_labels and make_params(labels=(mode, entries)) reach the
library. Seen along z with one pixel per voxel, a label volume of 2x2 voxel
columns shows each column's label colour; hiding a label empties exactly its
pixels; recolouring re-uploads only the table; bad labels are refused."""

import numpy as np
import pytest

from voxlight.core import native

from test_modes import axis_camera

NX, NY, NZ = 14, 12, 10


@pytest.fixture(scope="module")
def lib():
    return native.load_library()


@pytest.fixture(scope="module")
def ids():
    i, j = np.meshgrid(np.arange(NX), np.arange(NY), indexing="ij")
    col = 1 + i // 2 + 7 * (j // 2)
    a = np.zeros((NX, NY, NZ), np.uint16)
    a[:, :, 2:8] = col[:, :, None]
    return a


@pytest.fixture(scope="module")
def renderer(lib, ids):
    r = native.Renderer(lib=lib)
    r.set_volume(native.Volume.from_array(np.zeros((NX, NY, NZ), np.float32), lib=lib))
    r.set_labels(native.Volume.from_array(ids, lib=lib))
    yield r
    r.close()


def colour(i):
    return (i / 42.0, 1 - i / 42.0, 0.5, 1.0)


def render(lib, renderer, entries, mode="surface"):
    view, proj, w, h = axis_camera(2, (NX, NY, NZ))
    p = native.make_params(width=w, height=h, view=view, proj=proj, jitter=False, shading=False,
                           labels=(mode, entries), lib=lib)
    return renderer.render(p)[0]


def test_each_column_shows_its_label_colour(lib, renderer, ids):
    entries = [(i, colour(i), True) for i in range(1, 43)]
    rgba = render(lib, renderer, entries)
    want = np.array([colour(i) for i in range(43)], np.float32)[ids[:, :, 4]].transpose(1, 0, 2)
    assert np.abs(rgba - want).max() < 1e-5


def test_hiding_a_label_empties_exactly_its_pixels(lib, renderer, ids):
    entries = [(i, colour(i), True) for i in range(1, 43)]
    before = render(lib, renderer, entries)
    entries[9] = (10, colour(10), False)
    after = render(lib, renderer, entries)
    changed = np.any(before != after, axis=2)
    assert np.array_equal(changed, (ids[:, :, 4] == 10).T)
    assert np.all(after[changed] == 0)


def test_recolouring_uploads_only_the_table(lib, renderer):
    entries = [(i, colour(i), True) for i in range(1, 43)]
    render(lib, renderer, entries)
    v0, t0 = renderer.label_uploads()
    entries[0] = (1, (1, 0, 0, 1), True)
    render(lib, renderer, entries)
    render(lib, renderer, entries)
    assert renderer.label_uploads() == (v0, t0 + 1)


@pytest.mark.parametrize("entries, words", [
    ([(1, (1, 0, 0, 1), True), (1, (0, 1, 0, 1), True)], "twice"),
    ([(70000, (1, 0, 0, 1), True)], "70000"),
    ([(1, (float("nan"), 0, 0, 1), True)], "color[0]"),
])
def test_bad_labels_are_refused(lib, renderer, entries, words):
    with pytest.raises(native.VoxlightError, match=words.replace("[", r"\[").replace("]", r"\]")):
        render(lib, renderer, entries)


def test_unknown_mode_and_float_labels_are_refused(lib, renderer):
    with pytest.raises(Exception):
        render(lib, renderer, [(1, (1, 0, 0, 1), True)], mode="glow")
    r = native.Renderer(lib=lib)
    try:
        with pytest.raises(native.VoxlightError, match="integers"):
            r.set_labels(native.Volume.from_array(np.zeros((4, 4, 4), np.float32), lib=lib))
    finally:
        r.close()
