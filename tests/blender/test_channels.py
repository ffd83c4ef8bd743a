"""Multi-channel volumes in Blender (docs/channels.md, "In Blender"): a
NIfTI whose dim[5] holds three channels (a ball each, apart) imports as ONE
object with three channels named and coloured by default, each with its
range as window and its histogram (numpy's); F12 draws them, and hiding a
channel removes exactly its blob; one channel's window changes only its
pixels; solo shows the solo channel alone; a dye preset sets the colour
(of a channel named or of the active one); the colour takes keyframes; the settings survive saving
and reopening; settings the library cannot draw channels with (a shading
model other than Phong, bricked storage) draw channel 0 alone, with the
reason in the panel, never an error; the World's light does not stop them.

blender -b --factory-startup --python-exit-code 1 --python tests/blender/test_channels.py
"""

import os
import sys

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import _util as u  # noqa: E402
from _util import test  # noqa: E402
from nifti_write import write_channels_nifti  # noqa: E402

vx = u.install_addon()
SIZE = 64
N = 24
# three balls apart along x (and the third lower in z): red, green, blue
CENTRES = [(6, 12, 14), (17, 12, 14), (12, 12, 5)]
PEAKS = [40000, 30000, 20000]


def _ball(centre, peak):
    i, j, k = np.indices((N, N, N)).astype(float)
    d = np.sqrt(sum((a - c) ** 2 for a, c in zip((i, j, k), centre)))
    return np.where(d < 4.5, peak * (1 - 0.5 * d / 4.5), 0).astype(np.uint16)


CHANNELS = [_ball(c, p) for c, p in zip(CENTRES, PEAKS)]
PATH = write_channels_nifti(os.path.join(u.TMP, "three_channels.nii.gz"), CHANNELS,
                            np.diag([2.0, 2.0, 2.0, 1.0]))


def _mod(name):
    return sys.modules[u.MODULE + "." + name]


def _scene():
    scene = u.black_cycles_scene(SIZE)
    u.add_camera((0.0, -1.2, 0.0))
    ob = u.import_volume(PATH)
    ob.voxlight.jitter = False
    for ch in ob.voxlight.channels:
        ch.opacity = 4.0
    return scene, ob


def _offline(scene):
    rgba, _depth = vx.offline.render(scene, bpy.context.evaluated_depsgraph_get(), scene.camera,
                                     SIZE, SIZE)
    return rgba


def _alone(scene, ob, c):
    """The image of channel c drawn alone (every other hidden)."""
    keep = [ch.visible for ch in ob.voxlight.channels]
    for i, ch in enumerate(ob.voxlight.channels):
        ch.visible = i == c
    img = _offline(scene)
    for ch, v in zip(ob.voxlight.channels, keep):
        ch.visible = v
    return img


def _footprint(img):
    return img[..., 3] > 0


@test
def a_three_channel_file_imports_as_one_object_with_its_channels():
    scene, ob = _scene()
    vols = [o for o in bpy.data.objects if o.voxlight.is_volume]
    assert vols == [ob], vols
    p = ob.voxlight
    assert [ch.name for ch in p.channels] == ["Channel 0", "Channel 1", "Channel 2"]
    assert [tuple(round(v, 6) for v in ch.color) for ch in p.channels] == \
        [(1, 0, 0), (0, 1, 0), (0, 0, 1)]
    for ch, data in zip(p.channels, CHANNELS):
        assert (ch.window_low, ch.window_high) == (0.0, float(data.max()))
        assert (ch.data_min, ch.data_max) == (0.0, float(data.max()))
        ref, _ = np.histogram(data, bins=32, range=(0.0, float(data.max())))
        assert list(ch.histogram) == ref.tolist()
    assert p.use_channels and p.channel_blend == "add"
    assert p.shading_model == "phong" and not p.shading
    img = _offline(scene)
    for c in range(3):  # each channel's colour shows
        assert (img[..., c] > 0.2).sum() > 10, c


@test
def f12_draws_the_channels_and_hiding_one_removes_exactly_its_blob():
    scene, ob = _scene()

    def f12(name):
        scene.render.filepath = os.path.join(u.TMP, name + ".png")
        bpy.ops.render.render(write_still=True)
        return u.load_png(scene.render.filepath)[..., :3]

    both = f12("channels_all")
    assert (both[..., 1] > 0.2).sum() > 10  # green: channel 1
    blob = _footprint(_alone(scene, ob, 1))
    ob.voxlight.channels[1].visible = False
    hidden = f12("channels_hidden")
    assert (hidden[..., 1] < 0.02).all()  # no green anywhere
    assert np.abs(hidden - both)[~blob].max() < 2.5 / 255  # elsewhere the same (8-bit PNG)
    assert (both[blob][:, 1] - hidden[blob][:, 1]).max() > 0.2


@test
def a_channels_window_changes_only_its_pixels_and_solo_shows_one():
    scene, ob = _scene()
    before = _offline(scene)
    red = _footprint(_alone(scene, ob, 0))
    ob.voxlight.channels[0].window_high = PEAKS[0] / 4.0
    after = _offline(scene)
    diff = np.abs(after - before).max(axis=2)
    assert diff[~red].max() < 1e-6, (diff[~red].max(), np.argwhere(diff * ~red > 1e-6)[:5],
                                     red.sum())
    assert np.abs(after - before)[red].max() > 0.05
    ob.voxlight.channels[2].solo = True
    solo = _offline(scene)
    assert np.abs(solo - _alone(scene, ob, 2)).max() < 1e-6
    assert solo[..., 0].max() < 1e-6 and solo[..., 1].max() < 1e-6 and solo[..., 2].max() > 0.2
    bpy.context.view_layer.objects.active = ob
    assert bpy.ops.voxlight.channel_show_all() == {"FINISHED"}
    assert all(ch.visible and not ch.solo for ch in ob.voxlight.channels)


@test
def a_dye_preset_sets_the_colour_and_fit_restores_the_window():
    scene, ob = _scene()
    bpy.context.view_layer.objects.active = ob
    assert bpy.ops.voxlight.channel_dye(index=0, dye="DAPI") == {"FINISHED"}
    assert tuple(ob.voxlight.channels[0].color) == (0.0, 0.0, 1.0)
    ob.voxlight.active_channel = 1
    assert bpy.ops.voxlight.channel_dye(dye="CY5") == {"FINISHED"}  # the active channel
    assert tuple(ob.voxlight.channels[1].color) == (1.0, 0.0, 1.0)
    try:  # a channel the volume does not have: an error report, nothing changed
        bpy.ops.voxlight.channel_dye(index=7, dye="GFP")
    except RuntimeError as e:
        assert "channels 0..2, not 7" in str(e), e
    else:
        raise AssertionError("channel 7 was accepted")
    img = _offline(scene)
    red = _footprint(_alone(scene, ob, 0))
    assert img[red][:, 0].max() < 1e-6 and img[red][:, 2].max() > 0.2  # DAPI: blue, no red
    ch = ob.voxlight.channels[2]
    ch.window_low, ch.window_high = 500.0, 600.0
    ob.voxlight.active_channel = 2
    assert bpy.ops.voxlight.channel_fit_window() == {"FINISHED"}
    assert (ch.window_low, ch.window_high) == (0.0, float(PEAKS[2]))


@test
def the_colour_window_and_visibility_take_keyframes():
    scene, ob = _scene()
    ch = ob.voxlight.channels[0]
    ch.color = (1.0, 0.0, 0.0)
    ch.keyframe_insert("color", frame=1)
    ch.color = (0.0, 0.0, 1.0)
    ch.keyframe_insert("color", frame=11)
    ch.keyframe_insert("window_high", frame=1)
    ch.keyframe_insert("visible", frame=1)
    ch.keyframe_insert("opacity", frame=1)
    scene.frame_set(1)
    assert tuple(ch.color) == (1.0, 0.0, 0.0)
    first = _offline(scene)
    scene.frame_set(11)
    assert tuple(ch.color) == (0.0, 0.0, 1.0)
    last = _offline(scene)
    scene.frame_set(6)
    r, _g, b = ch.color
    assert 0.05 < r < 0.95 and 0.05 < b < 0.95
    red = _footprint(_alone(scene, ob, 0))
    assert first[red][:, 0].max() > 0.2 and last[red][:, 0].max() < 1e-6
    scene.frame_set(1)
    ob.animation_data_clear()


@test
def the_channel_settings_survive_saving_and_reopening():
    scene, ob = _scene()
    p = ob.voxlight
    p.channels[0].name = "Nuclei"
    p.channels[1].color = (0.25, 0.5, 0.75)
    p.channels[1].window_low = 1000.0
    p.channels[2].visible = False
    p.channels[2].ramp = "DIM"
    p.channel_blend = "max"
    p.active_channel = 2
    before = _offline(scene)
    (ob,) = u.reopen([ob], "channels.blend")
    p = ob.voxlight
    assert [ch.name for ch in p.channels] == ["Nuclei", "Channel 1", "Channel 2"]
    assert np.allclose(tuple(p.channels[1].color), (0.25, 0.5, 0.75))
    assert p.channels[1].window_low == 1000.0 and not p.channels[2].visible
    assert p.channels[2].ramp == "DIM" and p.channel_blend == "max" and p.active_channel == 2
    assert list(p.channels[0].histogram) == list(np.histogram(CHANNELS[0], 32, (0, PEAKS[0]))[0])
    after = _offline(bpy.context.scene)
    assert np.abs(after - before).max() < 1e-5


@test
def settings_that_cannot_draw_channels_draw_channel_0_alone_and_say_why():
    scene, ob = _scene()
    p = ob.voxlight
    cp = _mod("channel_props")
    p.use_channels = False
    scalar = _offline(scene)  # channel 0 with the volume's own transfer function
    assert scalar[..., 3].max() > 0
    p.use_channels = True
    assert cp.why_not(p) == ""
    p.shading = True
    p.shading_model = "shadowed"
    assert "Phong" in cp.why_not(p)
    p.shading = False
    p.render_mode = "mip"
    assert "DVR" in cp.why_not(p)
    mip = _offline(scene)  # no exception: the scalar's MIP
    assert mip[..., 3].max() > 0
    p.render_mode = "dvr"
    # bricked storage pages the channels as the scalar: the same image as dense
    p.shading = False
    dense = _offline(scene)
    scene.voxlight.storage = "bricked"
    assert cp.why_not(p) == ""
    bricked = _offline(scene)
    assert bricked[..., 3].max() > 0 and np.abs(bricked - scalar).max() > 2e-3  # the channels, not channel 0
    assert np.abs(bricked - dense).max() < 2e-3
    scene.voxlight.storage = "auto"
    # the World's light is left out of channel frames rather than refusing them
    scene.voxlight.use_world_light = True
    p.shading = True
    p.shading_model = "phong"
    lit = _offline(scene)
    assert cp.why_not(p) == "" and lit[..., 1].max() > 0.1


class _Recorder:
    """Stands in for a UILayout: records (call, first text argument or
    property name, keyword arguments) of every call."""

    def __init__(self, calls):
        self.__dict__["calls"] = calls

    def __getattr__(self, name):
        def call(*args, **kw):
            what = args[1] if name == "prop" and len(args) > 1 else args[0] if args else None
            if name == "label":
                what = kw.get("text", what)
            self.calls.append((name, what, kw))
            return _Recorder(self.calls)
        return call

    def __setattr__(self, name, value):
        self.calls.append(("set", name, value))


def _draw_panel(ob):
    calls = []

    class Ctx:
        object = ob
        scene = bpy.context.scene
        region = None
        preferences = bpy.context.preferences
    panel = bpy.types.VOXLIGHT_PT_volume_channels
    assert panel.poll(Ctx)
    panel.draw(type("P", (), {"layout": _Recorder(calls)})(), Ctx)
    return calls


@test
def the_panel_lists_the_channels_shows_the_active_one_and_says_why_not():
    scene, ob = _scene()
    ob.voxlight.active_channel = 1
    calls = _draw_panel(ob)
    names = [c[1] for c in calls]
    assert "VOXLIGHT_UL_channels" in names and "channel_blend" in names
    for prop in ("window_low", "window_high", "opacity", "ramp", "color"):
        assert prop in names, prop
    assert "VOXLIGHT_MT_channel_dyes" in names
    icons = [c[2].get("icon_value") for c in calls if c[0] == "template_icon"]
    assert len(icons) == 1  # the active channel's histogram picture, its bars in its colour
    pv = vx.panels._previews["%s/channel 1" % ob.name]
    w, h = pv.image_size
    px = np.empty(w * h * 4, np.float32)
    pv.image_pixels_float.foreach_get(px)
    px = px.reshape(h, w, 4)
    assert (w, h) == tuple(vx.channel_ui.CHANNEL_PICTURE)
    assert (px[..., 1] > px[..., 0] + 0.2).sum() > 50  # green bars (channel 1 is green)
    assert not [c for c in calls if c[0] == "set" and c[1] == "alert"]
    # the Transfer Function panel says its ramp waits for the channels to be off
    tf_calls = []
    bpy.types.VOXLIGHT_PT_volume_tf.draw(type("P", (), {"layout": _Recorder(tf_calls)})(),
                                         type("C", (), {"object": ob, "region": None,
                                                        "preferences": bpy.context.preferences}))
    assert "Used when the channels are not drawn" in [c[1] for c in tf_calls if c[0] == "label"]
    # a channel's curve changes what the scene-shadow cache keys on
    key = vx.params.look_key(ob.voxlight)
    ob.voxlight.channels[2].ramp = "BRIGHT"
    assert vx.params.look_key(ob.voxlight) != key
    ob.voxlight.shading = True
    ob.voxlight.shading_model = "scatter"
    texts = " ".join(str(c[1]) for c in _draw_panel(ob) if c[0] == "label")
    assert "Channels not drawn" in texts and "Phong" in texts, texts
    ob.voxlight.use_channels = False
    texts = " ".join(str(c[1]) for c in _draw_panel(ob) if c[0] == "label")
    assert "Channel 0 alone" in texts and "Channels not drawn" not in texts, texts
    # a one-channel volume has no Channels panel
    one = u.import_volume(u.ball_file())
    assert len(one.voxlight.channels) == 0

    class Ctx:
        object = one
    assert not bpy.types.VOXLIGHT_PT_volume_channels.poll(Ctx)



@test
def an_ome_zarrs_names_colours_windows_and_visibility_seed_the_channels():
    """The file's omero metadata (tests/channel_files_write.py writes it)
    reaches the channel list through the library's information: names,
    colours decoded from the file's sRGB, display windows, and a channel the
    file hides imported hidden."""
    sys.path.insert(0, os.path.join(u.ROOT, "tests"))
    from channel_files_write import write_omero_zarr, stack  # noqa: E402
    u.reset_scene()
    vol = stack(3, (5, 6, 7), np.uint16)
    store = write_omero_zarr(os.path.join(u.TMP, "omero.zarr"), vol, ["DAPI", "GFP", "Membrane"],
                             [(0, 0, 255), (0, 255, 0), (255, 128, 0)], [(10, 500), (20, 600), (30, 700)],
                             [True, False, True])
    ob = u.import_volume(str(store))
    chans = ob.voxlight.channels
    assert [c.name for c in chans] == ["DAPI", "GFP", "Membrane"], [c.name for c in chans]
    # sRGB 128/255 decoded to linear (IEC 61966-2-1, written out here)
    half = ((128 / 255 + 0.055) / 1.055) ** 2.4
    assert np.allclose(tuple(chans[2].color), (1.0, half, 0.0), atol=1e-5), tuple(chans[2].color)
    assert np.allclose(tuple(chans[0].color), (0.0, 0.0, 1.0))
    assert [(c.window_low, c.window_high) for c in chans] == [(10, 500), (20, 600), (30, 700)]
    assert [c.visible for c in chans] == [True, False, True]


u.run("test_channels")
