"""Which visible scene points turn their lit side to a light: the volume's
shadow on the scene (scene_shadows.write_render) belongs only there. A
point whose surface, on the side the camera sees, faces away from a light
gets none of that light through its own surface, whatever lies beyond it,
so a volume there shadows nothing. Engines still leak some light onto such
faces (EEVEE's sphere lights, soft shadows); darkening that leak painted a
volume enclosed in a mesh onto the mesh's far side.

No bpy: the z-buffer's triangle ids (zbuffer.rasterize), the triangles and
the camera in, a boolean image out."""

import numpy as np


def pixel_positions(depth, view, proj):
    """(height, width, 3) world positions of the pixel centres at planar
    `depth` (row 0 = bottom); NaN where depth is not finite."""
    h, w = depth.shape
    ys, xs = np.mgrid[0:h, 0:w]
    ndc_x = (xs + 0.5) / w * 2.0 - 1.0
    ndc_y = (ys + 0.5) / h * 2.0 - 1.0
    p = np.asarray(proj, np.float64)
    d = np.where(np.isfinite(depth), depth, np.nan).astype(np.float64)
    z = -d  # view space looks down -Z
    clip_w = p[3, 2] * z + p[3, 3]
    # Invert x_ndc = (p00 x + p02 z + p03) / w_clip (and the same for y).
    vx = (ndc_x * clip_w - p[0, 2] * z - p[0, 3]) / p[0, 0]
    vy = (ndc_y * clip_w - p[1, 2] * z - p[1, 3]) / p[1, 1]
    cam = np.linalg.inv(np.asarray(view, np.float64))
    pts = np.stack([vx, vy, z, np.ones_like(z)], -1) @ cam.T
    return pts[..., :3]


def surface_normals(triangles, ids, depth, view, proj):
    """(height, width, 3) unit normals of the visible triangles, turned to
    the camera's side; NaN where there is no surface (ids < 0)."""
    tris = np.asarray(triangles, np.float64).reshape(-1, 3, 3)
    ids = np.asarray(ids)
    out = np.full(ids.shape + (3,), np.nan)
    hit = (ids >= 0) & np.isfinite(depth)
    if not hit.any() or not len(tris):
        return out
    t = tris[ids[hit]]
    n = np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0])
    p = pixel_positions(depth, view, proj)[hit]
    eye = np.linalg.inv(np.asarray(view, np.float64))[:3, 3]
    n *= np.where(np.einsum("ij,ij->i", n, eye - p) < 0.0, -1.0, 1.0)[:, None]
    length = np.linalg.norm(n, axis=1)[:, None]
    out[hit] = n / np.where(length > 0.0, length, 1.0)
    return out


def depth_normals(positions, view):
    """(height, width, 3) unit normals from the world positions of a depth
    image (pixel_positions): the cross product of its neighbours'
    differences (the smaller one each way, so an edge does not bend a
    face), turned to the camera's side; NaN where a neighbour is missing.
    For a view that has no triangle per pixel (the viewport)."""
    p = np.asarray(positions, np.float64)
    pad = np.pad(p, ((1, 1), (1, 1), (0, 0)), constant_values=np.nan)

    def shorter(a, b):
        la = np.nan_to_num(np.linalg.norm(a, axis=-1), nan=np.inf)
        lb = np.nan_to_num(np.linalg.norm(b, axis=-1), nan=np.inf)
        return np.where((la <= lb)[..., None], a, b)

    dx = shorter(pad[1:-1, 2:] - p, p - pad[1:-1, :-2])
    dy = shorter(pad[2:, 1:-1] - p, p - pad[:-2, 1:-1])
    n = np.cross(dx, dy)
    eye = np.linalg.inv(np.asarray(view, np.float64))[:3, 3]
    n *= np.where(np.einsum("...i,...i", n, eye - p) < 0.0, -1.0, 1.0)[..., None]
    length = np.linalg.norm(n, axis=-1)[..., None]
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(length > 0.0, n / length, np.nan)


def faces_light(triangles, ids, depth, view, proj, light_position):
    """(height, width) bool: True where the visible surface's side that
    faces the camera faces the light too, or where there is no surface
    (ids < 0). light_position: a library light's (x, y, z, w): w = 0 a
    direction towards a sun, else a point."""
    ids = np.asarray(ids)
    out = np.ones(ids.shape, bool)
    hit = (ids >= 0) & np.isfinite(depth)
    if not hit.any() or not len(np.asarray(triangles).reshape(-1)):
        return out
    n = surface_normals(triangles, ids, depth, view, proj)[hit]
    p = pixel_positions(depth, view, proj)[hit]
    lp = np.asarray(light_position, np.float64)
    to_light = np.broadcast_to(lp[:3], p.shape) if lp[3] == 0.0 else lp[:3] - p
    out[hit] = np.einsum("ij,ij->i", n, to_light) > 0.0
    return out
