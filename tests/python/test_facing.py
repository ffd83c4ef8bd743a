"""core/facing.py and the z-buffer's triangle ids: the volume's scene shadow
belongs only on surfaces that turn the side the camera sees towards the
light. A closed box seen from a corner, lit from behind one of its visible
faces: that face (and only it) gets no shadow."""

import numpy as np

from voxlight.core import depth, facing, zbuffer

W = H = 40


def _look_at(eye, target=(0.0, 0.0, 0.0)):
    eye = np.asarray(eye, np.float64)
    f = np.asarray(target, np.float64) - eye
    f /= np.linalg.norm(f)
    r = np.cross(f, [0.0, 0.0, 1.0])
    r /= np.linalg.norm(r)
    u = np.cross(r, f)
    view = np.eye(4)
    view[0, :3], view[1, :3], view[2, :3] = r, u, -f
    view[:3, 3] = -view[:3, :3] @ eye
    return view


def _perspective(fov=0.9, near=0.1, far=100.0):
    t = 1.0 / np.tan(fov / 2)
    p = np.zeros((4, 4))
    p[0, 0] = p[1, 1] = t
    p[2, 2] = (far + near) / (near - far)
    p[2, 3] = 2 * far * near / (near - far)
    p[3, 2] = -1.0
    return p


def _box():
    """The 12 triangles of the cube [-1, 1]^3, two per face, face order
    -x, +x, -y, +y, -z, +z (winding does not matter to facing)."""
    tris = []
    for axis in range(3):
        for side in (-1.0, 1.0):
            a, b = [i for i in range(3) if i != axis]
            quad = []
            for u, v in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
                p = [0.0, 0.0, 0.0]
                p[axis], p[a], p[b] = side, u, v
                quad.append(p)
            tris += [[quad[0], quad[1], quad[2]], [quad[0], quad[2], quad[3]]]
    return np.array(tris)


def test_ids_name_the_nearest_triangle_and_positions_lie_on_it():
    view, proj = _look_at((5.0, -6.0, 4.0)), _perspective()
    ids = np.full((H, W), -1, np.int64)
    z = zbuffer.rasterize(_box(), view, proj, W, H, ids=ids)
    assert (np.isfinite(z) == (ids >= 0)).all()
    seen = set(np.unique(ids[ids >= 0]) // 2)
    assert seen == {1, 2, 5}, seen  # +x, -y, +z face the camera
    p = facing.pixel_positions(z, view, proj)[ids >= 0]
    assert np.abs(np.abs(p).max(axis=1) - 1.0).max() < 1e-3  # on the box's surface
    assert depth.window_to_planar(np.ones(1), proj)[0] == np.inf


def test_a_face_turned_away_from_the_light_gets_no_shadow():
    view, proj = _look_at((5.0, -6.0, 4.0)), _perspective()
    ids = np.full((H, W), -1, np.int64)
    z = zbuffer.rasterize(_box(), view, proj, W, H, ids=ids)
    face = np.where(ids >= 0, ids // 2, -1)
    for light in ((0.3, 1.0, 0.5, 0.0), (4.0, 8.0, 3.0, 1.0)):  # a sun, a point, both beyond +y
        lit = facing.faces_light(_box(), ids, z, view, proj, light)
        assert not lit[face == 2].any(), light     # -y faces away from them
        assert lit[(face == 1) | (face == 5)].all(), light
        assert lit[face < 0].all()                 # no surface: nothing to decide
