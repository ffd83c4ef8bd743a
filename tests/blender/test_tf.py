"""Headless Blender: the ColorRamp transfer function, 3D Slicer presets,
classification modes, gradient opacity and the import histogram (issue 6).

blender -b --factory-startup --python-exit-code 1 --python tests/blender/test_tf.py
"""

import os
import sys

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import _util as u  # noqa: E402
from _util import test  # noqa: E402

vx = u.install_addon()
RES = (64, 64)


def _volume(name, lo=0.0, hi=120.0):
    """The phantom ball rescaled so 0 -> lo and 120 -> hi (data units)."""
    u.reset_scene()
    v = u.phantom(32) / 120.0
    aff = np.diag([2.0, 2.0, 2.0, 1.0])
    aff[:3, 3] = -31.0
    path = u.write_nifti(os.path.join(u.TMP, name), (lo + v * (hi - lo)).astype(np.float32),
                         aff)
    ob = u.import_volume(path)
    u.add_camera((0.0, -2.5, 0.3))
    ob.voxlight.jitter = False
    return ob


def _render(ob):
    return vx.render_volume(ob, resolution=RES)


def _diff(a, b):
    return float(np.abs(a - b).max())


@test
def import_gives_ramp_and_histogram():
    ob = _volume("hist.nii.gz")
    p = ob.voxlight
    tex = p.tf_texture
    assert tex is not None and tex.type == "BLEND" and tex.use_color_ramp
    assert tex.name.startswith(".VXL TF")
    h = np.array(p.histogram)
    assert h.sum() == 32 ** 3, h.sum()
    assert h[0] > h[-1] > 0  # mostly background zeros, some bright ball voxels
    from voxlight import tf
    assert len(tf.histogram_text(h)) == 32


@test
def editing_a_ramp_stop_changes_the_render():
    ob = _volume("ramp.nii.gz")
    p = ob.voxlight
    p.use_window, p.window_low, p.window_high = True, 0.0, 120.0
    ref = _render(ob)
    p.use_color_ramp = True
    img = _render(ob)
    assert _diff(img, ref) > 1e-3, "ColorRamp did not replace the preset"
    ramp = p.tf_texture.color_ramp
    prev = img
    for what, edit in (("colour", lambda: setattr(ramp.elements[1], "color", (1, 0, 0, 1))),
                       ("alpha", lambda: setattr(ramp.elements[1], "alpha", 0.1)),
                       ("position", lambda: setattr(ramp.elements[0], "position", 0.5)),
                       ("new stop", lambda: setattr(ramp.elements.new(0.8), "color",
                                                    (0, 0, 1, 1)))):
        edit()
        img = _render(ob)
        assert _diff(img, prev) > 1e-3, "ramp %s edit did not change the image" % what
        prev = img
    # Red stop: the image is red where the ball is.
    assert img[..., 0].max() > 0.2
    # The sampled table is part of the viewport's frame key.
    view, proj = np.eye(4), np.eye(4)
    k1 = vx.native.params_digest(vx.params.build(ob, 8, 8, view, proj), "id")
    ramp.elements[0].color = (0, 1, 0, 0.5)
    k2 = vx.native.params_digest(vx.params.build(ob, 8, 8, view, proj), "id")
    k3 = vx.native.params_digest(vx.params.build(ob, 8, 8, view, proj), "id")
    assert k1 != k2 and k2 == k3
    # Back to the library preset: the ramp is ignored.
    p.use_color_ramp = False
    assert _diff(_render(ob), ref) < 1e-5


# Each preset on a volume whose values lie where the preset shows something.
PRESET_DATA = {"CT_BONE": (-1000.0, 1000.0), "CT_SOFT_TISSUE": (-1000.0, 100.0),
               "CT_LUNG": (-1000.0, -500.0), "MR_DEFAULT": (0.0, 300.0),
               "MR_ANGIO": (0.0, 300.0)}


@test
def presets_rewrite_the_ramp_and_render():
    from voxlight import tf
    assert set(PRESET_DATA) == set(tf.SLICER_PRESETS)
    images = {}
    for key, (lo, hi) in PRESET_DATA.items():
        ob = _volume("preset_%s.nii.gz" % key.lower(), lo, hi)
        p = ob.voxlight
        with bpy.context.temp_override(object=ob, active_object=ob):
            assert bpy.ops.voxlight.tf_preset(preset=key) == {"FINISHED"}
        wlo, whi, stops = tf.preset_stops(key)
        assert p.use_color_ramp and p.use_window
        assert abs(p.window_low - wlo) < 1e-3 and abs(p.window_high - whi) < 1e-3
        els = p.tf_texture.color_ramp.elements
        assert len(els) == len(stops), (key, len(els), len(stops))
        # The ramp reproduces the preset's opacity at its own points.
        pr = tf.SLICER_PRESETS[key]
        for x, a in pr["opacity"]:
            if wlo <= x <= whi:
                got = p.tf_texture.color_ramp.evaluate((x - wlo) / (whi - wlo))[3]
                assert abs(got - a) < 0.02, (key, x, a, got)
        img = _render(ob)
        assert img[..., 3].max() > 0.2, (key, img[..., 3].max())
        assert img[0, 0, 3] < 0.05, key
        images[key] = img
    keys = list(images)
    for i in range(len(keys)):
        for j in range(i + 1, len(keys)):
            assert images[keys[i]].shape == images[keys[j]].shape


@test
def classification_and_gradient_opacity_change_the_render():
    ob = _volume("classify.nii.gz")
    p = ob.voxlight
    p.use_window, p.window_low, p.window_high = True, 20.0, 110.0
    p.use_color_ramp = True
    ramp = p.tf_texture.color_ramp
    # A sharp ramp: pre-integration matters most there.
    ramp.elements[0].position, ramp.elements[0].color = 0.55, (1, 0.5, 0.2, 0.0)
    ramp.elements[1].position, ramp.elements[1].color = 0.6, (1, 1, 1, 0.8)
    prev = _render(ob)
    for name, value in (("classify", "pre"), ("classify", "preint"), ("classify", "post"),
                        ("gradient_opacity", "boundary"), ("gradient_ref", 0.5),
                        ("gradient_exp", 3.0), ("gradient_opacity", "iso"),
                        ("iso_value", 90.0), ("iso_thickness", 3.0)):
        setattr(p, name, value)
        img = _render(ob)
        assert np.isfinite(img).all()
        assert _diff(img, prev) > 1e-3, "%s=%r did not change the image" % (name, value)
        prev = img
    assert img[..., 3].max() > 0.05


@test
def f12_uses_the_ramp():
    """F12 (bpy.ops.render.render) composites the ColorRamp's colours."""
    ob = _volume("f12.nii.gz")
    scene = bpy.context.scene
    scene.render.resolution_x = scene.render.resolution_y = 48
    scene.render.engine = "BLENDER_WORKBENCH"
    p = ob.voxlight
    p.use_window, p.window_low, p.window_high = True, 0.0, 120.0
    p.use_color_ramp = True
    ramp = p.tf_texture.color_ramp
    for e in ramp.elements:
        e.color = (0.0, 1.0, 0.0, e.color[3])
    ramp.elements[1].alpha = 1.0
    out = os.path.join(u.TMP, "f12_ramp.png")
    scene.render.filepath = out
    scene.render.image_settings.file_format = "PNG"
    bpy.ops.render.render(write_still=True)
    img = u.load_png(out)
    centre = img[20:28, 20:28, :3].mean(axis=(0, 1))
    assert centre[1] > centre[0] + 0.1 and centre[1] > centre[2] + 0.1, centre


class _AnyLayout:
    """Stands in for a UILayout: accepts every call and records prop names."""

    def __init__(self, log):
        self.__dict__["log"] = log

    def __getattr__(self, name):
        def call(*args, **kw):
            self.log.append((name, args[1] if len(args) > 1 else kw.get("text")))
            return _AnyLayout(self.log)
        return call

    def __setattr__(self, name, value):
        pass


@test
def panel_draws_ramp_and_new_properties():
    ob = _volume("panel.nii.gz")
    p = ob.voxlight
    panel = bpy.types.VOXLIGHT_PT_volume
    for use_ramp, gop in ((False, "off"), (True, "boundary"), (True, "iso")):
        p.use_color_ramp, p.gradient_opacity = use_ramp, gop
        log = []

        class Ctx:
            object = ob
        panel.draw(type("P", (), {"layout": _AnyLayout(log)})(), Ctx)
        names = {n for _f, n in log}
        assert "classify" in names and "gradient_opacity" in names
        assert ("template_color_ramp", "color_ramp") in log or not use_ramp
        assert (("prop", "preset") in log) == (not use_ramp)
        assert ("iso_value" in names) == (gop == "iso")
        assert any(isinstance(n, str) and n.startswith("Histogram") for n in names)


@test
def unregister_removes_the_handler():
    bpy.ops.preferences.addon_disable(module="voxlight")
    assert not [h for h in bpy.app.handlers.depsgraph_update_post
                if "voxlight" in getattr(h, "__module__", "")]
    assert not hasattr(bpy.ops.voxlight, "tf_preset") or \
        "voxlight.tf_preset" not in dir(bpy.types)
    bpy.ops.preferences.addon_enable(module="voxlight")


u.run("test_tf")
