"""Framing a volume in the viewport after import (plugin/core/framing.py):
the bounding sphere and the view distance that fits it, checked by
projecting with a projection built like Blender's viewport camera."""

import math

import numpy as np
import pytest

from voxlight.core import framing, volume_space


def viewport_proj(lens, w, h, perspective, distance, near=0.01, far=1000.0):
    """Blender's viewport camera: 36 mm sensor, zoom 2, fitted to the larger side."""
    half_big = framing.VIEWPORT_HALF_SENSOR_MM / lens
    sx, sy = (half_big, half_big * h / w) if w >= h else (half_big * w / h, half_big)
    if perspective:
        return np.array([[1 / sx, 0, 0, 0], [0, 1 / sy, 0, 0],
                         [0, 0, (far + near) / (near - far), 2 * far * near / (near - far)],
                         [0, 0, -1, 0]])
    ex, ey = sx * distance, sy * distance  # orthographic half extents at the view distance
    return np.array([[1 / ex, 0, 0, 0], [0, 1 / ey, 0, 0],
                     [0, 0, -2 / (far - near), -(far + near) / (far - near)], [0, 0, 0, 1]])


def view_matrix(rot, location, distance):
    """Blender's view: rotation about view_location, eye distance behind it."""
    world_from_view = np.eye(4)
    world_from_view[:3, :3] = rot
    world_from_view[:3, 3] = np.asarray(location) + rot @ np.array([0, 0, distance])
    return np.linalg.inv(world_from_view)


def random_rotation(rng):
    q = rng.normal(size=4)
    a, b, c, d = q / np.linalg.norm(q)
    return np.array([[a*a+b*b-c*c-d*d, 2*(b*c-a*d), 2*(b*d+a*c)],
                     [2*(b*c+a*d), a*a-b*b+c*c-d*d, 2*(c*d-a*b)],
                     [2*(b*d-a*c), 2*(c*d+a*b), a*a-b*b-c*c+d*d]])


def ndc(points, view, proj):
    clip = np.c_[points, np.ones(len(points))] @ (proj @ view).T
    assert (clip[:, 3] > 0).all()  # all in front of the eye
    return clip[:, :3] / clip[:, 3:4]


def test_bounding_sphere_of_a_box():
    model = np.diag([0.02, 0.03, 0.01, 1.0])
    model[:3, 3] = [1.0, -2.0, 0.5]
    corners = volume_space.world_corners(model, (10, 20, 30))
    centre, radius = framing.bounding_sphere(corners)
    assert np.allclose(centre, model[:3, :3] @ (np.array([10, 20, 30]) / 2 - 0.5) + model[:3, 3])
    assert math.isclose(radius, 0.5 * math.sqrt(0.2**2 + 0.6**2 + 0.3**2))


@pytest.mark.parametrize("perspective", [True, False])
@pytest.mark.parametrize("w,h,lens", [(1321, 852, 50.0), (400, 900, 50.0), (640, 640, 24.0)])
def test_sphere_fits_the_narrower_side_exactly(perspective, w, h, lens):
    """margin 1: the sphere touches the narrower side and stays inside."""
    rng = np.random.default_rng(3)
    centre, radius = np.array([0.4, -1.0, 2.0]), 0.9
    dist = framing.view_distance(radius, lens, w, h, perspective, margin=1.0)
    dirs = rng.normal(size=(20000, 3))
    sphere = centre + radius * dirs / np.linalg.norm(dirs, axis=1)[:, None]
    for _ in range(3):
        rot = random_rotation(rng)
        p = ndc(sphere, view_matrix(rot, centre, dist), viewport_proj(lens, w, h, perspective, dist))
        narrow = 1 if w >= h else 0
        assert np.abs(p[:, :2]).max() <= 1.0 + 1e-9
        assert np.abs(p[:, narrow]).max() > 0.99  # tight: touches the edge


def test_frame_puts_every_corner_in_view_with_margin():
    model = np.diag([0.01, 0.01, 0.012, 1.0])
    model[:3, :3] = random_rotation(np.random.default_rng(5)) @ model[:3, :3]
    model[:3, 3] = [3.0, 1.0, -2.0]
    corners = volume_space.world_corners(model, (181, 217, 181))
    loc, dist = framing.frame(corners, 50.0, 1321, 852)
    for rot in (np.eye(3), random_rotation(np.random.default_rng(9))):
        p = ndc(corners, view_matrix(rot, loc, dist), viewport_proj(50.0, 1321, 852, True, dist))
        assert np.abs(p[:, :2]).max() < 1.0 / 1.05      # inside, with room to spare
        assert np.abs(p[:, :2]).max() > 0.4             # and not a speck


def test_bad_input_is_an_error():
    with pytest.raises(ValueError):
        framing.view_distance(0.0, 50.0, 100, 100)
    with pytest.raises(ValueError):
        framing.view_distance(1.0, 50.0, 0, 100)
