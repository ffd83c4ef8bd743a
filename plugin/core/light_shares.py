"""Each light's share of the light a visible scene point sends to the
camera, and from it the volume's shadow on that point, for engines without
per-light passes (EEVEE in F12, the viewport's layer).

Why not subtract EEVEE's direct-light passes: they hold about 1 % precision,
and where the direct light is almost all of a pixel's light, what the
subtraction leaves in a shadow is mostly that rounding, in bands along the
floor's lines of equal brightness (docs/scene_shadows.md, "EEVEE"). Here
the pixel is multiplied by a factor computed in float64 from geometry:

    result = image * (1 - F),   F = sum_l w_l * (1 - T_l),
    w_l = D_l / (sum_k D_k + A)

with D_l the diffuse light of light l at the point (per unit albedo) and A
the world's. The factor is as smooth as the geometry and the
transmittances, so nothing of the passes' rounding is amplified; each
light's shadow darkens only that light's share, and the world's light stays.

Units follow Cycles (EEVEE matches it): a diffuse surface of albedo 1 sends
E / pi of irradiance E to the camera. A Sun of strength S gives
E = S cos(theta); a point (and spot) light of power P at distance d gives
E = P cos(theta) / (4 pi d^2); a uniform world of radiance L gives L.
Approximate: specular light is shared like the diffuse; area lights count as
spots of their power (lights.py gives them a cone); a mesh's shadow on the
point is not known here (the point counts as lit by every light it faces),
nor is the world's occlusion.

No bpy: positions and normals per pixel, lights.SceneLight values in."""

import math

import numpy as np

from . import lights as _lights


def _brightness(color):
    return float(np.mean(np.asarray(color, np.float64)[:3]))


def _spot_mask(shape, to_point):
    """Blender's spot cone with its blend (Cycles' spot attenuation) along
    the unit directions `to_point` from the light; 1 without a cone."""
    if shape.spot_angle <= 0.0:
        return 1.0
    axis = np.asarray(shape.spot_direction, np.float64)
    n = np.linalg.norm(axis)
    if n <= 0.0:
        return 1.0
    cos_t = to_point @ (axis / n)
    cos_edge = math.cos(min(shape.spot_angle, math.pi) / 2.0)
    smooth = (1.0 - cos_edge) * shape.spot_blend
    t = cos_t - cos_edge
    if smooth > 0.0:
        x = np.clip(t / smooth, 0.0, 1.0)
        return np.where(t > 0.0, x * x * (3.0 - 2.0 * x), 0.0)
    return (t > 0.0).astype(np.float64)


def diffuse_light(light, positions, normals):
    """(h, w) light that `light` (a lights.SceneLight) sends from the points
    `positions` (h, w, 3) with unit `normals` (h, w, 3) to the camera, per
    unit albedo; 0 where a point faces away or is not finite."""
    p = np.asarray(positions, np.float64)
    n = np.asarray(normals, np.float64)
    lp = np.asarray(light.position, np.float64)
    strength = float(light.intensity) * _brightness(light.color)
    if lp[3] == 0.0:
        to_light = np.broadcast_to(lp[:3] / np.linalg.norm(lp[:3]), p.shape)
        irradiance = strength * np.einsum("...i,...i", n, to_light)
    else:
        power = strength * _lights.REFERENCE_POWER["POINT"]
        v = lp[:3] - p
        d2 = np.maximum(np.einsum("...i,...i", v, v), 1e-12)
        u = v / np.sqrt(d2)[..., None]
        irradiance = power * np.einsum("...i,...i", n, u) / (4.0 * math.pi * d2)
        irradiance = irradiance * _spot_mask(light.shape, -u)
    out = np.maximum(irradiance, 0.0) / math.pi
    return np.where(np.isfinite(out), out, 0.0)


def shares(lights, positions, normals, ambient):
    """[(h, w)] each light's share w_l of the point's light, with `ambient`
    the world's light per unit albedo (its radiance); the shares and the
    world's sum to 1 where anything lights the point, all 0 where nothing
    does."""
    direct = [diffuse_light(l, positions, normals) for l in lights]
    if not direct:
        return []
    total = sum(direct) + max(float(ambient), 0.0)
    safe = np.where(total > 0.0, total, 1.0)
    return [np.where(total > 0.0, d / safe, 0.0) for d in direct]


def shadow_amount(light_shares, transmittances):
    """(h, w) F = sum_l w_l (1 - T_l): the part of each pixel's light the
    volume takes away. `transmittances`: {light index: (h, w) T}, a light
    missing there is not shadowed."""
    out = None
    for i, w in enumerate(light_shares):
        t = transmittances.get(i)
        if t is None:
            continue
        part = w * (1.0 - np.asarray(t, np.float64))
        out = part if out is None else out + part
    if out is None:
        return None
    return np.clip(out, 0.0, 1.0).astype(np.float32)
