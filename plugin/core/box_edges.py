"""Which edges of a volume's box outline lie in front of everything inside
the box, so the viewport can draw them again over the composited volume.

Blender draws the outline (the Empty's wire cube, a Volume object's bounds)
before the add-on composites the volume. A line behind the volume is right
to be covered by it, but the volume also partly covers the lines in front:
the line's anti-aliased fringe carries no depth, so the volume behind it
paints over that fringe, and the edge looks broken or dashed where tissue
lies behind it. The box is convex and holds the whole volume, so an edge
with at least one of its two faces towards the viewer has nothing of the
volume in front of it: those edges are drawn again on top. Edges whose two
faces both face away are hidden by the box itself and left as Blender drew
them, under the volume.

Corners are numbered by bits: bit 0 is +x, bit 1 +y, bit 2 +z of the box's
own axes, so the same code serves any parallelepiped (a sheared or scaled
object). Pure numpy: tests/python/test_box_edges.py.
"""

import numpy as np

# the 12 edges: corner pairs that differ in one bit
EDGES = tuple((i, i | (1 << b)) for b in range(3) for i in range(8) if not i & (1 << b))


def cube_corners(matrix):
    """The 8 corners (8, 3) of the cube [-1, 1]^3 under the 4x4 `matrix`
    (an Empty's matrix_world with its display size folded in)."""
    m = np.asarray(matrix, np.float64).reshape(4, 4)
    local = np.array([[1.0 if i & (1 << b) else -1.0 for b in range(3)] + [1.0] for i in range(8)])
    return (local @ m.T)[:, :3]


def box_corners(matrix, lo, hi):
    """The 8 corners (8, 3) of the local box lo..hi (a bound box's min and
    max) under `matrix`."""
    m = np.asarray(matrix, np.float64).reshape(4, 4)
    lo, hi = np.asarray(lo, np.float64), np.asarray(hi, np.float64)
    local = np.array([[hi[b] if i & (1 << b) else lo[b] for b in range(3)] + [1.0] for i in range(8)])
    return (local @ m.T)[:, :3]


def _faces_towards(corners_view, perspective):
    """For each face (axis, side) with side 0 = low, 1 = high: whether it
    faces the viewer. corners_view are in view space (camera at the origin
    looking down -z)."""
    centre = corners_view.mean(axis=0)
    toward = {}
    for axis in range(3):
        others = [b for b in range(3) if b != axis]
        for side in (0, 1):
            idx = [i for i in range(8) if bool(i & (1 << axis)) == bool(side)]
            pts = corners_view[idx]
            fc = pts.mean(axis=0)
            e0 = corners_view[idx[0] | (1 << others[0])] - corners_view[idx[0]]
            e1 = corners_view[idx[0] | (1 << others[1])] - corners_view[idx[0]]
            n = np.cross(e0, e1)
            if np.dot(n, fc - centre) < 0.0:
                n = -n
            to_eye = -fc if perspective else np.array([0.0, 0.0, 1.0])
            toward[(axis, side)] = float(np.dot(n, to_eye)) > 0.0
    return toward


def front_edges(corners_world, view, perspective):
    """The edges (pairs of corner indices, from EDGES) with at least one face
    towards the viewer: nothing inside the box lies in front of them.
    `view` is the 4x4 world -> view matrix; `perspective` whether the view
    has an eye point (else its rays are parallel to -z)."""
    c = np.asarray(corners_world, np.float64)
    v = np.asarray(view, np.float64).reshape(4, 4)
    cv = np.c_[c, np.ones(8)] @ v.T
    toward = _faces_towards(cv[:, :3], perspective)
    out = []
    for i, j in EDGES:
        axis = (i ^ j).bit_length() - 1
        faces = [(b, 1 if i & (1 << b) else 0) for b in range(3) if b != axis]
        if any(toward[f] for f in faces):
            out.append((i, j))
    return out


def segments(corners_world, edges):
    """The edges as a flat list of line end points, for a LINES batch."""
    c = np.asarray(corners_world, np.float64)
    return [tuple(c[k]) for e in edges for k in e]
