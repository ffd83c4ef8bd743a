"""OpenVDB files are read in a helper process (csrc/vdb_spawn.c,
csrc/vdb_helper_main.c): a file on which libopenvdb aborts gives a clean
error and this process lives on; the parent trusts nothing the helper
sends (fake helpers below), leaves no zombie and no descriptor behind, and
never falls back to reading in-process."""

import os
import stat
import struct
import sys
import time

import numpy as np
import pytest

from voxlight import native
from vdb_write import write_vdb

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
ABORTS = os.path.join(ROOT, "tests", "fuzz", "upstream", "openvdb_delayed_load_mask_assert.vdb")
HEADER = "=8sII3II3d16dQ"  # vxl_vdb_header in csrc/vdb_stream.h


@pytest.fixture(scope="module")
def lib():
    return native.load_library()


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
    """An executable Python script standing in for voxlight-vdb-read."""
    p = tmp_path / "fake-helper"
    p.write_text("#!%s\nimport struct, sys, time\nout = sys.stdout.buffer\nHEADER = %r\n%s\n"
                 % (sys.executable, HEADER, body))
    p.chmod(0o755)
    return str(p)


def _header(status=0, dims=(4, 3, 2), nbytes=None, msg_len=0, magic=b"VXLVDB1\0"):
    n = dims[0] * dims[1] * dims[2] * 4 if nbytes is None else nbytes
    return struct.pack(HEADER, magic, status, 7, *dims, msg_len, 1.0, 1.0, 1.0,
                       *np.eye(4).T.ravel(), n)


@pytest.mark.parametrize("body, needle", [
    # a header that claims 2^30 voxels: refused by the budget before allocating
    ("out.write(%r)" % _header(dims=(1024, 1024, 1024)), r"over the memory budget of 1\.0 MiB"),
    ("out.write(%r + bytes(10))" % _header(), r"output was cut short \(202 of 288 bytes\)"),
    ("out.write(%r)" % _header(nbytes=5), r"announced 5 bytes for 4x3x2"),
    ("out.write(b'hello world' * 30)", r"sent no valid header"),
    ("out.write(%r + bytes(96) + b'x')" % _header(), r"more than it announced"),
    ("sys.stderr.write('no such grid\\n'); sys.exit(4)", r"failed \(exit 4\): no such grid"),
    ("out.write(%r + b'it is broken'); sys.exit(1)" % _header(status=3, msg_len=12), r"^it is broken$"),
    ("import os, signal; os.kill(os.getpid(), signal.SIGSEGV)", r"crashed \(signal 11: SIGSEGV\)"),
])
def test_parent_trusts_nothing_the_helper_sends(lib, small_vdb, tmp_path, monkeypatch, body, needle):
    monkeypatch.setenv("VOXLIGHT_VDB_HELPER", _fake_helper(tmp_path, body))
    fds = _fds()
    with pytest.raises(native.VoxlightError, match=needle):
        native.Volume.load(small_vdb, memory_budget=1 << 20, lib=lib)
    assert _fds() == fds and _children() == []


def test_hung_helper_is_killed(lib, small_vdb, tmp_path, monkeypatch):
    monkeypatch.setenv("VOXLIGHT_VDB_HELPER", _fake_helper(tmp_path, "time.sleep(60)"))
    monkeypatch.setenv("VOXLIGHT_VDB_TIMEOUT", "1")
    t0 = time.monotonic()
    with pytest.raises(native.VoxlightError, match=r"took longer than 1 s and was stopped"):
        native.Volume.load(small_vdb, lib=lib)
    assert time.monotonic() - t0 < 30
    assert _children() == []


def test_missing_or_unrunnable_helper_is_an_error_not_a_fallback(lib, small_vdb, tmp_path, monkeypatch):
    monkeypatch.setenv("VOXLIGHT_VDB_HELPER", str(tmp_path / "nowhere"))
    with pytest.raises(native.VoxlightError, match=r"helper .*nowhere is missing"):
        native.Volume.load(small_vdb, lib=lib)
    plain = tmp_path / "not-executable"
    plain.write_bytes(b"")
    plain.chmod(stat.S_IRUSR | stat.S_IWUSR)
    assert not os.access(plain, os.X_OK)  # root too: no execute bit at all
    monkeypatch.setenv("VOXLIGHT_VDB_HELPER", str(plain))
    with pytest.raises(native.VoxlightError, match=r"is not executable"):
        native.Volume.load(small_vdb, lib=lib)


def test_add_on_restores_the_helpers_execute_bit(tmp_path):
    """Blender's zip install (zipfile.extractall) drops file modes;
    load_library gives the helper its execute bit back."""
    import zipfile
    src = tmp_path / "src"
    src.mkdir()
    (src / native.VDB_HELPER_NAME).write_bytes(b"#!/bin/sh\nexit 0\n")
    (src / native.VDB_HELPER_NAME).chmod(0o755)
    with zipfile.ZipFile(tmp_path / "a.zip", "w") as z:
        z.write(src / native.VDB_HELPER_NAME, native.VDB_HELPER_NAME)
    with zipfile.ZipFile(tmp_path / "a.zip") as z:
        z.extractall(tmp_path / "installed")
    helper = tmp_path / "installed" / native.VDB_HELPER_NAME
    assert not os.access(helper, os.X_OK)  # what Blender's install leaves
    assert native.restore_execute_bit(str(helper))
    mode = stat.S_IMODE(helper.stat().st_mode)
    assert mode & 0o111 == (mode & 0o444) >> 2 and mode & stat.S_IXUSR
    assert not native.restore_execute_bit(str(tmp_path / "missing"))
