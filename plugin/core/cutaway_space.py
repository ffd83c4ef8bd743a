"""The cutaways in world space, from Blender objects' matrices
(plain numpy, no bpy): a clip plane from an object's local XY plane, the
crop box from a cube Empty. Matrices are 4x4 math matrices (m[row][col],
as mathutils and numpy index them)."""

import numpy as np


def clip_plane(matrix_world):
    """(a, b, c, d) with unit (a, b, c): a x + b y + c z + d is the signed
    world distance from the object's local XY plane, positive on its local
    +Z side (the side that is kept). The local plane is z = 0 and the
    local z of a world point is row 2 of the inverse matrix; scaled to unit
    length that is the distance. ValueError when the matrix is singular."""
    m = np.asarray(matrix_world, np.float64).reshape(4, 4)
    try:
        inv = np.linalg.inv(m)
    except np.linalg.LinAlgError:
        raise ValueError("the plane's object has a singular transform (a scale of 0)") from None
    row = inv[2]
    n = float(np.linalg.norm(row[:3]))
    if not np.isfinite(row).all() or n == 0.0:
        raise ValueError("the plane's object has a singular transform (a scale of 0)")
    return tuple(float(v) for v in row / n)


def crop_box(matrix_world, display_size):
    """box -> world of a cube Empty: its cube is [-size, size]^3 in local
    space, so the box [-1, 1]^3 of the library is matrix_world @ scale(size).
    ValueError when that is singular."""
    m = np.asarray(matrix_world, np.float64).reshape(4, 4) @ np.diag(
        [display_size, display_size, display_size, 1.0])
    if not np.isfinite(m).all() or abs(np.linalg.det(m[:3, :3])) < 1e-30:
        raise ValueError("the crop box has no volume (a scale or size of 0)")
    return m


def signed_distance(plane, points):
    """a x + b y + c z + d for each of `points` (n, 3)."""
    p = np.asarray(points, np.float64).reshape(-1, 3)
    return p @ np.asarray(plane[:3], np.float64) + plane[3]


class CutawaySpec(dict):
    """The cutaway as make_params takes it (clip_planes, crop_box, cutters,
    caps), whose repr is a digest of its contents, so the add-on's change
    tests (params.look_key) see a moved plane or an edited cutter mesh
    without printing whole arrays."""

    def __repr__(self):
        import hashlib
        h = hashlib.blake2b(digest_size=16)
        for plane, thickness in self.get("clip_planes", ()):
            h.update(np.asarray(tuple(plane) + (thickness,), np.float64).tobytes())
        box = self.get("crop_box")
        h.update(b"none" if box is None else np.asarray(box, np.float64).tobytes())
        for verts, tris, remove_outside in self.get("cutters", ()):
            h.update(np.ascontiguousarray(verts, np.float64).tobytes())
            h.update(np.ascontiguousarray(tris, np.int64).tobytes())
            h.update(b"o" if remove_outside else b"i")
        h.update(b"caps" if self.get("caps", True) else b"nocaps")
        return "CutawaySpec(%s)" % h.hexdigest()
