"""Multi-channel volumes through the add-on's binding, without Blender: a
NIfTI whose dim[5] holds three channels (written by nifti_write) loads with
each channel's range in Volume.info; each channel's histogram equals
numpy's of that channel; the styles core/channel_plan builds from channel
settings reach the library (hiding a channel removes exactly its blob, the
LINEAR curve is the library's GRAY preset, DIM changes the image); and a
frame whose channels the library refuses (paged storage) is drawn with the
scalar alone, the refusal kept (runtime.drawing_channels)."""

import types

import numpy as np
import pytest

from voxlight.core import channel_defaults, channel_plan, native, runtime

from nifti_write import write_channels_nifti
from test_modes import axis_camera

N = 20


def ball(cx, peak):
    i, j, k = np.indices((N, N, N)).astype(float)
    d = np.sqrt((i - cx) ** 2 + (j - 10) ** 2 + (k - 10) ** 2)
    return np.where(d < 4, peak * (1 - 0.5 * d / 4), 0).astype(np.uint16)


CHANNELS = [ball(5, 40000), ball(14, 30000), ball(10, 20000)]


@pytest.fixture(scope="module")
def path(tmp_path_factory):
    return str(write_channels_nifti(tmp_path_factory.mktemp("ch") / "three.nii.gz", CHANNELS))


@pytest.fixture(scope="module")
def volume(lib, path):
    v = native.Volume.load(path, lib=lib)
    yield v
    v.close()


def channel(c, **kw):
    d = dict(visible=True, solo=False, color=channel_defaults.LIBRARY_COLORS[c],
             window_low=0.0, window_high=float(CHANNELS[c].max()), opacity=4.0, ramp="LINEAR")
    d.update(kw)
    return types.SimpleNamespace(**d)


def render(lib, r, chans, **kw):
    view, proj, w, h = axis_camera(2, (N, N, N))
    styles = channel_plan.styles(chans) if chans else None
    p = native.make_params(width=w, height=h, view=view, proj=proj, jitter=False, shading=False,
                           channels=styles, lib=lib, **kw)
    return r.render(p)[0]


def test_info_lists_each_channel_and_its_range(volume):
    info = volume.info
    assert info["channel_count"] == 3 and info["scalar_channel"] == 0
    assert info["channel_min"] == [0.0, 0.0, 0.0]
    assert info["channel_max"] == [float(c.max()) for c in CHANNELS]
    d = channel_defaults.channel_defaults(info)
    assert [x["window"] for x in d] == [(0.0, float(c.max())) for c in CHANNELS]


@pytest.mark.parametrize("c", [0, 1, 2])
def test_channel_histogram_is_numpys(volume, c):
    lo, hi = 0.0, float(CHANNELS[c].max())
    ref, _ = np.histogram(CHANNELS[c], bins=32, range=(lo, hi))
    assert np.array_equal(volume.histogram(32, channel=c), ref)
    # a narrower range than the data: values outside are not counted
    ref, _ = np.histogram(CHANNELS[c], bins=8, range=(100.0, hi / 2))
    assert np.array_equal(volume.histogram(8, 100.0, hi / 2, channel=c), ref)


def test_channel_histogram_refusals(lib, volume):
    with pytest.raises(native.VoxlightError, match="channels 0..2, not|the volume has channels 0..2"):
        volume.histogram(8, channel=3)
    one = native.Volume.from_array(np.ones((4, 4, 4), np.float32), lib=lib)
    try:
        with pytest.raises(native.VoxlightError, match="not multi-channel"):
            one.histogram(8, channel=0)
    finally:
        one.close()


@pytest.fixture(scope="module")
def dense(lib, volume):
    r = native.Renderer(lib=lib, storage="dense")
    r.set_volume(volume)
    yield r
    r.close()


def test_hiding_a_channel_removes_exactly_its_blob(lib, dense):
    chans = [channel(0), channel(1), channel(2)]
    both = render(lib, dense, chans)
    chans[1].visible = False
    hidden = render(lib, dense, chans)
    alone = render(lib, dense, [channel(0), channel(1, solo=True), channel(2)])
    blob = alone[..., 3] > 0
    assert blob.any() and (hidden[~blob] == both[~blob]).all()
    assert (hidden[blob][:, 1] < both[blob][:, 1]).all()  # channel 1 is green
    # ADD: everything = hidden + channel 1 alone
    assert np.allclose(both, np.minimum(hidden + alone, 1.0), atol=1e-5)


def test_linear_is_the_gray_preset_and_dim_differs(lib, dense):
    chans = [channel(0), channel(1), channel(2)]
    linear = render(lib, dense, chans)
    table = np.stack([np.linspace(0, 1, 256)] * 3 + [0.1 * np.linspace(0, 1, 256)], 1)
    view, proj, w, h = axis_camera(2, (N, N, N))
    styles = channel_plan.styles(chans)
    for s in styles:
        s["tf_rgba"] = table
    p = native.make_params(width=w, height=h, view=view, proj=proj, jitter=False, shading=False,
                           channels=styles, lib=lib)
    assert np.allclose(dense.render(p)[0], linear, atol=2e-3)
    chans[0].ramp = "DIM"
    dim = render(lib, dense, chans)
    assert not np.allclose(dim, linear, atol=1e-3)


def test_max_blend_differs_from_add(lib, dense):
    chans = [channel(0), channel(1), channel(2)]
    assert not np.allclose(render(lib, dense, chans, channel_blend="max"),
                           render(lib, dense, chans), atol=1e-4)


def test_a_refused_frame_draws_the_scalar_and_says_why(lib, volume):
    r = native.Renderer(lib=lib)
    try:
        r.set_volume(volume)
        view, proj, w, h = axis_camera(2, (N, N, N))
        # a model the add-on's rules refuse, asked for past them: the library refuses it too
        kw = dict(width=w, height=h, view=view, proj=proj, jitter=False, shading=True, shading_model="shadowed",
                  lib=lib)
        entry = types.SimpleNamespace(channel_refusal="")
        p = native.make_params(channels=channel_plan.styles([channel(0), channel(1), channel(2)]), **kw)
        rgba, _depth = runtime.drawing_channels(entry, p, r.render)
        assert "PHONG" in entry.channel_refusal
        scalar = r.render(native.make_params(**kw))[0]
        assert np.array_equal(rgba, scalar) and scalar[..., 3].max() > 0
    finally:
        r.close()
