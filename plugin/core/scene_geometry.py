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


def triangles(depsgraph, for_render=True):
    """(n, 3, 3) float64 world-space triangles of every visible solid object."""
    chunks = []
    for inst in depsgraph.object_instances:
        ob = inst.object
        if ob.type not in _GEOMETRY_TYPES:
            continue
        if for_render and not _visible_for_render(ob):
            continue
        try:
            mesh = ob.to_mesh()
        except RuntimeError:
            continue
        if mesh is None:
            continue
        try:
            mesh.calc_loop_triangles()
            n = len(mesh.loop_triangles)
            if n == 0:
                continue
            co = np.empty(len(mesh.vertices) * 3, np.float64)
            mesh.vertices.foreach_get("co", co)
            tri = np.empty(n * 3, np.int64)
            mesh.loop_triangles.foreach_get("vertices", tri)
        finally:
            ob.to_mesh_clear()
        mw = np.array(inst.matrix_world, np.float64)
        world = co.reshape(-1, 3) @ mw[:3, :3].T + mw[:3, 3]
        chunks.append(world[tri.reshape(-1, 3)])
    if not chunks:
        return np.zeros((0, 3, 3))
    return np.concatenate(chunks, axis=0)
