"""core/startup_cube.py: which Cube the importer hides."""

import numpy as np

from voxlight.core import startup_cube as sc

CORNERS = [(x, y, z) for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]


def test_the_factory_cube_is_recognised():
    assert sc.is_factory_cube("Cube", "MESH", 8, np.eye(4), CORNERS)


def test_an_edited_or_renamed_cube_is_the_users():
    moved = np.eye(4)
    moved[0, 3] = 3.0
    scaled = np.diag([2.0, 2.0, 2.0, 1.0])
    assert not sc.is_factory_cube("Cube", "MESH", 8, moved, CORNERS)
    assert not sc.is_factory_cube("Cube", "MESH", 8, scaled, CORNERS)
    assert not sc.is_factory_cube("Cube", "MESH", 24, np.eye(4), CORNERS)  # subdivided
    assert not sc.is_factory_cube("Box", "MESH", 8, np.eye(4), CORNERS)
    assert not sc.is_factory_cube("Cube", "CURVE", 8, np.eye(4), CORNERS)
    small = [tuple(0.5 * np.array(c)) for c in CORNERS]
    assert not sc.is_factory_cube("Cube", "MESH", 8, np.eye(4), small)


def test_overlap():
    cube = sc.world_box(np.eye(4), CORNERS)
    assert sc.overlaps(cube, (np.array([-0.9, -0.9, -0.9]), np.array([0.9, 0.9, 0.9])))  # inside
    assert sc.overlaps(cube, (np.array([-3.0] * 3), np.array([3.0] * 3)))  # encloses it
    assert not sc.overlaps(cube, (np.array([5.0, 0, 0]), np.array([7.0, 1, 1])))  # beside it
