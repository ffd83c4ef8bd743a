"""The import option that turns a scan so Blender's named views match its
anatomy (plugin/core/orientation.py), checked against the views' real
directions and through the same placement maths the importer uses."""

import numpy as np
import pytest

from voxlight.core import orientation, volume_space

# Blender's named views as bpy.ops.view3d.view_axis sets them (measured in
# Blender 3.4 with view_rotation; tests/blender/test_gui_orientation.py
# checks them again): direction the view looks along, screen right.
VIEWS = {
    "FRONT": ((0, 1, 0), (1, 0, 0)),
    "BACK": ((0, -1, 0), (-1, 0, 0)),
    "RIGHT": ((-1, 0, 0), (0, 1, 0)),
    "LEFT": ((1, 0, 0), (0, -1, 0)),
    "TOP": ((0, 0, -1), (1, 0, 0)),
}
# RAS+ (nifti1.h): +x toward the patient's Right, +y Anterior, +z Superior.
RIGHT, ANTERIOR, SUPERIOR = np.eye(3)


def seen_side(view):
    """The outward direction of the side a named view sees."""
    return -np.array(VIEWS[view][0], np.float64)


def turned(orient, v):
    return orientation.scene_from_file(orient)[:3, :3] @ v


def test_blender_views_show_the_anatomy():
    o = orientation.BLENDER_VIEWS
    assert np.allclose(turned(o, ANTERIOR), seen_side("FRONT"))    # face in Front
    assert np.allclose(turned(o, -ANTERIOR), seen_side("BACK"))
    assert np.allclose(turned(o, SUPERIOR), seen_side("TOP"))      # top of the head in Top
    # As for a Blender character facing -Y: Left sees the patient's right.
    assert np.allclose(turned(o, RIGHT), seen_side("LEFT"))
    assert np.allclose(turned(o, -RIGHT), seen_side("RIGHT"))
    # Front shows the face as one sees a person: their right on screen left.
    assert np.dot(turned(o, RIGHT), VIEWS["FRONT"][1]) < 0


def test_turn_is_a_rotation_not_a_mirror():
    m = orientation.scene_from_file(orientation.BLENDER_VIEWS)
    r = m[:3, :3]
    assert np.allclose(r @ r.T, np.eye(3)) and np.isclose(np.linalg.det(r), 1.0)
    assert np.allclose(m[:3, 3], 0) and np.allclose(m[3], [0, 0, 0, 1])


def test_file_axes_keep_scanner_coordinates():
    """Option off: today's placement, the face toward +Y (Back sees it)."""
    assert np.allclose(orientation.scene_from_file(orientation.FILE), np.eye(4))
    aff = np.array([[0, 0, 1.5, -10], [-2, 0, 0, 20], [0, 1, 0, 30], [0, 0, 0, 1]], np.float64)
    assert np.allclose(orientation.oriented_affine(aff, orientation.FILE), aff)
    assert np.allclose(turned(orientation.FILE, ANTERIOR), seen_side("BACK"))
    with pytest.raises(ValueError):
        orientation.scene_from_file("SIDEWAYS")


@pytest.mark.parametrize("source,vdb,expected", [
    ("sform", False, True), ("qform", False, True),
    ("none", False, False),   # TIFF/PNG stacks, spacing-only headers, phantoms
    ("sform", True, False),   # OpenVDB: a transform but no anatomy
])
def test_only_anatomical_volumes_are_turned(source, vdb, expected):
    info = {"affine_source": source}
    assert orientation.has_anatomy(info, vdb) is expected
    want = orientation.BLENDER_VIEWS if expected else orientation.FILE
    assert orientation.choose(True, info, vdb) == want
    assert orientation.choose(False, info, vdb) == orientation.FILE


@pytest.mark.parametrize("centre_at", [None, (0.3, -0.2, 0.5)])
def test_marker_placement_through_the_importer_maths(centre_at):
    """An oblique, LPS-like stored scan (as DICOM/NRRD loaders hand over
    after converting to RAS): a voxel on the anterior side ends up on the
    side Front sees, the box centre still at the cursor."""
    dims = (20, 24, 16)
    # voxel i -> -x (stored right-to-left), j -> +y rotated 30 deg about z, k -> z
    c, s = np.cos(np.radians(30)), np.sin(np.radians(30))
    rot = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]]) @ np.diag([-1.0, 1.0, 1.0])
    aff = np.eye(4)
    aff[:3, :3] = rot @ np.diag([0.9, 1.1, 2.0])
    aff[:3, 3] = [40.0, -12.0, 7.0]
    centre_vox = (np.array(dims) - 1) / 2.0
    # the voxel whose RAS position lies farthest toward Anterior
    ras = lambda v: (aff @ np.append(v, 1.0))[:3]  # noqa: E731
    grid = np.stack(np.meshgrid(*[[0, d - 1] for d in dims], indexing="ij"), -1).reshape(-1, 3)
    front_vox = max(grid, key=lambda v: ras(v)[1])
    for orient, side in ((orientation.BLENDER_VIEWS, "FRONT"), (orientation.FILE, "BACK")):
        m = volume_space.scene_from_voxel(orientation.oriented_affine(aff, orient), dims, 0.01,
                                          center_at=centre_at)
        p = (m @ np.append(front_vox, 1.0))[:3]
        centre = (m @ np.append(centre_vox, 1.0))[:3]
        if centre_at is not None:
            assert np.allclose(centre, centre_at)
        # the anterior corner is the one nearest the view that sees `side`
        look = np.array(VIEWS[side][0], np.float64)
        depth = [(m @ np.append(v, 1.0))[:3] @ look for v in grid]
        assert np.isclose(p @ look, min(depth)), (orient, p)
        assert (p - centre) @ look < 0
