"""Multi-channel volumes in the CLI (docs/channels.md), on a NIfTI whose
dim[5] holds two uint16 channels (header written here): `info` lists the
channels and the reader's note; `--channels 0,1` draws both in one pass and
its image is the sum of `--channels 0` and `--channels 1` (numpy, within the
8-bit PNG's rounding); hiding a channel (leaving it out) removes exactly its
blob; `--channel-window` changes only its channel's pixels; `--channel N`
renders channel N alone as a one-channel file of it; bricked, sparse and
compressed storage draw the channels as dense storage does; bad values are
clean errors. Then the files the helper-process readers and MetaImage read as
channels (tests/channel_files_write.py): `info` names each channel with its
colour, window and visibility from OME metadata, and every format of the
same voxels renders the same image as the NIfTI of them."""
import struct
import sys
from pathlib import Path

import numpy as np
import pytest

from test_cli import assert_clean_error, png_rgba, run, write_nifti

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from channel_files_write import (COLORS, NAMES, stack, write_mha, write_ome_tiff, write_omero_zarr,  # noqa: E402
                                 write_sample_tiff, write_tiff)

N = 20
VIEW = ["--size", "%dx%d" % (N, N), "--ortho", "--no-jitter", "--no-shading", "--view", "z"]


def ball(cx, cy, cz, r, peak):
    z, y, x = np.indices((N, N, N)).astype(float)
    d = np.sqrt((x - cx) ** 2 + (y - cy) ** 2 + (z - cz) ** 2)
    return np.where(d < r, peak * (1 - 0.5 * d / r), 0).astype(np.uint16)


def write_channels_nifti(path, channels):
    """NIfTI-1, dim = (5, N, N, N, 1, C): C uint16 (z, y, x) channels, one after the other."""
    hdr = bytearray(348)
    struct.pack_into("<i", hdr, 0, 348)
    struct.pack_into("<8h", hdr, 40, 5, N, N, N, 1, len(channels), 1, 1)
    struct.pack_into("<hh", hdr, 70, 512, 16)
    struct.pack_into("<8f", hdr, 76, 1, 1, 1, 1, 1, 1, 1, 1)
    struct.pack_into("<f", hdr, 108, 352.0)
    hdr[344:348] = b"n+1\0"
    path.write_bytes(bytes(hdr) + b"\0" * 4 + b"".join(c.astype("<u2").tobytes() for c in channels))


@pytest.fixture
def disjoint(tmp_path):
    path = tmp_path / "two.nii"
    write_channels_nifti(path, [ball(6, 10, 10, 4, 40000), ball(14, 10, 10, 4, 30000)])
    return path


@pytest.fixture
def overlapping(tmp_path):
    path = tmp_path / "over.nii"
    write_channels_nifti(path, [ball(8, 10, 10, 5, 40000), ball(12, 10, 10, 5, 30000)])
    return path


def premultiplied(path, *args):
    """The render as premultiplied floats in [0, 1] (the PNG holds straight alpha)."""
    out = path.parent / ("out_%d.png" % (abs(hash(args)) % 100000))
    res = run("render", path, "-o", out, *VIEW, *args)
    assert res.returncode == 0, res.stderr
    rgba = png_rgba(out).astype(float) / 255.0
    rgba[..., :3] *= rgba[..., 3:4]
    return rgba


def test_info_lists_the_channels(disjoint):
    res = run("info", disjoint)
    assert res.returncode == 0, res.stderr
    assert "channels:    2 (the scalar is channel 0" in res.stdout
    assert "channel 0: 0 .. 40000" in res.stdout and "channel 1: 0 .. 30000" in res.stdout
    assert "NIfTI dim[5]: 2 channels (channel 0 is the scalar)" in res.stdout
    res = run("info", disjoint, "--channel-axis", "off")
    assert "channels:" not in res.stdout and "frames:      2" in res.stdout


def test_additive_composite_is_the_sum_of_the_channels(overlapping):
    both = premultiplied(overlapping, "--channels", "0,1")
    alone = [premultiplied(overlapping, "--channels", str(c)) for c in (0, 1)]
    total = alone[0] + alone[1]
    assert total[..., 3].max() < 1.0  # nothing clamped
    assert (alone[0][..., 3] > 0).sum() > 10 and (alone[1][..., 3] > 0).sum() > 10
    assert ((alone[0][..., 3] > 0) & (alone[1][..., 3] > 0)).sum() > 5  # they overlap
    assert np.abs(both - total).max() <= 3.0 / 255.0
    # the default colours: channel 0 red, channel 1 green
    assert alone[0][..., 1:3].max() == 0 and alone[1][..., [0, 2]].max() == 0
    assert np.array_equal(premultiplied(overlapping, "--channels", "all"), both)


def test_hiding_a_channel_removes_exactly_its_blob(disjoint):
    both = premultiplied(disjoint, "--channels", "0,1")
    only0 = premultiplied(disjoint, "--channels", "0")
    only1 = premultiplied(disjoint, "--channels", "1")
    empty1 = only1[..., 3] == 0
    assert np.array_equal(both[empty1], only0[empty1])
    assert (only0[~empty1][..., 3] == 0).all() and (both[~empty1][..., 3] > 0).all()


def test_a_channel_window_changes_only_that_channel(disjoint):
    before = premultiplied(disjoint, "--channels", "0,1")
    after = premultiplied(disjoint, "--channels", "0,1", "--channel-window", "1:0:15000",
                          "--channel-color", "1:0,0.5,1")
    only1 = premultiplied(disjoint, "--channels", "1", "--channel-window", "1:0:15000")
    empty1 = only1[..., 3] == 0
    assert np.array_equal(before[empty1], after[empty1])
    assert (after[~empty1][..., 3] > before[~empty1][..., 3]).sum() > 10
    assert after[~empty1][..., 2].max() > 0  # the new colour's blue


def test_channel_n_renders_that_channel_alone(disjoint, tmp_path):
    one = tmp_path / "one.nii"
    write_nifti(one, ball(14, 10, 10, 4, 30000).astype(np.int16))
    a = premultiplied(disjoint, "--channel", "1", "--preset", "gray")
    b = premultiplied(one, "--preset", "gray")
    assert np.array_equal(a, b) and a[..., 3].max() > 0


def test_max_blend_renders(overlapping):
    both = premultiplied(overlapping, "--channels", "0,1", "--channel-blend", "max")
    assert both[..., 3].max() > 0


@pytest.mark.parametrize("storage", ["bricked", "sparse", "compressed"])
def test_paged_storage_draws_the_channels_as_dense(overlapping, storage):
    """The channels page as the scalar does: the same image as dense storage
    (the library's images differ by under 1e-5, the PNG's 8 bits by at most
    one code where that straddles a rounding)."""
    dense = premultiplied(overlapping, "--channels", "0,1", "--storage", "dense")
    paged = premultiplied(overlapping, "--channels", "0,1", "--storage", storage, "--page-brick", "8")
    assert dense[..., 3].max() > 0
    assert np.abs(paged - dense).max() <= 1.0 / 255 + 1e-9


@pytest.mark.parametrize("args,words", [
    (["--channels", "0,5"], ["channels 0..1"]),
    (["--channels", "0,x"], ["--channels", "all or I,J"]),
    (["--channels", "0", "--channel-color", "0:2,0,0"], ["--channel-color", "0..1"]),
    (["--channels", "0", "--channel-window", "0:5:1"], ["--channel-window", "LO < HI"]),
    (["--channel-color", "0:1,0,0"], ["need --channels"]),
    (["--channels", "0", "--channel-window", "1:0:5"], ["does not draw"]),
    (["--channels", "0", "--channel-blend", "over"], ["--channel-blend", "add or max"]),
    (["--channel", "2"], ["scalar channel 2", "0..1"]),
    (["--channels", "0,1", "--mode", "mip"], ["DVR"]),
])
def test_bad_channel_options_are_clean_errors(disjoint, tmp_path, args, words):
    assert_clean_error(run("render", disjoint, "-o", tmp_path / "bad.png", *VIEW, *args), *words)


def test_channels_of_a_volume_without_channels(tmp_path):
    grey = tmp_path / "grey.nii"
    write_nifti(grey, np.zeros((4, 4, 4), np.uint8))
    assert_clean_error(run("render", grey, "-o", tmp_path / "g.png", "--channels", "all"), "no channels")
    assert_clean_error(run("render", grey, "-o", tmp_path / "g.png", "--channel", "1"), "no channels")


@pytest.fixture
def formats(tmp_path):
    """Two uint16 channels of one N^3 stack in every format that reads
    channels (MetaImage's 3 and 4 are colour unless asked), and the NIfTI
    of them; spacing 1 mm where the format has one."""
    vol = stack(2, (N, N, N), np.uint16, seed=11) * 100
    files = {"nifti": tmp_path / "ref.nii", "tiff": tmp_path / "samples.tif", "ome": tmp_path / "cells.ome.tif",
             "zarr": tmp_path / "cells.zarr", "mha": tmp_path / "cells.mha"}
    write_channels_nifti(files["nifti"], list(vol))
    write_sample_tiff(files["tiff"], vol)
    write_ome_tiff(files["ome"], vol, NAMES, COLORS, "XYCZT")
    write_omero_zarr(files["zarr"], vol, NAMES, COLORS, [(100, 5000), (0, 9000)], [True, False])
    write_mha(files["mha"], vol)
    return files


def channel_lines(out):
    return [line.strip() for line in out.splitlines() if line.startswith("  channel ")]


def test_info_names_the_channels_of_every_format(formats):
    lines = {}
    for name, path in formats.items():
        res = run("info", path)
        assert res.returncode == 0, res.stderr
        assert "channels:    2 (the scalar is channel 0" in res.stdout, name
        lines[name] = channel_lines(res.stdout)
    assert lines["zarr"][0].endswith('"DAPI"  colour #0000FF (sRGB)  window 100 .. 5000')
    assert lines["zarr"][1].endswith('"GFP"  colour #00FF00 (sRGB)  window 0 .. 9000  hidden in the file')
    assert lines["ome"][1].endswith('"GFP"  colour #00FF00 (sRGB)')
    # the files without metadata say only the ranges, the same as the NIfTI's
    assert lines["tiff"] == lines["mha"] == lines["nifti"]
    assert [line.split('"')[0].strip() for line in lines["ome"]] == lines["nifti"]
    notes = {"tiff": "TIFF samples: 2 channels", "ome": "OME-TIFF SizeC: 2 channels",
             "zarr": "OME-Zarr c axis: 2 channels", "mha": "MetaImage ElementNumberOfChannels: 2 channels"}
    for name, note in notes.items():
        assert note in run("info", formats[name]).stdout
    # one channel, as before: "#c=N", and channels off
    res = run("info", str(formats["zarr"]) + "#c=1")
    assert res.returncode == 0 and "channels:" not in res.stdout, res.stderr
    res = run("info", formats["tiff"], "--channel-axis", "off")
    assert res.returncode == 0 and "channels:" not in res.stdout and "components:  1" in res.stdout, res.stderr


def test_every_format_renders_the_niftis_image(formats):
    """The same voxels on the same grid: the channels drawn in one march
    give the NIfTI's image exactly (MetaImage's LPS axes mirror x and y, so
    its view is compared against the NIfTI's turned half a turn)."""
    ref = premultiplied(formats["nifti"], "--channels", "all")
    assert ref[..., 3].max() > 0
    for name in ("tiff", "ome", "zarr"):
        assert np.array_equal(premultiplied(formats[name], "--channels", "all"), ref), name
    assert np.array_equal(premultiplied(formats["mha"], "--channels", "all"), ref[::-1, ::-1])


def test_bad_channel_files_are_clean_errors(formats, tmp_path):
    assert_clean_error(run("info", formats["mha"], "--channel-axis", "off"), "2 channels per voxel and channels off")
    nine = tmp_path / "nine.mha"
    write_mha(nine, stack(9, (4, 4, 4), np.uint16))
    assert_clean_error(run("info", nine), "9 channels per voxel is not supported", "2 to 8 channels")


def test_an_ome_tiff_time_point_is_the_frame(tmp_path):
    """SizeT 2, XYZCT: page z + 3 (c + 2 t) holds 100 t + 10 c + z; --frame t reads t's planes."""
    xml = ('<OME><Image><Pixels DimensionOrder="XYZCT" SizeX="5" SizeY="4" SizeZ="3" SizeC="2" SizeT="2">'
           '<Channel Name="a"/><Channel Name="b"/></Pixels></Image></OME>')
    pages = [np.full((4, 5), 100 * t + 10 * c + z, np.uint16) for t in range(2) for c in range(2) for z in range(3)]
    path = tmp_path / "t.ome.tif"
    write_tiff(path, pages, description=xml)
    for t in (0, 1):
        res = run("info", path, "--frame", str(t))
        assert res.returncode == 0, res.stderr
        assert f"frames:      2 (this is frame {t}" in res.stdout
        assert channel_lines(res.stdout) == [f'channel 0: {100 * t} .. {100 * t + 2}  "a"',
                                             f'channel 1: {100 * t + 10} .. {100 * t + 12}  "b"']
    assert_clean_error(run("info", path, "--frame", "2"), "frame 2 asked for, the OME-TIFF has 2 time points")
