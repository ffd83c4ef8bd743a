"""Scene lights -> library lights (vxl_light) and their shapes
(vxl_light_shape). No bpy: the objects are read by attribute only, so the
tests (tests/python/test_scene_lights.py) pass stand-ins.

Mapping (documented in README.md):
  * Sun: directional (w = 0). The library wants the direction towards the
    light; a Blender sun shines along its local -Z, so that is the object's
    world +Z axis. Intensity = strength (W/m^2), so the default sun (1.0)
    gives 1.0. Shape: size = the sun's angle (angular diameter, radians).
  * Point, Spot, Area: positional (w = 1) at the object's world location.
    Intensity = power / REFERENCE_POWER, so Blender's default 1000 W point
    or spot gives 1.0.
  * Point: size = shadow_soft_size (the radius, world units).
  * Spot: cone = spot_size (full angle) and spot_blend, pointing along the
    object's world -Z; size = shadow_soft_size.
  * Area: a spot with a wide cone facing along the object's -Z: an area
    light lights only the side it faces, and most along its normal, which a
    point light would get wrong (it would light what is behind the panel).
    The cone is the light's spread (180 degrees by default) with a blend of
    1, so the mask falls smoothly from the normal to the panel's plane,
    close to the cosine of a flat emitter. Size (softness) = half the
    panel's larger side, object scale included: the radius of the disc the
    panel covers.
  * Colour = the light's colour. At most 8 lights (the strongest) are used.
  * Visibility follows Blender: F12 skips lights disabled for rendering;
    the viewport skips lights hidden there (the eye; the monitor and
    disabled collections never reach the depsgraph).
  * No lights (or scene lights switched off): light_count 0, which makes the
    library use its headlight.
The library reads zero colour / intensity as "default", so a light that is
really off is passed as a tiny positive value instead of being dropped
(dropping the last one would turn the headlight on).
"""

import math
from typing import NamedTuple

import numpy as np

from . import native

REFERENCE_POWER = {"POINT": 1000.0, "SPOT": 1000.0, "AREA": 1000.0}
_TINY = 1e-6


class Shape(NamedTuple):
    """A light's vxl_light_shape, fields in the struct's order; all zero is
    a plain light."""
    spot_direction: tuple = (0.0, 0.0, 0.0)
    spot_angle: float = 0.0  # full cone angle, radians; 0 = no cone
    spot_blend: float = 0.0
    size: float = 0.0        # sun: angular diameter (radians); others: radius


class SceneLight(NamedTuple):
    """One library light: vxl_light's fields and its shape. The first three
    are what native.make_params has always taken for a light."""
    position: tuple
    color: tuple
    intensity: float
    shape: Shape = Shape()


def _unit(v, fallback):
    n = float(np.linalg.norm(v))
    return tuple(float(x) / n for x in v) if n > 0 else fallback


def map_light(kind, matrix_world, color, energy):
    """One light as (position4, color3, intensity). matrix_world: 4x4."""
    m = np.asarray(matrix_world, np.float64).reshape(4, 4)
    if kind == "SUN":
        position = [*_unit(m[0:3, 2], (0.0, 0.0, 1.0)), 0.0]
        intensity = float(energy)
    else:
        position = [*m[0:3, 3], 1.0]
        intensity = float(energy) / REFERENCE_POWER.get(kind, 1000.0)
    col = [max(float(c), _TINY) for c in color]
    return (tuple(float(v) for v in position), tuple(col), max(intensity, _TINY))


def map_shape(kind, matrix_world, light):
    """The Shape of Blender light data `light` (read by attribute) of type
    `kind` placed by matrix_world (4x4)."""
    m = np.asarray(matrix_world, np.float64).reshape(4, 4)
    facing = _unit(-m[0:3, 2], (0.0, 0.0, -1.0))  # a spot or area shines along local -Z
    radius = max(float(getattr(light, "shadow_soft_size", 0.0)), 0.0)
    if kind == "SUN":
        return Shape(size=min(max(float(getattr(light, "angle", 0.0)), 0.0), math.pi))
    if kind == "SPOT":
        angle = min(max(float(light.spot_size), 0.0), math.pi)
        blend = min(max(float(light.spot_blend), 0.0), 1.0)
        return Shape(facing, angle, blend, radius)
    if kind == "AREA":
        sx, sy = float(np.linalg.norm(m[0:3, 0])), float(np.linalg.norm(m[0:3, 1]))
        side_x = float(light.size)
        side_y = float(light.size_y) if getattr(light, "shape", "SQUARE") in (
            "RECTANGLE", "ELLIPSE") else side_x
        half = 0.5 * max(abs(side_x) * sx, abs(side_y) * sy)
        spread = min(max(float(getattr(light, "spread", math.pi)), 0.0), math.pi)
        return Shape(facing, spread or math.pi, 1.0, half)
    return Shape(size=radius)


def scene_light(kind, matrix_world, light):
    """SceneLight of Blender light data `light` of type `kind`."""
    pos, col, inten = map_light(kind, matrix_world, light.color, light.energy)
    return SceneLight(pos, col, inten, map_shape(kind, matrix_world, light))


def _shown(inst, for_render):
    """Whether Blender shows the light of depsgraph instance `inst`: F12
    and the API's renders follow Disable in Renders, the viewport the eye
    (hidden objects stay in the viewport depsgraph). Instances (collection
    instances, particles) follow their instancer, which the depsgraph did."""
    if getattr(inst, "is_instance", False):
        return True
    orig = inst.object.original
    if for_render:
        return not orig.hide_render
    return orig.visible_get()


def collect(depsgraph, for_render=False):
    """SceneLights of the evaluated scene, strongest first, at most 8."""
    out = []
    for inst in depsgraph.object_instances:
        ob = inst.object
        if ob.type != "LIGHT" or not _shown(inst, for_render):
            continue
        light = ob.data
        if light.type not in ("SUN", "POINT", "SPOT", "AREA"):
            continue
        out.append(scene_light(light.type, np.array(inst.matrix_world), light))
    out.sort(key=lambda l: -l.intensity * max(l.color))
    return out[:native.MAX_LIGHTS]
