"""Overlays through the ctypes binding, without Blender:
Renderer.set_overlay and make_params(overlays=[...]) reach the library.
Seen along z with one pixel per world unit, an overlay in its own grid and
affine shows exactly over the pixels its box covers; its blend modes
differ as the header says; bad overlays are refused. The params' digest
follows the overlays' contents, not their pointers."""

import ctypes

import numpy as np
import pytest

from voxlight.core import native

from test_modes import axis_camera

NX, NY, NZ = 20, 16, 12
RED = np.array([[1, 0, 0, 0], [1, 0, 0, 1]], np.float32)       # value 0: clear, 1: opaque red
GREY = np.array([[0.5, 0.5, 0.5, 0], [0.5, 0.5, 0.5, 0.03]], np.float32)


@pytest.fixture(scope="module")
def lib():
    return native.load_library()


def ball_volume(lib, affine):
    """4^3 voxels of 1 placed by `affine` (voxel -> world)."""
    return native.Volume.from_array(np.ones((4, 4, 4), np.float32), affine=affine, lib=lib)


def shift(tx, ty, tz, scale=1.0):
    a = np.diag([scale, scale, scale, 1.0])
    a[:3, 3] = tx, ty, tz
    return a


@pytest.fixture(scope="module")
def renderer(lib):
    """An empty base (zeros: clear under any table here) with slot 0 holding
    4^3 unit voxels centred from world (10, 3, 4): its box covers x 9.5..13.5,
    y 2.5..6.5, so pixel columns 10..13 and rows 3..6."""
    r = native.Renderer(lib=lib)
    r.set_volume(native.Volume.from_array(np.zeros((NX, NY, NZ), np.float32), lib=lib))
    vol = ball_volume(lib, shift(10, 3, 4))
    r.set_overlay(0, vol)
    vol.close()  # the renderer keeps its own copy
    yield r
    r.close()


def render(lib, r, overlays=(), base_tf=GREY, **kw):
    view, proj, w, h = axis_camera(2, (NX, NY, NZ))
    p = native.make_params(width=w, height=h, view=view, proj=proj, jitter=False, shading=False,
                           tf_rgba=base_tf, window=(0, 1), overlays=list(overlays), lib=lib, **kw)
    return r.render(p)[0]


def footprint(x0, x1, y0, y1):
    """(h, w) mask of pixel columns x0..x1 and rows y0..y1 (inclusive)."""
    m = np.zeros((NY, NX), bool)
    m[y0:y1 + 1, x0:x1 + 1] = True
    return m


def red(slot=0, **kw):
    return dict(dict(slot=slot, tf_rgba=RED, window=(0, 1), shading=False), **kw)


def test_an_overlay_lands_where_its_affine_says(lib, renderer):
    without = render(lib, renderer)
    assert without[..., 3].max() == 0  # the base alone is clear
    img = render(lib, renderer, [red()])
    inside = footprint(10, 13, 3, 6)
    a = img[..., 3]
    assert (a[inside] > 0.9).all(), a[inside]
    # outside its box nothing, apart from the box's own edge pixels
    assert (a[~footprint(9, 14, 2, 7)] == 0).all()
    rgb = img[inside][:, :3] / img[inside][:, 3:]
    assert np.allclose(rgb, [1, 0, 0], atol=0.02)


def test_an_overlay_with_a_scaled_affine_and_the_slot_emptied(lib):
    r = native.Renderer(lib=lib)
    try:
        r.set_volume(native.Volume.from_array(np.zeros((NX, NY, NZ), np.float32), lib=lib))
        # 2 mm voxels from (4.5, 2.5, 4.5): the box covers x 3.5..11.5, y 1.5..9.5
        r.set_overlay(1, ball_volume(lib, shift(4.5, 2.5, 4.5, scale=2.0)))
        a = render(lib, r, [red(slot=1)])[..., 3]
        assert (a[footprint(4, 11, 2, 9)] > 0.9).all()
        assert (a[~footprint(3, 12, 1, 10)] == 0).all()
        r.set_overlay(1, None)  # emptied: the frame no longer shows it
        try:
            a = render(lib, r, [red(slot=1)])[..., 3]
        except native.VoxlightError:
            return  # refusing an empty slot is as honest as drawing nothing
        assert a.max() == 0
    finally:
        r.close()


def test_blends_over_add_and_max_differ_as_the_header_says(lib, renderer):
    base = np.full((NX, NY, NZ), 1.0, np.float32)  # a grey medium everywhere
    r = native.Renderer(lib=lib)
    try:
        r.set_volume(native.Volume.from_array(base, lib=lib))
        r.set_overlay(0, ball_volume(lib, shift(10, 3, 4)))
        inside = footprint(10, 13, 3, 6)
        plain = render(lib, r)
        over = render(lib, r, [red(blend="over")])
        add = render(lib, r, [red(blend="add")])
        mx = render(lib, r, [red(blend="max")])
        for img in (over, add, mx):
            assert np.abs(img[inside] - plain[inside]).max() > 0.05
            # away from the overlay each is the base alone
            assert np.allclose(img[~footprint(9, 14, 2, 7)], plain[~footprint(9, 14, 2, 7)], atol=1e-4)
        # ADD is a glow: it absorbs nothing, so the opacity is the base's
        assert np.allclose(add[inside][:, 3], plain[inside][:, 3], atol=1e-3)
        assert (add[inside][:, 0] > plain[inside][:, 0] + 0.05).all()
        # OVER and MAX absorb: the opaque red ball makes its pixels more opaque
        assert (over[inside][:, 3] > plain[inside][:, 3] + 0.1).all()
        assert (mx[inside][:, 3] > plain[inside][:, 3] + 0.1).all()
        assert np.abs(add[inside] - mx[inside]).max() > 0.05
        # the opacity scale reaches the library
        faint = render(lib, r, [red(blend="over", opacity_scale=0.05)])
        assert (faint[inside][:, 3] < over[inside][:, 3] - 0.05).all()
    finally:
        r.close()


def test_preset_window_and_overlay_style_structs_reach_the_library(lib, renderer):
    by_dict = render(lib, renderer, [dict(slot=0, preset="hot", window=(0, 2), shading=False)])
    s = native.OverlayStyle()
    s.slot, s.preset, s.has_window, s.window_low, s.window_high, s.shading_off = (
        0, lib.index("preset", "hot"), 1, 0.0, 2.0, 1)
    by_struct = render(lib, renderer, [s])
    assert np.array_equal(by_dict, by_struct)
    assert by_dict[footprint(10, 13, 3, 6)][:, 3].min() > 0
    other = render(lib, renderer, [dict(slot=0, preset="hot", window=(0, 1), shading=False)])
    assert not np.array_equal(by_dict, other)


def test_bad_overlays_are_refused(lib, renderer):
    with pytest.raises(native.VoxlightError):
        renderer.set_overlay(native.MAX_OVERLAYS, None)
    with pytest.raises(ValueError):
        render(lib, renderer, [red(slot=i % 3) for i in range(native.MAX_OVERLAYS + 1)])
    with pytest.raises(native.VoxlightError):
        render(lib, renderer, [red(blend="glow")])
    with pytest.raises(ValueError):
        render(lib, renderer, [red(colour=1)])
    # overlays march with the DVR ray caster only (voxlight.h)
    with pytest.raises(native.VoxlightError):
        render(lib, renderer, [red()], mode="mip")
    # the renderer still works afterwards
    assert render(lib, renderer, [red()])[..., 3].max() > 0.9


# ------------------------------------------------------ params (no rendering)

def params(lib, overlays):
    view, proj, w, h = axis_camera(2, (NX, NY, NZ))
    return native.make_params(width=w, height=h, view=view, proj=proj, overlays=overlays, lib=lib)


def test_params_hold_the_overlays_and_their_tables(lib):
    tf = np.linspace(0, 1, 16, dtype=np.float32).reshape(4, 4)
    model = shift(1, 2, 3, scale=0.5)
    p = params(lib, [dict(slot=2, blend="max", interpolation="nearest", tf_rgba=tf, window=(-1, 5),
                          opacity_scale=0.5, shading=False, model=model)])
    del tf
    assert p.overlay_count == 1
    o = p.overlays[0]
    assert o.struct_size == ctypes.sizeof(native.OverlayStyle)
    assert (o.slot, o.blend, o.interpolation, o.interpolation_set) == (2, 2, 0, 1)
    assert (o.has_window, o.window_low, o.window_high, o.opacity_scale, o.shading_off) == (1, -1, 5, 0.5, 1)
    assert o.has_model == 1 and np.allclose(native.matrix_from_cm(o.model), model)
    assert o.tf_size == 4
    table = np.ctypeslib.as_array(o.tf_rgba, (4, 4))
    assert np.array_equal(table, np.linspace(0, 1, 16, dtype=np.float32).reshape(4, 4))
    none = params(lib, None)
    assert none.overlay_count == 0 and not none.overlays


def test_digest_follows_the_overlays_contents_not_pointers(lib):
    def d(**kw):
        return native.params_digest(params(lib, [red(**kw)]))

    assert d() == d()  # built twice: other pointers, the same frame
    assert d() != native.params_digest(params(lib, None))
    assert d() != d(blend="add")
    assert d() != d(opacity_scale=0.5)
    assert d() != d(model=shift(1, 0, 0))
    assert d() != d(tf_rgba=RED * 0.5)


def test_tiles_keep_the_overlays(lib):
    p = params(lib, [red()])
    t = native.tile_params(p, 2, 3, 10, 9)
    assert t.overlay_count == 1
    assert ctypes.addressof(t.overlays.contents) == ctypes.addressof(p.overlays.contents)
    assert t._overlays is p._overlays and t._overlay_tables is p._overlay_tables
