"""Scene lights -> library lights (vxl_light).

Mapping (documented in README.md):
  * Sun: directional (w = 0). The library wants the direction towards the
    light; a Blender sun shines along its local -Z, so that is the object's
    world +Z axis. Intensity = strength (W/m^2), so the default sun (1.0)
    gives 1.0.
  * Point, Spot, Area: positional (w = 1) at the object's world location.
    Spot cones and area shapes are not modelled. Intensity = power /
    REFERENCE_POWER, so Blender's default 1000 W point or spot gives 1.0.
  * Colour = the light's colour. At most 8 lights (the strongest) are used.
  * No lights (or scene lights switched off): light_count 0, which makes the
    library use its headlight.
The library reads zero colour / intensity as "default", so a light that is
really off is passed as a tiny positive value instead of being dropped
(dropping the last one would turn the headlight on).
"""

import numpy as np

from . import native

REFERENCE_POWER = {"POINT": 1000.0, "SPOT": 1000.0, "AREA": 1000.0}
_TINY = 1e-6


def map_light(kind, matrix_world, color, energy):
    """One light as (position4, color3, intensity). matrix_world: 4x4."""
    m = np.asarray(matrix_world, np.float64).reshape(4, 4)
    if kind == "SUN":
        z = m[0:3, 2]
        n = np.linalg.norm(z)
        direction = z / n if n > 0 else np.array([0.0, 0.0, 1.0])
        position = [*direction, 0.0]
        intensity = float(energy)
    else:
        position = [*m[0:3, 3], 1.0]
        intensity = float(energy) / REFERENCE_POWER.get(kind, 1000.0)
    col = [max(float(c), _TINY) for c in color]
    return (tuple(float(v) for v in position), tuple(col), max(intensity, _TINY))


def collect(depsgraph, for_render=False):
    """Lights of the evaluated scene, strongest first, at most 8."""
    out = []
    for inst in depsgraph.object_instances:
        ob = inst.object
        if ob.type != "LIGHT":
            continue
        if for_render and ob.original.hide_render:
            continue
        light = ob.data
        out.append(map_light(light.type, np.array(inst.matrix_world), light.color, light.energy))
    out.sort(key=lambda l: -l[2] * max(l[1]))
    return out[:native.MAX_LIGHTS]
