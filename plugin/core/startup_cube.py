"""The factory startup Cube and a new import (no bpy, tested in plain
Python).

Blender's factory scene has a 2 m grey Cube at the origin, and an import
lands at the 3D cursor (the origin) at about that size, so the first thing
a new user would see is the Cube. The importer hides it, from the viewport
and from renders, when it is still the factory Cube (the name, 8 vertices,
a 2-unit box, at the origin, unrotated, unscaled) and its box overlaps the
volume's. Why hide rather than the alternatives:
  * deleting would destroy an object the user may want back; hidden, it
    is one click away in the Outliner (and the import's undo restores it);
  * moving the volume away would break "centre at the 3D cursor" and
    scanner coordinates, and the Cube would still stand in the view;
  * drawing the volume through the Cube would make every mesh
    transparent to it, which is wrong for the user's own meshes.
A Cube the user has edited, moved or renamed is theirs and is left alone.
"""

import numpy as np

NAME = "Cube"
HALF = 1.0          # the factory cube spans -1..1
_TOL = 1e-4


def is_factory_cube(name, kind, vertex_count, matrix_world, bound_box):
    """Whether an object is the factory startup Cube, untouched.
    matrix_world: 4x4; bound_box: its 8 local corners."""
    if name != NAME or kind != "MESH" or vertex_count != 8:
        return False
    m = np.asarray(matrix_world, np.float64).reshape(4, 4)
    if not np.allclose(m, np.eye(4), atol=_TOL):
        return False
    b = np.asarray(bound_box, np.float64).reshape(8, 3)
    return bool(np.allclose(b.min(0), -HALF, atol=_TOL) and np.allclose(b.max(0), HALF, atol=_TOL))


def world_box(matrix_world, bound_box):
    """(min, max) world corners of an object's local bounding box."""
    m = np.asarray(matrix_world, np.float64).reshape(4, 4)
    b = np.asarray(bound_box, np.float64).reshape(-1, 3)
    w = b @ m[:3, :3].T + m[:3, 3]
    return w.min(0), w.max(0)


def overlaps(box_a, box_b):
    """Whether two (min, max) boxes share any volume or touch."""
    (a0, a1), (b0, b1) = box_a, box_b
    a0, a1, b0, b1 = (np.asarray(v, np.float64) for v in (a0, a1, b0, b1))
    return bool(np.all(a0 <= b1) and np.all(b0 <= a1))
