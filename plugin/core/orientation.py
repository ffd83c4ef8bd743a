"""Turning a scan so that Blender's named views match its anatomy. Pure
numpy (no bpy), unit-tested in tests/python/test_orientation.py.

The library gives every anatomical format in NIfTI's RAS+ world: +x
towards the patient's Right, +y Anterior, +z Superior (nifti1.h, "METHOD
2"); NRRD, MetaImage and DICOM are converted there from LPS by their
loaders. A scan placed as is therefore faces +Y.

Blender's named views (read from bpy.ops.view3d.view_axis in
tests/blender/test_gui_orientation.py):
  Front (numpad 1)        looks along +Y: it sees the -Y side, +X to the right;
  Right (numpad 3)        looks along -X: it sees the +X side;
  Left (Ctrl numpad 3)    looks along +X: it sees the -X side;
  Top (numpad 7)          looks along -Z: it sees the +Z side.
So a scan in RAS shows the back of the head in Front.

The one proper rotation that puts the face in Front (anterior -> -Y) and
keeps the top of the head in Top (superior -> +Z) is 180 degrees about Z;
it takes the patient's right to -X. Front then shows the face as one sees
a person facing them (their right on the screen's left), Left shows the
patient's right side and Right their left side: exactly how Blender shows
a character modelled facing -Y (its ".L" side is +X). Putting the face in
Front and the patient's right in Right at once would need a mirror
(y -> -y), which swaps the patient's sides: never done here.

Formats without anatomy (TIFF/PNG stacks, NIfTI/NRRD/MetaImage without an
orientation, OpenVDB grids, generated phantoms) are not turned: their axes
are the data's own, and turning them would only hide that.
"""

import numpy as np

# Object.voxlight.orientation: how the import placed the file's world frame.
FILE = "FILE"                    # as in the file (scanner RAS, or the data's own axes)
BLENDER_VIEWS = "BLENDER_VIEWS"  # turned: Blender's named views match the anatomy

# Scene <- RAS for BLENDER_VIEWS: 180 degrees about +Z (det +1, no mirror).
BLENDER_FROM_RAS = np.diag([-1.0, -1.0, 1.0, 1.0])


def has_anatomy(info, is_vdb=False):
    """Whether the loaded volume's world frame is anatomical (RAS): the
    file gave an orientation (NIfTI qform/sform, NRRD space directions,
    MetaImage TransformMatrix/Offset, DICOM patient geometry). Stacks and
    files with spacing only report affine_source "none"; OpenVDB grids are
    in scene units with no anatomy although they carry a transform."""
    return not is_vdb and info.get("affine_source") in ("qform", "sform")


def choose(anatomical_views, info, is_vdb=False):
    """The orientation an import gets: BLENDER_VIEWS when asked for and the
    volume has anatomy, else FILE."""
    return BLENDER_VIEWS if anatomical_views and has_anatomy(info, is_vdb) else FILE


def scene_from_file(orientation):
    """4x4 rotation from the file's world frame to the scene's (before the
    unit scale and centring, which it commutes with: it fixes the origin
    and is a pure rotation)."""
    if orientation == BLENDER_VIEWS:
        return BLENDER_FROM_RAS.copy()
    if orientation == FILE:
        return np.eye(4)
    raise ValueError("unknown orientation %r" % (orientation,))


def oriented_affine(affine, orientation):
    """voxel -> scene-oriented mm: the loader's affine turned as chosen."""
    return scene_from_file(orientation) @ np.asarray(affine, np.float64).reshape(4, 4)
