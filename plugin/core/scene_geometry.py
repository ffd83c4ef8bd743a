"""World-space triangles of the scene's evaluated meshes, for the numpy
z-buffer (zbuffer.py) that gives F12 renders their occlusion.

Evaluated geometry means modifiers, shape keys and animation are applied;
instances (collection instances, particles, geometry-node instances) come
from depsgraph.object_instances with their own matrices.
"""

import numpy as np

_GEOMETRY_TYPES = {"MESH", "CURVE", "SURFACE", "FONT", "META"}


def _visible_for_render(ob):
    orig = ob.original
    if orig.hide_render:
        return False
    # Cycles ray visibility: an object the camera cannot see does not occlude.
    return getattr(orig, "visible_camera", True)


def mesh_arrays(ob, matrix_world):
    """(vertices (n, 3) float64 in world space through matrix_world,
    triangles (m, 3) int64 indices) of an evaluated object's mesh, or None
    when it has no triangles (or no mesh). Also the cutaways' cutter
    meshes (cutaway.py)."""
    try:
        mesh = ob.to_mesh()
    except RuntimeError:
        return None
    if mesh is None:
        return None
    try:
        mesh.calc_loop_triangles()
        n = len(mesh.loop_triangles)
        if n == 0:
            return None
        co = np.empty(len(mesh.vertices) * 3, np.float64)
        mesh.vertices.foreach_get("co", co)
        tri = np.empty(n * 3, np.int64)
        mesh.loop_triangles.foreach_get("vertices", tri)
    finally:
        ob.to_mesh_clear()
    mw = np.array(matrix_world, np.float64)
    return co.reshape(-1, 3) @ mw[:3, :3].T + mw[:3, 3], tri.reshape(-1, 3)


def triangles(depsgraph, for_render=True):
    """(n, 3, 3) float64 world-space triangles of every visible solid object."""
    chunks = []
    for inst in depsgraph.object_instances:
        ob = inst.object
        if ob.type not in _GEOMETRY_TYPES:
            continue
        if for_render and not _visible_for_render(ob):
            continue
        arrays = mesh_arrays(ob, inst.matrix_world)
        if arrays is not None:
            chunks.append(arrays[0][arrays[1]])
    if not chunks:
        return np.zeros((0, 3, 3))
    return np.concatenate(chunks, axis=0)
