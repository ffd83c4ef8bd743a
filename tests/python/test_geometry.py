"""bpy-free maths of the add-on: depth conversions, the numpy z-buffer,
volume placement and the light mapping."""

import numpy as np
import pytest

from voxlight.core import depth, lights, volume_space, zbuffer


def perspective(fov_y=1.0, aspect=1.0, near=0.1, far=100.0):
    f = 1.0 / np.tan(fov_y / 2)
    return np.array([[f / aspect, 0, 0, 0], [0, f, 0, 0],
                     [0, 0, (far + near) / (near - far), 2 * far * near / (near - far)],
                     [0, 0, -1, 0]])


def ortho(size=4.0, near=0.1, far=100.0):
    return np.array([[2 / size, 0, 0, 0], [0, 2 / size, 0, 0],
                     [0, 0, -2 / (far - near), -(far + near) / (far - near)], [0, 0, 0, 1]])


@pytest.mark.parametrize("proj", [perspective(), ortho()])
def test_depth_round_trip(proj):
    d = np.array([0.2, 1.0, 7.5, 60.0, np.inf], np.float32)
    win = depth.planar_to_window(d, proj)
    assert win[-1] == 1.0 and (win[:-1] < 1.0).all()
    back = depth.window_to_planar(win, proj)
    assert np.isinf(back[-1])
    assert np.allclose(back[:-1], d[:-1], rtol=1e-3)


def test_zbuffer_plane_half_screen():
    """A plane at z = -5 covering x < 0: left half at distance 5, right empty."""
    proj = perspective()
    tris = np.array([[[-50, -50, -5], [0, -50, -5], [0, 50, -5]],
                     [[-50, -50, -5], [0, 50, -5], [-50, 50, -5]]], np.float64)
    z = zbuffer.rasterize(tris, np.eye(4), proj, 40, 30)
    assert z.shape == (30, 40)
    assert np.allclose(z[:, :19], 5.0, rtol=1e-4)
    assert np.isinf(z[:, 21:]).all()


def test_zbuffer_nearest_wins_and_tilted_plane():
    proj = perspective()
    far = np.array([[[-50, -50, -9], [50, -50, -9], [0, 50, -9]]], np.float64)
    near = np.array([[[-50, -50, -3], [50, -50, -3], [0, 50, -3]]], np.float64)
    z = zbuffer.rasterize(np.concatenate([far, near]), np.eye(4), proj, 16, 16)
    assert np.allclose(z[8, 8], 3.0, rtol=1e-4)
    # A floor that passes behind the camera (near-plane clipping): the planar
    # distance grows towards the horizon and is finite below it.
    floor = np.array([[[-100, -1, 100], [100, -1, 100], [0, -1, -100]]], np.float64)
    z = zbuffer.rasterize(floor, np.eye(4), proj, 16, 16)
    col = z[:8, 8]
    assert np.isfinite(col).all() and (np.diff(col) > 0).all()  # row 0 = bottom: nearest
    assert np.isinf(z[9:, 8]).all()


def test_zbuffer_empty_and_offscreen():
    z = zbuffer.rasterize(np.zeros((0, 3, 3)), np.eye(4), perspective(), 8, 8)
    assert np.isinf(z).all()
    behind = np.array([[[-1, -1, 5], [1, -1, 5], [0, 1, 5]]], np.float64)
    assert np.isinf(zbuffer.rasterize(behind, np.eye(4), perspective(), 8, 8)).all()


def test_volume_space_cube_matches_voxel_box():
    dims = (30, 40, 20)
    aff = np.array([[0, -2, 0, 10], [1.5, 0, 0, -4], [0, 0, 3, 7], [0, 0, 0, 1]], float)
    s = volume_space.scene_from_voxel(aff, dims, 0.01, center_at=(1, 2, 3))
    obj = volume_space.object_matrix(s, dims)
    cube = np.array([[x, y, z, 1] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float)
    from_cube = (cube @ obj.T)[:, :3]
    corners = volume_space.world_corners(s, dims)
    assert np.allclose(np.sort(from_cube, axis=0), np.sort(corners, axis=0))
    assert np.allclose(corners.mean(axis=0), [1, 2, 3])
    # Without shear the remainder is exactly voxel -> cube.
    assert np.allclose(volume_space.voxel_to_local(s, obj), volume_space.voxel_to_cube(dims))


def test_light_mapping():
    m = np.eye(4)
    m[:3, 3] = (1, 2, 3)
    m[:3, :3] = [[1, 0, 0], [0, 0, 1], [0, -1, 0]]  # +Z axis maps to world +Y
    pos, col, inten = lights.map_light("SUN", m, (1, 0.5, 0.25), 3.0)
    assert np.allclose(pos, (0, 1, 0, 0)) and inten == 3.0 and col == (1, 0.5, 0.25)
    pos, col, inten = lights.map_light("POINT", m, (1, 1, 1), 1000.0)
    assert pos == (1, 2, 3, 1) and inten == pytest.approx(1.0)
    # Off stays off: never 0, which the library reads as "default".
    pos, col, inten = lights.map_light("SPOT", m, (0, 0, 0), 0.0)
    assert 0 < inten < 1e-3 and 0 < max(col) < 1e-3


def _look(eye, target=(0.0, 0.0, 0.0)):
    eye = np.asarray(eye, np.float64)
    f = np.asarray(target, np.float64) - eye
    f /= np.linalg.norm(f)
    up = np.array([0.0, 0.0, 1.0]) if abs(f[2]) < 0.99 else np.array([0.0, 1.0, 0.0])
    s = np.cross(f, up)
    s /= np.linalg.norm(s)
    u = np.cross(s, f)
    m = np.eye(4)
    m[0, :3], m[1, :3], m[2, :3] = s, u, -f
    m[:3, 3] = -m[:3, :3] @ eye
    return m


def _unit_box_model(n=10):
    """Voxel box of n^3 voxels mapped onto the world cube [-1, 1]^3."""
    m = np.eye(4)
    m[:3, :3] *= 2.0 / n
    m[:3, 3] = -1.0 + 1.0 / n
    return m


def test_screen_rect_holds_the_projected_box():
    model, dims = _unit_box_model(), (10, 10, 10)
    view, proj = _look((0.0, -6.0, 0.0)), perspective(fov_y=0.8)
    w, h = 200, 100
    rect = volume_space.screen_rect(model, dims, view, proj, w, h)
    x0, y0, x1, y1 = rect
    assert 0 < x0 < x1 < w and 0 < y0 < y1 < h
    # Every pixel whose ray meets the box lies inside the rectangle.
    corners = volume_space.world_corners(model, dims)
    clip = np.c_[corners, np.ones(8)] @ (proj @ view).T
    sx = (clip[:, 0] / clip[:, 3] * 0.5 + 0.5) * w
    sy = (clip[:, 1] / clip[:, 3] * 0.5 + 0.5) * h
    assert x0 <= sx.min() and sx.max() <= x1 and y0 <= sy.min() and sy.max() <= y1
    # Looking away: culled. Camera inside: the whole image.
    assert volume_space.screen_rect(model, dims, _look((0.0, -6.0, 0.0), (0.0, -12.0, 0.0)),
                                    proj, w, h) is None
    assert volume_space.outside_frustum(model, dims, _look((40.0, -6.0, 0.0), (40.0, 0.0, 0.0)),
                                        proj)
    assert volume_space.screen_rect(model, dims, _look((0.0, -0.5, 0.0), (0.0, 1.0, 0.0)),
                                    proj, w, h) == (0, 0, w, h)
    near, far = volume_space.planar_range(model, dims, view)
    assert near == pytest.approx(5.0) and far == pytest.approx(7.0)
    assert volume_space.voxel_size(model) == pytest.approx(0.2)


def test_depth_for_library_keeps_only_what_changes_the_image():
    planar = np.array([[0.5, 5.0, 5.03, 5.07],
                       [6.99, 7.0, 30.0, np.inf]], np.float32)
    out = depth.for_library(planar, near=4.9, far=7.0, quantum=0.05)
    assert out[0, 0] == 0.0                                # before the box: stops every ray
    assert out[0, 1] == pytest.approx(5.0, abs=0.051)      # rounded down: stops no later
    assert out[0, 1] <= 5.0
    assert out[0, 2] == pytest.approx(5.0) and out[0, 3] == pytest.approx(5.05)
    assert out[1, 0] == pytest.approx(6.95)
    assert np.isinf(out[1, 1:]).all()                      # behind the box: as if empty
    # Wobble below the quantum gives the same depth, so the same frame key.
    wobble = depth.for_library(planar + np.float32(0.004), 4.9, 7.0, 0.05)
    assert np.array_equal(out, wobble)
    # Outside the footprint rectangle nothing can be hit.
    masked = depth.for_library(planar, 4.9, 7.0, 0.05, rect=(2, 0, 4, 1))
    assert np.isinf(masked[:, :2]).all() and np.isinf(masked[1]).all()
    assert masked[0, 2] == pytest.approx(5.0)


def test_downsample_picks_pixel_centres():
    img = np.arange(12, dtype=np.float32).reshape(3, 4)
    assert np.array_equal(depth.downsample(img, 2, 1), [[5.0, 7.0]])
    assert depth.downsample(img, 4, 3) is img
