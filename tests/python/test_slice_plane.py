"""Slice planes and cutaways without Blender: the pure maths of
core/slice_plane.py and core/cutaway_space.py, Renderer.render_slice
against numpy, and the cutaway/MatCap structs make_params builds."""

import ctypes

import numpy as np
import pytest

from voxlight.core import cutaway_space, native, slice_plane


def _rot(axis, deg):
    a = np.radians(deg)
    c, s = np.cos(a), np.sin(a)
    i, j = [k for k in range(3) if k != axis]
    m = np.eye(4)
    m[i, i], m[i, j], m[j, i], m[j, j] = c, -s, s, c
    return m


def _trs(t=(0, 0, 0), r=np.eye(4), s=(1, 1, 1)):
    m = r @ np.diag(list(s) + [1.0])
    m[:3, 3] = t
    return m


# ------------------------------------------------------------ pure maths

def test_clip_plane_keeps_the_local_plus_z_side():
    m = _trs((1, 2, 3), _rot(0, 30) @ _rot(2, 45), (2, 3, 0.5))
    plane = cutaway_space.clip_plane(m)
    assert abs(np.linalg.norm(plane[:3]) - 1) < 1e-12
    # local (x, y, z) -> world; the plane's value is the world distance from local z = 0
    for local, want_sign in (((0.3, -2, 1), 1), ((5, 1, -1), -1), ((1, 1, 0), 0)):
        w = m @ np.array(list(local) + [1.0])
        d = cutaway_space.signed_distance(plane, w[:3])[0]
        assert np.sign(round(d, 9)) == want_sign
    # distance is in world units: local z = 1 is 0.5 world units along the scaled z
    w = m @ np.array([0, 0, 1.0, 1])
    assert abs(cutaway_space.signed_distance(plane, w[:3])[0] - 0.5) < 1e-12
    with pytest.raises(ValueError):
        cutaway_space.clip_plane(np.diag([1, 1, 0, 1.0]))


def test_crop_box_is_the_empty_cube():
    m = _trs((1, 0, 0), _rot(2, 30), (2, 1, 1))
    box = cutaway_space.crop_box(m, 0.5)
    corner = box @ np.array([1, 1, 1, 1.0])
    assert np.allclose(corner, m @ np.array([0.5, 0.5, 0.5, 1]))
    with pytest.raises(ValueError):
        cutaway_space.crop_box(m, 0.0)


def test_cutaway_spec_repr_follows_the_contents():
    a = cutaway_space.CutawaySpec(clip_planes=[((0, 0, 1, 0), 0.0)], crop_box=None, cutters=[],
                                  caps=True)
    b = cutaway_space.CutawaySpec(clip_planes=[((0, 0, 1, 0.1), 0.0)], crop_box=None, cutters=[],
                                  caps=True)
    assert repr(a) != repr(b) and repr(a) == repr(cutaway_space.CutawaySpec(a))
    assert "array" not in repr(a)


def test_plane_to_world_maps_the_mesh_rectangle():
    mw = _trs((1, 2, 3), _rot(1, 20), (2, 2, 2))
    p = slice_plane.plane_to_world(mw, (-0.5, -1, 0), (1.5, 1, 0))
    # the square's corners are the rectangle's corners, through matrix_world
    assert np.allclose(p @ [-1, -1, 0, 1], mw @ [-0.5, -1, 0, 1])
    assert np.allclose(p @ [1, 1, 0, 1], mw @ [1.5, 1, 0, 1])
    with pytest.raises(ValueError):
        slice_plane.plane_to_world(mw, (0, 0, 0), (0, 1, 0))
    with pytest.raises(ValueError):
        slice_plane.plane_to_world(np.diag([1, 0, 1, 1.0]), (-1, -1, 0), (1, 1, 0))


def test_image_size_is_about_a_pixel_per_voxel():
    model = np.diag([0.5, 1.0, 2.0, 1.0])
    p = slice_plane.plane_to_world(np.eye(4), (-10, -5, 0), (10, 5, 0))  # 20 x 10 world units
    assert slice_plane.image_size(p, model, 1024) == (40, 20)
    assert slice_plane.image_size(p, model, 20) == (20, 10)  # the longer side capped, aspect kept
    assert slice_plane.image_size(p, np.diag([100.0, 100, 100, 1]), 1024) == (1, 1)


def test_inside_volume_and_pixel_positions():
    model = _trs((10, 0, 0), s=(2, 2, 2))
    dims = (4, 5, 6)
    pts = np.array([[10 - 1.0, 0, 0], [10 - 1.01, 0, 0], [10 + 7, 9, 11], [10 + 7.1, 9, 11]])
    assert list(slice_plane.inside_volume(pts, model, dims)) == [True, False, True, False]
    p = slice_plane.plane_to_world(np.eye(4), (0, 0, 0), (4, 2, 0))
    pos = slice_plane.pixel_positions(p, 4, 2)
    assert pos.shape == (2, 4, 3)
    assert np.allclose(pos[0, 0], [0.5, 0.5, 0]) and np.allclose(pos[1, 3], [3.5, 1.5, 0])


# ------------------------------------------------------------ the library

def _ramp_volume(lib):
    """u8 voxels v = i + 10 j + 50 k (exact after normalising by 255)."""
    i, j, k = np.meshgrid(np.arange(6), np.arange(5), np.arange(4), indexing="ij")
    data = (i + 10 * j + 50 * k).astype(np.uint8)
    data[0, 0, 0], data[-1, -1, -1] = 0, 255
    return data, native.Volume.from_array(data, lib=lib)


def test_render_slice_nearest_equals_the_voxels(lib, renderer):
    data, vol = _ramp_volume(lib)
    with vol:
        renderer.set_volume(vol)
    model = _trs((3, -1, 2), _rot(2, 25), (1.5, 1.5, 1.5))
    plane = slice_plane.plane_to_world(_trs((0, 0, 0), _rot(0, 15)) @ model, (-1.3, -1.2, 0),
                                       (6.7, 5.4, 0))
    w, h = 37, 29
    p = native.make_params(width=w, height=h, model=model, window=(0, 255),
                           tf_rgba=[[0, 0, 0, 1], [1, 1, 1, 1]])
    rgba = renderer.render_slice(p, plane, "nearest")
    assert rgba.shape == (h, w, 4)
    pos = slice_plane.pixel_positions(plane, w, h)
    inside = slice_plane.inside_volume(pos, model, data.shape)
    assert 50 < inside.sum() < w * h
    q = pos @ np.linalg.inv(model)[:3, :3].T + np.linalg.inv(model)[:3, 3]
    idx = np.clip(np.floor(q + 0.5).astype(int), 0, np.array(data.shape) - 1)
    want = data[idx[..., 0], idx[..., 1], idx[..., 2]] / 255.0
    frac = np.abs(q - np.floor(q) - 0.5)
    clear = inside & (frac > 1e-4).all(-1)  # no pixel on a voxel boundary
    edge = np.abs(q + 0.5).min(-1) > 1e-4
    assert np.abs(rgba[..., 0][clear] - want[clear]).max() < 1e-6
    assert (rgba[..., 3][inside & edge] == 1).all()
    assert (rgba[~inside & edge] == 0).all()
    # moving the plane moves the image: a shifted plane samples other voxels
    moved = renderer.render_slice(p, _trs((0, 0, 1.5)) @ plane, "nearest")
    assert not np.array_equal(moved, rgba)
    with pytest.raises(native.VoxlightError, match="interpolation"):
        renderer.lib.index("interpolation", "bogus")
    with pytest.raises(native.VoxlightError, match="singular"):
        renderer.render_slice(p, np.diag([1, 0, 1, 1.0]), "linear")


def test_make_params_carries_mode_cutaway_and_matcap(lib):
    verts = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], np.float64)
    tris = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    cut = cutaway_space.CutawaySpec(clip_planes=[((0, 0, 1, -0.5), 0.25)],
                                    crop_box=np.diag([2, 2, 2, 1.0]),
                                    cutters=[(verts, tris, True)], caps=False)
    matcap = np.random.default_rng(1).random((8, 6, 3)).astype(np.float32)
    p = native.make_params(width=8, height=8, mode="mip", cutaway=cut, matcap=matcap,
                           matcap_key=7, lib=lib)
    assert p.mode == lib.index("mode", "mip")
    c = p.cutaway.contents
    assert c.clip_plane_count == 1 and list(c.clip_planes[0].plane) == [0, 0, 1, -0.5]
    assert c.clip_planes[0].thickness == 0.25 and c.has_crop == 1 and c.caps_off == 1
    assert c.crop_box[0] == 2 and c.crop_box[15] == 1
    assert c.cutter_count == 1
    k = c.cutters[0]
    assert k.remove_outside == 1 and k.vertex_count == 4 and k.triangle_count == 4
    assert k.struct_size == ctypes.sizeof(native.Cutter)
    assert [k.indices[i] for i in range(12)] == tris.ravel().tolist()
    assert k.vertices[3] == 1.0
    m = p.matcap.contents
    assert (m.width, m.height, m.key) == (6, 8, 7)
    assert m.rgba[3] == 1.0 and abs(m.rgba[0] - matcap[0, 0, 0]) < 1e-7
    # equal contents, equal digest; a moved plane changes it
    q = native.make_params(width=8, height=8, mode="mip", cutaway=cutaway_space.CutawaySpec(cut),
                           matcap=matcap, matcap_key=7, lib=lib)
    assert native.params_digest(p) == native.params_digest(q)
    cut2 = cutaway_space.CutawaySpec(cut, clip_planes=[((0, 0, 1, -0.4), 0.25)])
    r = native.make_params(width=8, height=8, mode="mip", cutaway=cut2, matcap=matcap,
                           matcap_key=7, lib=lib)
    assert native.params_digest(p) != native.params_digest(r)
    # a tile of the params points at the same structs
    p.has_camera = 1
    p.proj[0] = p.proj[5] = p.proj[10] = p.proj[15] = 1.0
    t = native.tile_params(p, 0, 0, 4, 4)
    assert t.cutaway.contents.cutter_count == 1 and t.matcap.contents.width == 6
    with pytest.raises(ValueError):
        native.make_params(cutaway={"clip_planes": [((0, 0, 1, 0), 0)] * 7}, lib=lib)
    with pytest.raises(ValueError):
        native.make_params(matcap=np.zeros((4, 4)), lib=lib)
