"""Blender lights -> library lights and shapes (plugin/core/lights.py), without
Blender: light data, objects and depsgraph instances are stand-ins read by
attribute, the way the add-on reads Blender's."""

import math
from types import SimpleNamespace as NS

import numpy as np
import pytest

from voxlight.core import lights


def _matrix(location=(0.0, 0.0, 0.0), rotation=np.eye(3), scale=(1.0, 1.0, 1.0)):
    m = np.eye(4)
    m[:3, :3] = np.asarray(rotation, np.float64) @ np.diag(scale)
    m[:3, 3] = location
    return m


def _rot_y(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def _data(kind, **kw):
    base = dict(type=kind, color=(1.0, 1.0, 1.0), energy=1000.0, shadow_soft_size=0.25)
    if kind == "SUN":
        base.update(energy=1.0, angle=math.radians(0.526))
    if kind == "SPOT":
        base.update(spot_size=math.radians(45.0), spot_blend=0.15)
    if kind == "AREA":
        base.update(size=0.5, size_y=0.5, shape="SQUARE", spread=math.pi)
    base.update(kw)
    return NS(**base)


def _instance(name, data, matrix, hide_render=False, visible=True, is_instance=False,
              kind="LIGHT"):
    orig = NS(name=name, hide_render=hide_render, visible_get=lambda: visible)
    return NS(object=NS(type=kind, data=data, original=orig), matrix_world=matrix,
              is_instance=is_instance)


def test_sun_direction_angle_colour_and_strength():
    # Rotated 90 degrees about Y: its local +Z (towards the sun) is world +X.
    m = _matrix(location=(5.0, 6.0, 7.0), rotation=_rot_y(math.pi / 2))
    sun = lights.scene_light("SUN", m, _data("SUN", color=(1.0, 0.5, 0.25), energy=3.0,
                                               angle=math.radians(10.0)))
    assert np.allclose(sun.position, (1.0, 0.0, 0.0, 0.0), atol=1e-12)  # w = 0, location ignored
    assert sun.color == (1.0, 0.5, 0.25) and sun.intensity == 3.0
    assert sun.shape.size == pytest.approx(math.radians(10.0))  # the angle, as the header wants
    assert sun.shape.spot_angle == 0.0 and sun.shape.spot_direction == (0.0, 0.0, 0.0)
    # A sharp sun (angle 0) gives hard shadows.
    assert lights.scene_light("SUN", m, _data("SUN", angle=0.0)).shape.size == 0.0


def test_point_light_radius_and_power():
    m = _matrix(location=(1.0, 2.0, 3.0))
    pt = lights.scene_light("POINT", m, _data("POINT", energy=500.0, shadow_soft_size=0.1))
    assert pt.position == (1.0, 2.0, 3.0, 1.0)
    assert pt.intensity == pytest.approx(0.5)  # 1000 W is 1
    assert pt.shape == lights.Shape(size=pytest.approx(0.1))
    assert pt.shape.spot_angle == 0.0


def test_spot_cone_follows_its_matrix():
    # A spot shines along its local -Z; turned 90 degrees about Y that is world -X.
    m = _matrix(location=(0.0, 0.0, 2.0), rotation=_rot_y(math.pi / 2))
    spot = lights.scene_light("SPOT", m, _data("SPOT", spot_size=math.radians(30.0),
                                                 spot_blend=0.4, shadow_soft_size=0.05))
    assert spot.position == (0.0, 0.0, 2.0, 1.0)
    assert np.allclose(spot.shape.spot_direction, (-1.0, 0.0, 0.0), atol=1e-12)
    assert spot.shape.spot_angle == pytest.approx(math.radians(30.0))
    assert spot.shape.spot_blend == pytest.approx(0.4)
    assert spot.shape.size == pytest.approx(0.05)
    # Scale does not change the direction's length; Blender's limits hold.
    m2 = _matrix(rotation=np.eye(3), scale=(3.0, 3.0, 3.0))
    wide = lights.scene_light("SPOT", m2, _data("SPOT", spot_size=4.0, spot_blend=2.0))
    assert np.allclose(wide.shape.spot_direction, (0.0, 0.0, -1.0))
    assert wide.shape.spot_angle == pytest.approx(math.pi) and wide.shape.spot_blend == 1.0


def test_area_light_is_a_wide_soft_spot_facing_its_minus_z():
    m = _matrix(location=(0.0, -1.0, 0.0), rotation=_rot_y(math.pi), scale=(2.0, 1.0, 1.0))
    area = lights.scene_light("AREA", m, _data("AREA", size=0.5, energy=250.0))
    assert area.position == pytest.approx((0.0, -1.0, 0.0, 1.0))
    assert area.intensity == pytest.approx(0.25)
    assert np.allclose(area.shape.spot_direction, (0.0, 0.0, 1.0), atol=1e-12)  # flipped
    # The cone is the spread (180 degrees: the half space it faces), blended fully.
    assert area.shape.spot_angle == pytest.approx(math.pi) and area.shape.spot_blend == 1.0
    # Softness: half the larger side, object scale included (0.5 * 2 / 2).
    assert area.shape.size == pytest.approx(0.5)
    rect = lights.scene_light("AREA", _matrix(), _data("AREA", shape="RECTANGLE", size=0.2,
                                                        size_y=1.2, spread=math.radians(60)))
    assert rect.shape.size == pytest.approx(0.6)
    assert rect.shape.spot_angle == pytest.approx(math.radians(60))
    # A square ignores size_y, as Blender does.
    sq = lights.scene_light("AREA", _matrix(), _data("AREA", shape="SQUARE", size=0.2,
                                                      size_y=5.0))
    assert sq.shape.size == pytest.approx(0.1)


def test_off_lights_stay_lights():
    """Zero colour or power is "default" to the library; an off light is
    passed as a tiny one so the headlight stays off."""
    off = lights.scene_light("SPOT", _matrix(), _data("SPOT", color=(0, 0, 0), energy=0.0))
    assert 0 < off.intensity < 1e-3 and 0 < max(off.color) < 1e-3


def _depsgraph(*instances):
    return NS(object_instances=list(instances))


def test_hidden_lights_follow_blenders_visibility():
    m = _matrix(location=(0.0, 0.0, 1.0))
    dg = _depsgraph(
        _instance("shown", _data("POINT"), m),
        _instance("no_render", _data("POINT", energy=2000.0), m, hide_render=True),
        _instance("eye_hidden", _data("POINT", energy=3000.0), m, visible=False),
        _instance("mesh", None, m, kind="MESH"),
    )
    viewport = lights.collect(dg, for_render=False)
    render = lights.collect(dg, for_render=True)
    # The viewport shows what the eye shows (Disable in Renders is not hiding there).
    assert sorted(round(l.intensity) for l in viewport) == [1, 2]
    # F12 renders what renders: the eye does not matter, Disable in Renders does.
    assert sorted(round(l.intensity) for l in render) == [1, 3]


def test_instanced_lights_follow_their_instancer():
    """A light instanced by a collection instance comes from a hidden
    collection: its own flags say hidden, yet it is shown."""
    m = _matrix()
    dg = _depsgraph(_instance("inst", _data("POINT"), m, hide_render=True, visible=False,
                              is_instance=True))
    assert len(lights.collect(dg, True)) == len(lights.collect(dg, False)) == 1


def test_strongest_eight_first_and_every_type():
    m = _matrix()
    kinds = ["SUN", "POINT", "SPOT", "AREA"] * 3
    dg = _depsgraph(*[_instance("l%d" % i, _data(k, energy=(i + 1) * (1.0 if k == "SUN"
                                                                     else 1000.0)), m)
                      for i, k in enumerate(kinds)])
    got = lights.collect(dg)
    assert len(got) == 8
    assert [l.intensity for l in got] == pytest.approx([12, 11, 10, 9, 8, 7, 6, 5])
    assert {l.shape.spot_angle > 0 for l in got} == {True, False}  # spots and areas have cones
