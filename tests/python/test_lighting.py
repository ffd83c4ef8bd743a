"""The volume's lighting settings without Blender (plugin/core/lighting.py and
params' light watch), and their way into vxl_render_params
(native.make_params, tile_params, params_digest)."""

import ctypes
import math
import re

import numpy as np
import pytest

from voxlight.core import lighting, lights, native

from conftest import ROOT


class Props:
    """Object.voxlight as the add-on reads it: attributes, and get() for
    what the file stored (Blender's ID properties: unset = not stored)."""

    def __init__(self, tf_version=lighting.TF_LIGHTING, **stored):
        self.tf_version = tf_version
        self.stored = dict(stored)
        self.shadow_quality = "AUTO"
        self.occlusion_radius = lighting.DEFAULT_OCCLUSION_RADIUS
        self.occlusion_strength = lighting.DEFAULT_OCCLUSION_STRENGTH
        self.anisotropy = 0.0

    @property
    def shading_model(self):
        return self.stored.get("shading_model", lighting.DEFAULT_MODEL)

    @shading_model.setter
    def shading_model(self, value):
        self.stored["shading_model"] = value

    def get(self, key):
        return self.stored.get(key)


def test_defaults_show_shadows_with_a_little_occlusion():
    kw = lighting.look_kwargs(Props())
    assert kw["shading_model"] == "shadowed"
    assert kw["ambient_occlusion"] == 4.0 and kw["occlusion_strength"] == 0.5
    assert kw["anisotropy"] == 0.0 and kw["illumination_size"] == 0  # the library chooses


def test_fallback_models_are_the_headers():
    """The panel's list without a library is the header's VXL_SHADING_* in order."""
    with open(ROOT + "/csrc/include/voxlight.h") as f:
        header = f.read()
    defines = dict((n.lower(), int(v)) for n, v in
                   re.findall(r"#define VXL_SHADING_(PHONG|SHADOWED|SCATTER|PATH) (\d+)", header))
    assert tuple(sorted(defines, key=defines.get)) == native.SHADING_MODELS
    assert lighting.DEFAULT_MODEL in native.SHADING_MODELS
    assert lighting.LEGACY_MODEL == native.SHADING_MODELS[0]  # phong: today's look


def test_old_volumes_keep_phong():
    # Saved before shading models (tf_version 2): nothing stored -> phong.
    old = Props(tf_version=2)
    assert lighting.shading_model_of(old) == "phong"  # even before the upgrade ran
    lighting.upgrade(old, 2)
    assert old.get("shading_model") == "phong"
    old.tf_version = lighting.TF_LIGHTING
    assert lighting.look_kwargs(old)["shading_model"] == "phong"
    # Every older version too (0: before the single editor).
    assert lighting.shading_model_of(Props(tf_version=0)) == "phong"
    # An appended old volume whose model the artist then set keeps that choice.
    chosen = Props(tf_version=2, shading_model="scatter")
    assert lighting.shading_model_of(chosen) == "scatter"
    lighting.upgrade(chosen, 2)
    assert chosen.get("shading_model") == "scatter"
    # A current volume is not touched.
    new = Props()
    lighting.upgrade(new, lighting.TF_LIGHTING)
    assert new.get("shading_model") is None and lighting.shading_model_of(new) == "shadowed"


def test_occlusion_strength_zero_is_off_and_ranges_hold():
    p = Props()
    p.occlusion_strength = 0.0  # the library reads 0 as full strength
    assert lighting.look_kwargs(p)["ambient_occlusion"] == 0.0
    p.occlusion_strength, p.occlusion_radius, p.anisotropy = 3.0, -2.0, 1.0
    kw = lighting.look_kwargs(p)
    assert kw["occlusion_strength"] == 1.0 and kw["ambient_occlusion"] == 0.0
    assert -1.0 < kw["anisotropy"] < 1.0  # HG's g must stay inside (-1, 1)


def test_shadow_quality_and_dragging():
    sizes = {k: s for k, _n, _d, s in lighting.SHADOW_QUALITIES}
    assert sizes == {"AUTO": 0, "LOW": 64, "MEDIUM": 128, "HIGH": 256}
    for key, size in sizes.items():
        assert lighting.illumination_size(key) == size
        dragged = lighting.illumination_size(key, dragging=True)
        # only a quality finer than the library's automatic size coarsens
        # (to it); Auto stays the library's choice, Low its own size
        assert dragged == (lighting.DRAG_ILLUMINATION_SIZE if size > lighting.DRAG_ILLUMINATION_SIZE else size)
    assert lighting.illumination_size("HIGH", dragging=True) < 256
    assert lighting.illumination_size("AUTO", dragging=True) == 0


def _sun(x):
    return lights.SceneLight((x, 0.0, 1.0, 0.0), (1.0, 1.0, 1.0), 1.0, lights.Shape(size=0.01))


def test_light_watch_sees_a_drag_and_its_end():
    w = lighting.LightWatch()
    assert w.update([_sun(1.0)], now=10.0, settle_time=0.3) is None  # first sight: still
    assert w.update([_sun(1.0)], now=10.1, settle_time=0.3) is None
    left = w.update([_sun(0.5)], now=10.2, settle_time=0.3)  # moved
    assert left == pytest.approx(0.3)
    assert w.update([_sun(0.5)], now=10.4, settle_time=0.3) == pytest.approx(0.1)
    assert w.update([_sun(0.5)], now=10.6, settle_time=0.3) is None  # settled
    # Colour and strength do not shape the illumination volume: no drag.
    brighter = [lights.SceneLight((0.5, 0.0, 1.0, 0.0), (1.0, 0.0, 0.0), 5.0,
                                  lights.Shape(size=0.01))]
    assert w.update(brighter, now=11.0, settle_time=0.3) is None
    # A change of shape (the sun's angle) rebuilds it: counts as a drag.
    wider = [lights.SceneLight((0.5, 0.0, 1.0, 0.0), (1.0, 0.0, 0.0), 5.0,
                               lights.Shape(size=0.2))]
    assert w.update(wider, now=12.0, settle_time=0.3) is not None


# ------------------------------------------------------- into the params

def _spot_and_sun():
    spot = lights.SceneLight((0.0, 0.0, 2.0, 1.0), (1.0, 1.0, 1.0), 1.0,
                             lights.Shape((0.0, 0.0, -1.0), 0.5, 0.25, 0.1))
    return [spot, _sun(1.0)]


def test_make_params_passes_shapes_and_settings(lib):
    p = native.make_params(lights=_spot_and_sun(), shading_model="scatter",
                           ambient_occlusion=4.0, occlusion_strength=0.5, anisotropy=0.3,
                           illumination_size=128, lib=lib)
    assert p.shading_model == lib.names("shading_model").index("scatter") == 2
    assert (p.ambient_occlusion, p.occlusion_strength) == (4.0, 0.5)
    assert p.anisotropy == pytest.approx(0.3) and p.illumination_size == 128
    assert p.light_count == 2 and bool(p.light_shapes)
    s0, s1 = p.light_shapes[0], p.light_shapes[1]
    assert s0.struct_size == s1.struct_size == ctypes.sizeof(native.LightShape)
    assert list(s0.spot_direction) == [0.0, 0.0, -1.0]
    assert (s0.spot_angle, s0.spot_blend, s0.size) == pytest.approx((0.5, 0.25, 0.1))
    assert (s1.spot_angle, s1.size) == (0.0, pytest.approx(0.01))
    # Plain (x, y, z) light tuples still work and pass no shapes.
    plain = native.make_params(lights=[((0, 0, 1, 0), (1, 1, 1), 1.0)], lib=lib)
    assert not plain.light_shapes and plain.shading_model == 0
    with pytest.raises(native.VoxlightError):
        native.make_params(shading_model="raytraced", lib=lib)


def test_shapes_outlive_the_call_and_tiles(lib):
    p = native.make_params(lights=_spot_and_sun(), lib=lib)
    import gc
    gc.collect()
    assert p.light_shapes[0].spot_angle == pytest.approx(0.5)  # the array is still there
    t = native.tile_params(native.make_params(width=8, height=8, view=np.eye(4), proj=np.eye(4),
                                              lights=_spot_and_sun(), lib=lib), 0, 0, 4, 4)
    gc.collect()
    assert t.light_shapes[0].size == pytest.approx(0.1)


def test_digest_follows_shapes_and_settings(lib):
    base = dict(lights=_spot_and_sun(), lib=lib)
    d = native.params_digest(native.make_params(**base))
    assert native.params_digest(native.make_params(**base)) == d  # pointers do not count
    moved = _spot_and_sun()
    moved[0] = moved[0]._replace(shape=moved[0].shape._replace(spot_angle=0.6))
    assert native.params_digest(native.make_params(lights=moved, lib=lib)) != d
    for kw in (dict(shading_model="shadowed"), dict(ambient_occlusion=2.0),
               dict(occlusion_strength=0.2), dict(anisotropy=0.5), dict(illumination_size=64)):
        assert native.params_digest(native.make_params(**base, **kw)) != d, kw


def test_a_dragged_light_coarsens_only_the_illumination_volume():
    """params.while_lights_move marks the lights; build() then asks
    lighting for the coarse size. Checked without bpy through lighting."""
    p = Props()
    p.shadow_quality = "HIGH"
    still = lighting.look_kwargs(p)
    dragged = lighting.look_kwargs(p, dragging=True)
    assert still["illumination_size"] == 256
    assert dragged["illumination_size"] == lighting.DRAG_ILLUMINATION_SIZE
    assert {k: v for k, v in dragged.items() if k != "illumination_size"} == \
        {k: v for k, v in still.items() if k != "illumination_size"}


def test_sun_angle_is_radians():
    assert lights.map_shape("SUN", np.eye(4), type("L", (), {"angle": math.pi * 2})()).size \
        == pytest.approx(math.pi)
