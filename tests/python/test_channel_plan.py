"""core/channel_plan.py: which settings the library cannot draw channels
with (the panel's reason, checked before a frame), and the channel styles
built from the channels' settings."""

import types

import numpy as np
import pytest

from voxlight.core import channel_plan as cp


def channel(**kw):
    d = dict(visible=True, solo=False, color=(1.0, 0.0, 0.0), window_low=0.0, window_high=10.0,
             opacity=1.0, ramp="LINEAR")
    d.update(kw)
    return types.SimpleNamespace(**d)


def test_no_conflict_with_the_defaults_and_unlit_shadow_models():
    assert cp.conflict() == ""
    assert cp.conflict(shading=False, shading_model="shadowed") == ""  # unlit: any model


@pytest.mark.parametrize("kw, word", [
    (dict(render_mode="mip"), "DVR"), (dict(classify="preint"), "Post"),
    (dict(gradient_opacity="boundary"), "Edges"), (dict(shading_model="scatter"), "Phong"),
    (dict(labels=True), "labels"), (dict(overlays=True), "overlays")])
def test_each_conflict_is_named(kw, word):
    assert word in cp.conflict(**kw)


def test_styles_list_every_channel_in_order():
    chans = [channel(), channel(visible=False, color=(0.0, 2.0, -1.0)),
             channel(window_low=9.0, window_high=3.0, opacity=0.5, ramp="DIM")]
    s = cp.styles(chans)
    assert [d["channel"] for d in s] == [0, 1, 2]
    assert [d["hidden"] for d in s] == [False, True, False]
    assert s[1]["color"] == (0.0, 1.0, 0.0)  # clamped (an overshooting keyframe)
    assert s[2]["window"] == (3.0, 9.0) and s[2]["opacity_scale"] == 0.5
    assert "tf_rgba" not in s[0]  # LINEAR: the library's GRAY preset
    t = np.linspace(0, 1, cp.TABLE_SIZE)
    assert np.allclose(s[2]["tf_rgba"][:, 3], 0.1 * t * t, atol=1e-6)
    assert np.allclose(s[2]["tf_rgba"][:, 0], t * t, atol=1e-6)


def test_solo_counts_only_on_visible_channels():
    chans = [channel(), channel(solo=True, visible=False), channel()]
    assert not any(d["solo"] for d in cp.styles(chans))
    assert cp.drawn(chans) == [0, 2]
    chans[2].solo = True
    assert [d["solo"] for d in cp.styles(chans)] == [False, False, True]
    assert cp.drawn(chans) == [2]


def test_ordered_window():
    assert cp.ordered_window(5, 2) == (2.0, 5.0)
    lo, hi = cp.ordered_window(3, 3)
    assert lo == 3.0 and hi > 3.0


def test_ramp_tables():
    assert cp.ramp_table("LINEAR") is None and cp.ramp_table("nonsense") is None
    for ident, *_ in cp.RAMPS[1:]:
        t = cp.ramp_table(ident, 16)
        assert t.shape == (16, 4) and t.dtype == np.float32
        assert t[0, 3] == 0.0 and abs(t[-1, 3] - cp.GRAY_OPACITY) < 1e-6
        assert np.all(np.diff(t[:, 3]) >= 0)  # opacity never falls as the value rises
