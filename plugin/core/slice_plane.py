"""Slice planes without bpy: which part of a plane object the
slice image covers, how many pixels it gets, and where each pixel lies.

A slice is the square [-1, 1]^2 at z = 0 of its plane_to_world matrix
(vxl_render_slice). For a plane object that square is the mesh's bounding
rectangle in local XY, so the image maps onto the mesh exactly through
Blender's Generated texture coordinates (the bounding box as [0, 1]^3)."""

import numpy as np

DEFAULT_MAX_SIDE = 1024


def plane_to_world(matrix_world, local_min, local_max):
    """The slice square of a plane object: matrix_world @ translate(centre)
    @ scale(half size) of its local bounding rectangle (local_min and
    local_max: the bounding box corners, x and y used). ValueError when the
    rectangle or the transform has no area."""
    lo = np.asarray(local_min, np.float64)[:2]
    hi = np.asarray(local_max, np.float64)[:2]
    half = (hi - lo) / 2.0
    if not (half > 0).all():
        raise ValueError("the slice plane's mesh has no extent in its local X and Y")
    local = np.eye(4)
    local[0, 0], local[1, 1] = half
    local[:2, 3] = (hi + lo) / 2.0
    m = np.asarray(matrix_world, np.float64).reshape(4, 4) @ local
    if not np.isfinite(m).all() or np.linalg.norm(np.cross(m[:3, 0], m[:3, 1])) == 0.0:
        raise ValueError("the slice plane is scaled to nothing in its X or Y")
    return m


def image_size(plane, model, max_side=DEFAULT_MAX_SIDE):
    """(width, height) in pixels: about one pixel per voxel (the finest
    voxel spacing of `model`, voxel -> world) along the slice's sides,
    both scaled down together when the longer one exceeds max_side, at
    least 1 each."""
    plane = np.asarray(plane, np.float64)
    model = np.asarray(model, np.float64)
    spacing = float(min(np.linalg.norm(model[:3, i]) for i in range(3)))
    sides = np.array([2.0 * np.linalg.norm(plane[:3, 0]), 2.0 * np.linalg.norm(plane[:3, 1])])
    px = sides / max(spacing, 1e-12)
    if px.max() > max_side:
        px *= max_side / px.max()
    w, h = (max(1, int(round(v))) for v in px)
    return w, h


def pixel_positions(plane, width, height):
    """World positions (height, width, 3) of the pixel centres, row 0 =
    bottom: pixel (x, y) lies at ((x + 0.5) / width * 2 - 1, (y + 0.5) /
    height * 2 - 1, 0) of the slice square (vxl_slice_params)."""
    plane = np.asarray(plane, np.float64)
    u = (np.arange(width) + 0.5) / width * 2.0 - 1.0
    v = (np.arange(height) + 0.5) / height * 2.0 - 1.0
    uu, vv = np.meshgrid(u, v)
    return (plane[:3, 0] * uu[..., None] + plane[:3, 1] * vv[..., None] + plane[:3, 3])


def inside_volume(points, model, dims):
    """Whether each world point (..., 3) lies in the volume's box (voxel
    centres at integers, the box [-0.5, dim - 0.5]): the pixels a slice
    gives alpha 1."""
    inv = np.linalg.inv(np.asarray(model, np.float64))
    p = np.asarray(points, np.float64)
    q = p @ inv[:3, :3].T + inv[:3, 3]
    d = np.asarray(dims, np.float64)
    return ((q >= -0.5) & (q <= d - 0.5)).all(axis=-1)
