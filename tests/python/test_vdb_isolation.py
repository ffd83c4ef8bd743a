"""OpenVDB files (like TIFF/PNG stacks and DICOM) are read in a helper
process (csrc/io/reader_spawn.c, csrc/io/helper_main.c, voxlight-read-oiio): a
file on which libopenvdb aborts gives a clean error and this process lives
on; the parent trusts nothing the helper sends (fake helpers below), leaves
no zombie and no descriptor behind, and never falls back to reading
in-process. tests/cli/test_reader_helpers.py covers missing helpers and
libraries per format."""

import ctypes
import os
import stat
import struct
import sys
import time

import numpy as np
import pytest

from voxlight.core import native, native_abi
from vdb_write import write_vdb

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
ABORTS = os.path.join(ROOT, "tests", "fuzz", "upstream", "openvdb_delayed_load_mask_assert.vdb")
# vxl_reader_header in csrc/io/reader_stream.h: magic; status, msg_len, kind,
# count, record_size, dims[3], src_dtype, texture_bits, nifti_version,
# affine_source, frame_count, frame, components, opacity_source; tex_lo, tex_hi,
# value_min, value_max; spacing[3]; affine[16]; nan_count, inf_count,
# storage_bytes, nbytes, colour_bytes; notes[512]; channel_count,
# scalar_channel; ch_tex_lo[8], ch_tex_hi[8], ch_min[8], ch_max[8];
# channel_bytes; ch_meta[8] (vxl_channel_meta, volume.h: 96 bytes each)
HEADER = "=8s16I4d3d16d5Q512s2I32dQ768s"
HEADER_SIZE = 1848
# vxl_channel_meta: window[2]; color_srgb[3]; has_color, has_window, hidden, reserved; name[64]
CHANNEL_META = "=2d3f4B64s"
HELPER_ENV = "VOXLIGHT_READ_OIIO"
TIMEOUT_ENV = "VOXLIGHT_READER_TIMEOUT"
VXL_DTYPE_F32 = 7


@pytest.fixture(scope="module")
def small_vdb(tmp_path_factory):
    path = tmp_path_factory.mktemp("iso") / "small.vdb"
    return write_vdb(path, [{"name": "density", "array": np.full((4, 3, 2), 2.0, np.float32)}])


def _fds():
    return sorted(os.listdir("/proc/self/fd"))


def _children():
    """Pids whose parent is this process (zombies included)."""
    me, out = str(os.getpid()), []
    for p in os.listdir("/proc"):
        if p.isdigit():
            try:
                with open("/proc/%s/stat" % p) as f:
                    fields = f.read().rsplit(")", 1)[1].split()
            except OSError:
                continue
            if fields[1] == me:
                out.append(p)
    return out


def test_openvdb_abort_is_a_clean_error(lib):
    fds = _fds()
    with pytest.raises(native.VoxlightError, match=r"openvdb_delayed_load_mask_assert\.vdb.*the OpenVDB reader "
                       r"crashed \(signal 6: SIGABRT\).*corrupt or unsupported.*mMask"):
        native.Volume.load(ABORTS, lib=lib)
    assert _fds() == fds
    assert _children() == []


def test_valid_file_leaves_no_child_or_descriptor(lib, small_vdb):
    fds = _fds()
    for _ in range(3):
        with native.Volume.load(small_vdb, lib=lib) as v:
            assert v.info["dims"] == (4, 3, 2)
    assert _fds() == fds
    assert _children() == []


def _fake_helper(tmp_path, body):
    """An executable Python script standing in for voxlight-read-oiio."""
    p = tmp_path / "fake-helper"
    p.write_text("#!%s\nimport struct, sys, time\nout = sys.stdout.buffer\nHEADER = %r\n%s\n"
                 % (sys.executable, HEADER, body))
    p.chmod(0o755)
    return str(p)


def _header(status=0, dims=(4, 3, 2), nbytes=None, msg_len=0, magic=b"VXLRD04\0", kind=1, affine=None,
            notes=b"", components=1, opacity_source=0, colour_bytes=None, channels=0, scalar_channel=0,
            channel_bytes=None, meta=b""):
    n = dims[0] * dims[1] * dims[2] * 4 if nbytes is None else nbytes
    c = (dims[0] * dims[1] * dims[2] * 3 if components > 1 else 0) if colour_bytes is None else colour_bytes
    cb = dims[0] * dims[1] * dims[2] * 2 * channels if channel_bytes is None else channel_bytes
    a = np.eye(4).T.ravel() if affine is None else affine
    return struct.pack(HEADER, magic, status, msg_len, kind, 0, 0, *dims, VXL_DTYPE_F32, 32, 0, 2, 1, 0,
                       components, opacity_source, 0.0, 1.0, 0.0, 1.0, 1.0, 1.0, 1.0, *a, 0, 0, n, n, c, notes,
                       channels, scalar_channel, *([0.0] * 32), cb, meta)


assert struct.calcsize(HEADER) == HEADER_SIZE


@pytest.mark.parametrize("body, needle", [
    # a header that claims 2^30 voxels: refused by the budget before allocating
    ("out.write(%r)" % _header(dims=(1024, 1024, 1024)), r"over the memory budget of 1\.0 MiB"),
    ("out.write(%r + bytes(10))" % _header(), r"output of the OpenVDB reader was cut short \(1858 of 1944 bytes\)"),
    # an older helper's header (magic 01, no notes; 02, no colour; 03, no channels) is refused, not misread
    ("out.write(%r + bytes(96))" % _header(magic=b"VXLRD01\0"), r"sent no valid header"),
    ("out.write(%r + bytes(96))" % _header(magic=b"VXLRD02\0"), r"sent no valid header"),
    ("out.write(%r + bytes(96))" % _header(magic=b"VXLRD03\0"), r"sent no valid header"),
    # channels: 2 bytes a channel a voxel after the texels (and colour),
    # charged to the budget with the texels (8 channels of 64x64x50 pass
    # the texels' 1 MiB alone, not with them), and all of it sent
    ("out.write(%r)" % _header(dims=(64, 64, 50), nbytes=64 * 64 * 50 * 4, channels=8),
     r"over the memory budget of 1\.0 MiB"),
    ("out.write(%r + bytes(96) + bytes(96))" % _header(channels=9, channel_bytes=96),
     r"inconsistent multi-channel header \(9 channels"),
    ("out.write(%r + bytes(96) + bytes(96))" % _header(channels=2, scalar_channel=2),
     r"inconsistent multi-channel header \(2 channels, scalar 2"),
    ("out.write(%r + bytes(96) + bytes(94))" % _header(channels=2, channel_bytes=94),
     r"inconsistent multi-channel header \(2 channels, scalar 0, 94 channel bytes\)"),
    ("out.write(%r + bytes(96) + bytes(96))" % _header(channels=2, meta=struct.pack(CHANNEL_META, 0, 0, 2.0, 0, 0,
                                                                                      1, 0, 0, 0, b"x")),
     r"inconsistent multi-channel header"),
    ("out.write(%r + bytes(96) + bytes(95))" % _header(channels=2), r"cut short \(2039 of 2040 bytes\)"),
    # colour: 3 bytes a voxel after the texels, the opacity source asked for,
    # charged to the budget with the texels, and all of it sent
    ("out.write(%r + bytes(96) + bytes(72))" % _header(components=2), r"sent 2 components"),
    ("out.write(%r + bytes(96))" % _header(colour_bytes=72), r"sent 1 components .* and 72 colour bytes"),
    ("out.write(%r + bytes(96) + bytes(72))" % _header(components=3, opacity_source=2),
     r"opacity source 2 \(asked for 0\)"),
    ("out.write(%r + bytes(96) + bytes(70))" % _header(components=3, colour_bytes=70),
     r"announced 70 colour bytes for 4x3x2 voxels"),
    ("out.write(%r + bytes(96) + bytes(71))" % _header(components=3),
     r"cut short \(2015 of 2016 bytes\)"),
    ("out.write(%r + bytes(96) + bytes(73))" % _header(components=3), r"more than it announced"),
    ("out.write(%r)" % _header(dims=(64, 64, 50), components=3), r"over the memory budget of 1\.0 MiB"),
    # notes: terminated inside their 512 bytes, one line of text
    ("out.write(%r + bytes(96))" % _header(notes=b"n" * 512), r"sent notes that are not one terminated line"),
    ("out.write(%r + bytes(96))" % _header(notes=b"two\nlines"), r"sent notes that are not one terminated line"),
    ("out.write(%r)" % _header(nbytes=5), r"announced 5 bytes for 4x3x2 voxels of 32 bits"),
    ("out.write(b'hello world' * 200)", r"sent no valid header"),
    ("out.write(%r + bytes(96) + b'x')" % _header(), r"more than it announced"),
    ("out.write(%r + bytes(96))" % _header(kind=2), r"reply of kind 2, not 1"),
    ("out.write(%r + bytes(96))" % _header(affine=[float("nan")] * 16), r"transform is not finite"),
    # float texels must lie in [0, 1]: 2.0 is refused, naming the voxel
    ("out.write(%r + bytes(8) + struct.pack('=f', 2.0) + bytes(84))" % _header(), r"texel outside \[0, 1\] at voxel 2"),
    ("sys.stderr.write('no such grid\\n'); sys.exit(4)", r"failed \(exit 4\): no such grid"),
    ("out.write(%r + b'it is broken'); sys.exit(1)" % _header(status=3, msg_len=12), r"^it is broken$"),
    ("import os, signal; os.kill(os.getpid(), signal.SIGSEGV)", r"crashed \(signal 11: SIGSEGV\)"),
])
def test_parent_trusts_nothing_the_helper_sends(lib, small_vdb, tmp_path, monkeypatch, body, needle):
    monkeypatch.setenv(HELPER_ENV, _fake_helper(tmp_path, body))
    fds = _fds()
    with pytest.raises(native.VoxlightError, match=needle):
        native.Volume.load(small_vdb, memory_budget=1 << 20, lib=lib)
    assert _fds() == fds and _children() == []


def test_helper_notes_reach_the_volume_info(lib, small_vdb, tmp_path, monkeypatch):
    """What a reader decided (vxl_volume.notes) crosses the pipe whole,
    UTF-8 included, into vxl_volume_info.notes."""
    notes = "PixelSpacing missing: 1 mm assumed; 2 slices interpolated where slices are missing (\u00b5m)"
    monkeypatch.setenv(HELPER_ENV, _fake_helper(tmp_path, "out.write(%r + bytes(96))"
                                                % _header(notes=notes.encode("utf-8"))))
    with native.Volume.load(small_vdb, lib=lib) as v:
        assert v.info["notes"] == notes
    monkeypatch.setenv(HELPER_ENV, _fake_helper(tmp_path, "out.write(%r + bytes(96))" % _header()))
    with native.Volume.load(small_vdb, lib=lib) as v:
        assert v.info["notes"] == ""
    assert _children() == []


def test_helper_colour_reaches_the_volume(lib, small_vdb, tmp_path, monkeypatch):
    """A colour volume's RGB8 follows its texels (3 bytes a voxel), and the
    opacity source the caller asked for is on the helper's command line."""
    body = ("assert sys.argv[10:] == ['0', '0', '0', '0'], sys.argv\n"
            "out.write(%r + bytes(96) + bytes(range(72)))" % _header(components=4))
    monkeypatch.setenv(HELPER_ENV, _fake_helper(tmp_path, body))
    with native.Volume.load(small_vdb, lib=lib) as v:
        info = native_abi._sized(native_abi.VolumeInfo)
        lib.check(lib.cdll.vxl_volume_get_info(v._handle, ctypes.byref(info)))
        assert (info.components, info.opacity_source, info.color_bytes) == (4, 0, 72)
    assert _children() == []


def test_helper_channels_reach_the_volume(lib, small_vdb, tmp_path, monkeypatch):
    """A multi-channel volume's packed channels follow its texels, with
    each channel's name, sRGB colour, window and visibility; the channels
    mode and scalar channel asked for are on the helper's command line."""
    meta = (struct.pack(CHANNEL_META, 10.0, 500.0, 0.0, 0.0, 1.0, 1, 1, 0, 0, "DAPI \u00b5".encode()) +
            struct.pack(CHANNEL_META, 0.0, 0.0, 1.0, 0.5, 0.0, 1, 0, 1, 0, b"GFP") + bytes(96 * 6))
    body = ("assert sys.argv[12:] == ['1', '1'], sys.argv\n"
            "out.write(%r + bytes(96) + bytes(range(96)))" % _header(channels=2, scalar_channel=1, meta=meta))
    monkeypatch.setenv(HELPER_ENV, _fake_helper(tmp_path, body))
    opt = native_abi._sized(native_abi.LoadOptions)
    opt.channels, opt.scalar_channel = 1, 1  # VXL_CHANNELS_ON
    h = ctypes.c_void_p()
    lib.check(lib.cdll.vxl_volume_load(os.fsencode(small_vdb), ctypes.byref(opt), ctypes.byref(h)))
    with native.Volume(lib, h) as v:
        info = native_abi._sized(native_abi.VolumeInfo)
        lib.check(lib.cdll.vxl_volume_get_info(v._handle, ctypes.byref(info)))
        assert (info.channel_count, info.scalar_channel, info.channel_bytes) == (2, 1, 96)
        assert info.channel_names[0].value.decode() == "DAPI \u00b5" and info.channel_names[1].value == b"GFP"
        assert list(info.channel_colors[0]) == [0.0, 0.0, 1.0] and list(info.channel_colors[1]) == [1.0, 0.5, 0.0]
        assert list(info.channel_color_known)[:3] == [1, 1, 0]
        assert (info.channel_window_known[0], info.channel_window_low[0], info.channel_window_high[0]) == (1, 10, 500)
        assert info.channel_window_known[1] == 0
        assert list(info.channel_active)[:3] == [1, 0, 0]  # the third is no channel
    assert _children() == []


def test_hung_helper_is_killed(lib, small_vdb, tmp_path, monkeypatch):
    monkeypatch.setenv(HELPER_ENV, _fake_helper(tmp_path, "time.sleep(60)"))
    monkeypatch.setenv(TIMEOUT_ENV, "1")
    t0 = time.monotonic()
    with pytest.raises(native.VoxlightError, match=r"took longer than 1 s and was stopped"):
        native.Volume.load(small_vdb, lib=lib)
    assert time.monotonic() - t0 < 30
    assert _children() == []


def test_missing_or_unrunnable_helper_is_an_error_not_a_fallback(lib, small_vdb, tmp_path, monkeypatch):
    monkeypatch.setenv(HELPER_ENV, str(tmp_path / "nowhere"))
    with pytest.raises(native.VoxlightError, match=r"OpenVDB files are read by the helper program .*nowhere, which is missing"):
        native.Volume.load(small_vdb, lib=lib)
    plain = tmp_path / "not-executable"
    plain.write_bytes(b"")
    plain.chmod(stat.S_IRUSR | stat.S_IWUSR)
    assert not os.access(plain, os.X_OK)  # root too: no execute bit at all
    monkeypatch.setenv(HELPER_ENV, str(plain))
    with pytest.raises(native.VoxlightError, match=r"is not executable"):
        native.Volume.load(small_vdb, lib=lib)


def test_add_on_restores_the_helpers_execute_bit(tmp_path):
    """Blender's zip install (zipfile.extractall) drops file modes;
    load_library gives the helper its execute bit back."""
    import zipfile
    src = tmp_path / "src"
    src.mkdir()
    name = "voxlight-read-oiio"
    (src / name).write_bytes(b"#!/bin/sh\nexit 0\n")
    (src / name).chmod(0o755)
    with zipfile.ZipFile(tmp_path / "a.zip", "w") as z:
        z.write(src / name, name)
    with zipfile.ZipFile(tmp_path / "a.zip") as z:
        z.extractall(tmp_path / "installed")
    helper = tmp_path / "installed" / name
    assert not os.access(helper, os.X_OK)  # what Blender's install leaves
    assert native.restore_execute_bit(str(helper))
    mode = stat.S_IMODE(helper.stat().st_mode)
    assert mode & 0o111 == (mode & 0o444) >> 2 and mode & stat.S_IXUSR
    assert not native.restore_execute_bit(str(tmp_path / "missing"))
