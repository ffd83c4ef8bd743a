"""plugin/core/box_edges.py: the box outline's edges that nothing inside the
box can cover, drawn again over the volume."""

import numpy as np
import pytest

from voxlight.core import box_edges


def _look_from(eye, target=(0.0, 0.0, 0.0), up=(0.0, 0.0, 1.0)):
    """world -> view: the camera at `eye` looking at `target`, -z forward."""
    eye, target, up = (np.asarray(a, np.float64) for a in (eye, target, up))
    f = target - eye
    f /= np.linalg.norm(f)
    if abs(np.dot(f, up)) > 0.99:
        up = np.array([0.0, 1.0, 0.0])
    s = np.cross(f, up)
    s /= np.linalg.norm(s)
    u = np.cross(s, f)
    m = np.eye(4)
    m[0, :3], m[1, :3], m[2, :3] = s, u, -f
    m[:3, 3] = -m[:3, :3] @ eye
    return m


@pytest.mark.parametrize("perspective", [True, False])
def test_face_on_view_draws_the_near_face_only(perspective):
    corners = box_edges.cube_corners(np.eye(4))
    edges = box_edges.front_edges(corners, _look_from((0.0, 0.0, 10.0)), perspective)
    assert len(edges) == 4
    # all four lie on the +z face (bit 2 set at both ends)
    assert all(i & 4 and j & 4 for i, j in edges)


@pytest.mark.parametrize("perspective", [True, False])
def test_corner_view_hides_the_three_edges_of_the_far_corner(perspective):
    corners = box_edges.cube_corners(np.eye(4))
    edges = box_edges.front_edges(corners, _look_from((10.0, 12.0, 9.0)), perspective)
    assert len(edges) == 9
    hidden = set(box_edges.EDGES) - set(edges)
    assert all(0 in e for e in hidden)  # corner 0 is (-1, -1, -1), away from the eye


def test_close_perspective_sees_side_faces_the_orthographic_view_does_not():
    """An eye above the box but beyond its +x side sees that side face in
    perspective; the parallel view along -z sees the top face only."""
    corners = box_edges.box_corners(np.eye(4), (-1, -1, -1), (1, 1, 1))
    view = _look_from((3.0, 0.0, 4.0), target=(3.0, 0.0, 0.0), up=(0.0, 1.0, 0.0))
    persp = box_edges.front_edges(corners, view, True)
    ortho = box_edges.front_edges(corners, view, False)
    assert len(ortho) == 4
    assert len(persp) == 7  # +z and +x faces: 4 + 4 - 1 shared


def test_sheared_scaled_box_and_segments():
    m = np.array([[2.0, 0.5, 0.0, 1.0], [0.0, 1.0, 0.3, -2.0], [0.0, 0.0, 3.0, 0.5], [0, 0, 0, 1]])
    corners = box_edges.cube_corners(m)
    assert np.allclose(corners[7], (m @ [1, 1, 1, 1])[:3])
    assert np.allclose(corners[0], (m @ [-1, -1, -1, 1])[:3])
    edges = box_edges.front_edges(corners, _look_from((20.0, -15.0, 12.0)), True)
    assert 4 <= len(edges) <= 9
    seg = box_edges.segments(corners, edges)
    assert len(seg) == 2 * len(edges) and all(len(p) == 3 for p in seg)
