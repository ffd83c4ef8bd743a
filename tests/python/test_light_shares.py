"""plugin/core/light_shares.py: each light's share of a point's light and the
shadow amount F = sum_l w_l (1 - T_l) that EEVEE's F12 and the viewport
multiply the image by (1 - F); plugin/core/facing.py's normals."""

import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "plugin"))
from core import facing, light_shares as ls  # noqa: E402
from core.lights import SceneLight, Shape  # noqa: E402

UP = np.array([0.0, 0.0, 1.0])


def _floor(n=5, size=4.0):
    """An n x n grid of points on the floor z = 0, normals up."""
    xs = np.linspace(-size / 2, size / 2, n)
    x, y = np.meshgrid(xs, xs)
    p = np.stack([x, y, np.zeros_like(x)], -1)
    return p, np.broadcast_to(UP, p.shape).copy()


def sun(strength=3.0, direction=(0.0, 0.0, 1.0), color=(1.0, 1.0, 1.0)):
    d = np.asarray(direction, np.float64)
    return SceneLight((*(d / np.linalg.norm(d)), 0.0), color, strength)


def point(power=1000.0, at=(0.0, 0.0, 2.0), shape=Shape()):
    return SceneLight((*at, 1.0), (1.0, 1.0, 1.0), power / 1000.0, shape)


def test_a_sun_and_a_point_light_give_cycles_irradiance_per_unit_albedo():
    p, n = _floor()
    s = ls.diffuse_light(sun(3.0, (0.0, 1.0, 1.0)), p, n)
    np.testing.assert_allclose(s, 3.0 * math.cos(math.pi / 4) / math.pi)
    pt = ls.diffuse_light(point(1000.0, (0.0, 0.0, 2.0)), p, n)
    d2 = (p ** 2).sum(-1) + 4.0
    cos = 2.0 / np.sqrt(d2)
    np.testing.assert_allclose(pt, 1000.0 * cos / (4 * math.pi * d2) / math.pi)


def test_a_light_behind_the_surface_gives_nothing_and_a_spot_only_inside_its_cone():
    p, n = _floor()
    assert not ls.diffuse_light(sun(1.0, (0.0, 0.0, -1.0)), p, n).any()
    assert not ls.diffuse_light(point(at=(0.0, 0.0, -1.0)), p, n).any()
    narrow = Shape(spot_direction=(0.0, 0.0, -1.0), spot_angle=math.radians(30), spot_blend=0.0)
    spot = ls.diffuse_light(point(at=(0.0, 0.0, 2.0), shape=narrow), p, n)
    inside = np.arctan(np.hypot(p[..., 0], p[..., 1]) / 2.0) < math.radians(15)
    assert spot[inside].min() > 0.0 and not spot[~inside].any()


def test_shares_and_the_worlds_light_sum_to_one():
    p, n = _floor()
    lights = [sun(3.0, (0.3, 0.2, 1.0)), point(1000.0, (1.0, 1.0, 3.0))]
    ambient = 0.05
    w = ls.shares(lights, p, n, ambient)
    direct = [ls.diffuse_light(l, p, n) for l in lights]
    np.testing.assert_allclose(sum(w) + ambient / (sum(direct) + ambient), 1.0)
    np.testing.assert_allclose(w[0] / w[1], direct[0] / direct[1])


def test_each_lights_shadow_darkens_only_its_own_share():
    """Two lights of equal light on the floor, the first blocked entirely:
    half of the direct light goes, the world's stays (not the one key
    light's shadow for all, and not a black umbra)."""
    p, n = _floor()
    lights = [sun(math.pi, (0.0, 0.0, 1.0)), sun(math.pi, (0.0, 0.0, 1.0))]
    w = ls.shares(lights, p, n, ambient=0.5)   # each light gives 1, the world 0.5
    f = ls.shadow_amount(w, {0: np.zeros(p.shape[:2]), 1: np.ones(p.shape[:2])})
    np.testing.assert_allclose(f, 1.0 / 2.5, rtol=1e-6)
    f = ls.shadow_amount(w, {1: np.full(p.shape[:2], 0.5)})
    np.testing.assert_allclose(f, 0.5 / 2.5, rtol=1e-6)
    assert ls.shadow_amount(w, {}) is None


def test_nothing_lit_and_no_surface_get_no_shadow():
    p, n = _floor(3)
    p[0, 0] = np.nan
    n[0, 0] = np.nan
    w = ls.shares([sun()], p, n, 0.0)
    f = ls.shadow_amount(w, {0: np.zeros((3, 3))})
    assert f[0, 0] == 0.0 and (f[1:, 1:] == 1.0).all()
    w = ls.shares([sun(1.0, (0.0, 0.0, -1.0))], p, n, 0.0)
    assert not ls.shadow_amount(w, {0: np.zeros((3, 3))}).any()


def test_the_shadow_amount_is_smooth_where_the_light_is():
    """Over a floor lit by a point light, F's second differences stay at
    the level of its smooth curvature: nothing of a quantised input."""
    xs = np.linspace(-3.0, 3.0, 200)
    x, y = np.meshgrid(xs, xs)
    p = np.stack([x, y, np.zeros_like(x)], -1)
    n = np.broadcast_to(UP, p.shape)
    w = ls.shares([sun(3.0, (0.4, 0.3, 1.0)), point(1000.0, (4.0, 1.0, 5.9))], p, n, 0.05)
    f = ls.shadow_amount(w, {0: np.zeros(x.shape), 1: np.zeros(x.shape)}).astype(np.float64)
    assert np.abs(np.diff(f, 2, axis=1)).max() < 1e-4


def _camera():
    eye = np.array([0.0, -4.0, 3.0])
    fwd = -eye / np.linalg.norm(eye)
    right = np.cross(fwd, UP)
    right /= np.linalg.norm(right)
    up = np.cross(right, fwd)
    view = np.eye(4)
    view[0, :3], view[1, :3], view[2, :3] = right, up, -fwd
    view[:3, 3] = -view[:3, :3] @ eye
    near, far, f = 0.1, 100.0, 1.0 / math.tan(math.radians(25))
    proj = np.zeros((4, 4))
    proj[0, 0] = proj[1, 1] = f
    proj[2, 2], proj[2, 3], proj[3, 2] = (far + near) / (near - far), 2 * far * near / (near - far), -1.0
    return view, proj


def _floor_depth(view, proj, w=32, h=24):
    """Planar depth of the floor z = 0 seen by the camera (inf where none)."""
    ys, xs = np.mgrid[0:h, 0:w]
    ndc = np.stack([(xs + 0.5) / w * 2 - 1, (ys + 0.5) / h * 2 - 1], -1)
    dirs = np.stack([ndc[..., 0] / proj[0, 0], ndc[..., 1] / proj[1, 1], -np.ones((h, w))], -1)
    cam = np.linalg.inv(view)
    world = dirs @ cam[:3, :3].T
    eye = cam[:3, 3]
    t = -eye[2] / world[..., 2]
    return np.where(t > 0, t, np.inf)   # planar depth: the view-space z of dirs is -1


def test_normals_from_triangles_and_from_depth_agree_on_a_floor():
    view, proj = _camera()
    depth = _floor_depth(view, proj)
    tris = np.array([[[-50, -50, 0], [50, -50, 0], [50, 50, 0]],
                     [[-50, -50, 0], [50, 50, 0], [-50, 50, 0]]], np.float64)
    ids = np.where(np.isfinite(depth), 0, -1)
    n_tri = facing.surface_normals(tris, ids, depth, view, proj)
    pos = facing.pixel_positions(depth, view, proj)
    n_depth = facing.depth_normals(pos, view)
    hit = np.isfinite(depth)
    np.testing.assert_allclose(n_tri[hit], np.broadcast_to(UP, n_tri[hit].shape), atol=1e-9)
    np.testing.assert_allclose(n_depth[hit], np.broadcast_to(UP, n_depth[hit].shape), atol=1e-6)
    assert np.isnan(n_tri[~hit]).all()
