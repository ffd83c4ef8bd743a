"""Framing a volume in a 3D viewport after import ("Frame in View", what
View Selected does for a mesh). Pure numpy (no bpy): the maths is
unit-tested in tests/python/test_framing.py and checked against Blender's
own projection in tests/blender/test_gui_orientation.py.

Blender's viewport (not looking through a camera) is a camera with the
view's lens (View › Focal Length, 50 mm by default), a 36 mm sensor and a
zoom of 2 (BKE_camera_params_from_view3d: DEFAULT_SENSOR_WIDTH,
CAMERA_PARAM_ZOOM_INIT_PERSP), fitted to the region's larger side. So
along the larger side the half field of view has tan = 36 / lens, along
the smaller side that times smaller / larger. Orthographic views show
the same extent at the view distance: half-width = distance * 36 / lens.
"""

import math

import numpy as np

VIEWPORT_HALF_SENSOR_MM = 36.0  # 36 mm sensor x zoom 2, halved
MARGIN = 1.1                    # a little room around the box, as View Selected leaves


def bounding_sphere(corners):
    """(centre, radius) of the sphere around the box's corners (the box's
    centre and half diagonal for a box)."""
    c = np.asarray(corners, np.float64).reshape(-1, 3)
    centre = (c.min(axis=0) + c.max(axis=0)) / 2.0
    radius = float(np.linalg.norm(c - centre, axis=1).max())
    return centre, radius


def view_distance(radius, lens_mm, width, height, perspective=True, margin=MARGIN):
    """The view distance at which a sphere of `radius` fits the region
    (width x height pixels) with `margin`: for perspective the sphere's
    tangent cone fits the narrower half angle; for orthographic its radius
    fits the narrower half extent."""
    if radius <= 0.0:
        raise ValueError("nothing to frame: radius %r" % (radius,))
    if lens_mm <= 0.0 or width <= 0 or height <= 0:
        raise ValueError("bad view: lens %r, region %r x %r" % (lens_mm, width, height))
    tan_half = VIEWPORT_HALF_SENSOR_MM / lens_mm * min(width, height) / max(width, height)
    if perspective:
        return radius * margin / math.sin(math.atan(tan_half))
    return radius * margin / tan_half


def frame(corners, lens_mm, width, height, perspective=True, margin=MARGIN):
    """(view_location, view_distance) that frames the box with these world
    corners, whatever the view's rotation (the bounding sphere looks the
    same from every side)."""
    centre, radius = bounding_sphere(corners)
    return centre, view_distance(radius, lens_mm, width, height, perspective, margin)
