"""core/channel_defaults.py: a multi-channel volume's per-channel defaults
from its information, with and without the metadata fields the library
gives from OME files (channel_names, channel_colors, channel_windows,
channel_active: plugin/core/native_volume.py's info)."""

import types

import numpy as np
import pytest

from voxlight.core import channel_defaults as cd

# The library's default colours, as frame_channels.c lists them (written
# out here, not imported, so a change on either side fails this test).
LIBRARY = [(1, 0, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (0, 1, 1), (1, 1, 0), (1, 0.5, 0), (1, 1, 1)]


def info(n, **extra):
    d = dict(channel_count=n, channel_min=[10.0 * c for c in range(n)],
             channel_max=[100.0 + 10.0 * c for c in range(n)])
    d.update(extra)
    return d


def test_defaults_follow_the_library_by_index():
    out = cd.channel_defaults(info(8))
    assert [d["name"] for d in out] == ["Channel %d" % c for c in range(8)]
    assert [d["color"] for d in out] == [tuple(map(float, c)) for c in LIBRARY]
    assert [d["window"] for d in out] == [(10.0 * c, 100.0 + 10.0 * c) for c in range(8)]
    assert all(d["decided"] == "default of its index" and d["dye"] == "" for d in out)


@pytest.mark.parametrize("n", [0, 1, 9])
def test_no_channels_without_a_multi_channel_volume(n):
    assert cd.channel_defaults(info(n)) == []
    assert cd.channel_defaults({}) == []


def test_names_that_name_a_dye_take_its_colour():
    meta = types.SimpleNamespace(**info(4), channel_names=[b"DAPI", "anti-GFP (488)", "  ", "Alexa 647"])
    out = cd.channel_defaults(meta)
    assert [d["name"] for d in out] == ["DAPI", "anti-GFP (488)", "Channel 2", "Alexa 647"]
    assert [d["dye"] for d in out] == ["DAPI", "GFP", "", "CY5"]
    assert [d["color"] for d in out] == [(0, 0, 1), (0, 1, 0), (0, 0, 1), (1, 0, 1)]
    assert out[0]["decided"] == "dye named" and out[2]["decided"] == "default of its index"


def test_metadata_colours_win_and_are_decoded_from_srgb():
    srgb = (1.0, 0.5, 0.2)
    out = cd.channel_defaults(info(3, channel_names=["DAPI", "x", "y"],
                                   channel_colors=[srgb, (2.0, 0.0, 0.0), None]))
    # IEC 61966-2-1, written out independently of colour_space.py
    ref = [c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4 for c in srgb]
    assert np.allclose(out[0]["color"], ref, atol=1e-6) and out[0]["decided"] == "metadata"
    assert out[1]["color"] == (0.0, 1.0, 0.0)  # out of range: not a colour, index default
    assert out[2]["color"] == (0.0, 0.0, 1.0)


def test_the_files_windows_and_visibility_are_taken_where_given():
    out = cd.channel_defaults(info(3, channel_windows=[(20.0, 60.0), None, (9.0, 3.0)],
                                   channel_active=[True, False, True]))
    assert out[0]["window"] == (20.0, 60.0) and out[0]["range"] == (0.0, 100.0)
    assert out[1]["window"] == (10.0, 110.0)  # none given: the channel's range
    assert out[2]["window"] == (20.0, 120.0)  # not a window: the range, not a guess
    assert [d["visible"] for d in out] == [True, False, True]
    assert all(d["visible"] for d in cd.channel_defaults(info(2)))


def test_an_empty_range_still_gives_a_window():
    out = cd.channel_defaults(info(2, channel_min=[5.0, 0.0], channel_max=[5.0, 1.0]))
    assert out[0]["window"] == (5.0, 6.0)


def test_dye_of_color_and_presets():
    for ident, _ui, rgb, _words in cd.DYES:
        assert cd.dye_of_color(rgb) == ident
    assert cd.dye_of_color((0.3, 0.3, 0.3)) == ""
    assert cd.DYE_COLORS["DAPI"] == (0, 0, 1) and cd.DYE_COLORS["GFP"] == (0, 1, 0)
    assert cd.DYE_COLORS["MCHERRY"] == (1, 0, 0) and cd.DYE_COLORS["CY5"] == (1, 0, 1)
    assert len({d[0] for d in cd.DYES}) == len(cd.DYES)
