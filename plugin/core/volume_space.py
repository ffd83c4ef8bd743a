"""Where a volume sits in the scene. Pure numpy (no bpy).

A Voxlight volume is an Empty drawn as a cube: Blender draws that cube as
[-1, 1]^3 in the object's local space. So the import sets the object's
matrix to (scene <- voxel) @ (voxel <- cube), and the add-on keeps the
remainder `voxel_to_local` (voxel -> object local) on the object. At render
time model = object.matrix_world @ voxel_to_local, so moving, rotating and
scaling the Empty moves the render with it. When the NIfTI affine has shear
(which an object's loc/rot/scale cannot hold) the shear lives in
voxel_to_local: the render stays exact, only the drawn cube is approximate.
"""

import numpy as np

# Object types that can be Voxlight volumes (Object.voxlight.is_volume):
# imported volumes are Empties; Blender Volume objects (OpenVDB) join when
# "Render with Voxlight" is on (volume_object.py).
VOLUME_TYPES = ("EMPTY", "VOLUME")


def voxel_to_cube(dims):
    """Maps the voxel box [-0.5, dim-0.5]^3 onto the cube [-1, 1]^3."""
    d = np.asarray(dims, np.float64)
    m = np.eye(4)
    m[0:3, 0:3] = np.diag(2.0 / d)
    m[0:3, 3] = 2.0 * 0.5 / d - 1.0
    return m


def scene_from_voxel(affine_mm, dims, unit_scale, center_at=None):
    """voxel -> scene units. unit_scale = scene units per millimetre. With
    center_at (a 3-vector, scene units) the box centre is moved there;
    otherwise the NIfTI world origin is the scene origin."""
    s = np.diag([unit_scale, unit_scale, unit_scale, 1.0])
    m = s @ np.asarray(affine_mm, np.float64).reshape(4, 4)
    if center_at is not None:
        centre_vox = np.append((np.asarray(dims, np.float64) - 1.0) / 2.0, 1.0)
        centre = (m @ centre_vox)[:3]
        t = np.eye(4)
        t[0:3, 3] = np.asarray(center_at, np.float64) - centre
        m = t @ m
    return m


def object_matrix(scene_from_vox, dims):
    """The object matrix that makes the drawn cube match the voxel box."""
    return scene_from_vox @ np.linalg.inv(voxel_to_cube(dims))


def voxel_to_local(scene_from_vox, object_matrix_as_set):
    """Remainder after Blender decomposed the object matrix (drops shear)."""
    return np.linalg.inv(np.asarray(object_matrix_as_set, np.float64)) @ scene_from_vox


def world_corners(model, dims):
    """The 8 world-space corners of the volume box under `model`."""
    lo = -0.5
    hi = np.asarray(dims, np.float64) - 0.5
    pts = np.array([[hi[a] if (c >> a) & 1 else lo for a in range(3)] + [1.0] for c in range(8)])
    return (pts @ np.asarray(model, np.float64).T)[:, :3]


def _clip_corners(model, dims, view, proj):
    c = world_corners(model, dims)
    return np.c_[c, np.ones(8)] @ (np.asarray(proj, np.float64) @ np.asarray(view, np.float64)).T


def outside_frustum(model, dims, view, proj):
    """True when all 8 box corners lie beyond the same clip plane (the box
    cannot be seen; conservative: a box may be reported visible when it
    is not, never the other way round)."""
    clip = _clip_corners(model, dims, view, proj)
    w = clip[:, 3:4]
    return bool(np.any(np.all(clip[:, :3] > w, axis=0)) or
                np.any(np.all(clip[:, :3] < -w, axis=0)))


def screen_rect(model, dims, view, proj, width, height, margin=1):
    """Pixel rectangle (x0, y0, x1, y1), row 0 = bottom, end exclusive, that
    holds every pixel whose ray can meet the box; None when the box is
    outside the view frustum. The whole image when a corner lies behind
    the camera (its projection is then not bounded by the corners')."""
    if outside_frustum(model, dims, view, proj):
        return None
    clip = _clip_corners(model, dims, view, proj)
    w = clip[:, 3]
    if np.any(w <= 1e-9):
        return (0, 0, int(width), int(height))
    ndc = clip[:, :2] / w[:, None]
    sx = (ndc[:, 0] * 0.5 + 0.5) * width
    sy = (ndc[:, 1] * 0.5 + 0.5) * height
    x0 = int(np.clip(np.floor(sx.min()) - margin, 0, width))
    x1 = int(np.clip(np.ceil(sx.max()) + margin, 0, width))
    y0 = int(np.clip(np.floor(sy.min()) - margin, 0, height))
    y1 = int(np.clip(np.ceil(sy.max()) + margin, 0, height))
    if x1 <= x0 or y1 <= y0:
        return None
    return (x0, y0, x1, y1)


def planar_range(model, dims, view):
    """(nearest, farthest) view-space planar distance of the box: the range
    in which a scene depth can stop a ray inside it."""
    c = world_corners(model, dims)
    z = (np.c_[c, np.ones(8)] @ np.asarray(view, np.float64).T)[:, 2]
    return float((-z).min()), float((-z).max())


def voxel_size(model):
    """The smallest world-space edge of one voxel under `model`."""
    m = np.asarray(model, np.float64).reshape(4, 4)
    return float(np.linalg.norm(m[:3, :3], axis=0).min())
