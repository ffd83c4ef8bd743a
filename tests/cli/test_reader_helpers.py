"""TIFF/PNG stacks and OpenVDB are read by voxlight-read-oiio, DICOM by
voxlight-read-dicom (csrc/io/reader_stream.h). When a helper cannot run - its
library missing, the helper itself missing, or crashing - that one format
fails with a message naming what to install, and every other format still
loads. VOXLIGHT_READ_OIIO / VOXLIGHT_READ_DICOM point the library at a
stand-in helper."""
import os
import re
import signal
import subprocess
from pathlib import Path

import numpy as np
import pytest

from helper_reply import notes_helper
from test_cli_dicom4d import write_series
from test_cli_formats import blob, write_nrrd, write_png

ROOT = Path(__file__).resolve().parents[2]
BUILD = ROOT / "build"
CLI = BUILD / "voxlight"
LOADER_MESSAGE = ("{helper}: error while loading shared libraries: {lib}: cannot open shared object file: "
                  "No such file or directory")


def packages():
    """The sonames and Debian packages this build derived (Makefile)."""
    text = (BUILD / "gen" / "reader_packages.h").read_text()
    return dict(re.findall(r'#define VXL_(\w+) "([^"]*)"', text))


def run(*args, env=None):
    e = dict(os.environ)
    e.pop("VOXLIGHT_BACKEND", None)
    e.update(env or {})
    return subprocess.run([str(CLI), *map(str, args)], capture_output=True, text=True, env=e, timeout=300)


@pytest.fixture(scope="module")
def inputs(tmp_path_factory):
    d = tmp_path_factory.mktemp("formats")
    write_nrrd(d / "a.nrrd", blob())
    stack = d / "stack"
    stack.mkdir()
    for k, img in enumerate(blob(dtype=np.uint16).astype(np.uint16)):
        write_png(stack / f"slice_{k + 1:03d}.png", img)
    write_series(d / "dicom", "1.2.840.99.7", "CT", n=6)
    return {"nrrd": d / "a.nrrd", "stack": stack / "slice_001.png", "dicom": d / "dicom"}


def fake_helper(tmp_path, name, script):
    p = tmp_path / name
    p.write_text("#!/bin/sh\n" + script + "\n")
    p.chmod(0o755)
    return str(p)


DIMS = {"nrrd": "4 x 5 x 6", "stack": "4 x 5 x 6", "dicom": "6 x 6 x 6"}


def loads(fmt, inputs, env):
    r = run("info", inputs[fmt], env=env)
    assert r.returncode == 0, r.stderr
    assert re.search(r"^dimensions:\s+%s$" % DIMS[fmt], r.stdout, re.M), r.stdout


def test_all_formats_load_through_the_real_helpers(inputs):
    for fmt in inputs:
        loads(fmt, inputs, {})


@pytest.mark.parametrize("fmt, env_name, helper, lib_key, needs", [
    ("stack", "VOXLIGHT_READ_OIIO", "voxlight-read-oiio", "OIIO", "TIFF/PNG stacks need OpenImageIO"),
    ("dicom", "VOXLIGHT_READ_DICOM", "voxlight-read-dicom", "DCMTK", "DICOM series need dcmtk"),
])
def test_a_missing_library_names_its_package_and_breaks_only_its_format(inputs, tmp_path, fmt, env_name, helper,
                                                                       lib_key, needs):
    pk = packages()
    soname, package = pk[lib_key + "_SONAME"], pk[lib_key + "_PACKAGE"]
    assert package, "dpkg could not tell the package of %s at build time" % soname
    msg = LOADER_MESSAGE.format(helper=helper, lib=soname)
    env = {env_name: fake_helper(tmp_path, helper, "echo '%s' >&2; exit 127" % msg)}
    r = run("info", inputs[fmt], env=env)
    assert r.returncode != 0
    expect = "%s (Debian package %s), and %s is missing: apt-get install %s" % (needs, package, soname, package)
    assert expect in r.stderr, r.stderr
    assert str(inputs[fmt]) in r.stderr
    for other in inputs:
        if other != fmt:
            loads(other, inputs, env)


@pytest.mark.parametrize("fmt, env_name, helper, needs", [
    ("stack", "VOXLIGHT_READ_OIIO", "voxlight-read-oiio", "TIFF/PNG stacks need OpenImageIO"),
    ("dicom", "VOXLIGHT_READ_DICOM", "voxlight-read-dicom", "DICOM series need dcmtk"),
])
def test_a_helper_too_new_for_the_systems_glibc_says_so(inputs, tmp_path, fmt, env_name, helper, needs):
    """On an older Linux (glibc 2.28, where the library itself runs) the
    dynamic loader refuses the Debian-built helper with its own words; the
    user gets one line naming the formats and why, and the rest loads."""
    msg = ("%s: /lib64/libc.so.6: version `GLIBC_2.34' not found (required by %s)" % (helper, helper))
    env = {env_name: fake_helper(tmp_path, helper, "cat >&2 <<'EOF'\n%s\nEOF\nexit 1" % msg)}
    r = run("info", inputs[fmt], env=env)
    assert r.returncode != 0
    assert "%s, and the helper %s was built for a newer Linux than this one (it needs GLIBC_2.34)" % (
        needs, helper) in r.stderr, r.stderr
    assert len([ln for ln in r.stderr.splitlines() if ln.strip()]) == 1, r.stderr
    for other in inputs:
        if other != fmt:
            loads(other, inputs, env)


def test_the_real_loader_message_for_a_missing_library(inputs, tmp_path):
    """The DICOM helper with its NEEDED entry renamed to a file that does not
    exist: the dynamic loader itself refuses to start it."""
    pk = packages()
    soname = pk["DCMTK_SONAME"]
    gone = soname[:-1] + ("X" if soname[-1] != "X" else "Y")
    data = (BUILD / "voxlight-read-dicom").read_bytes()
    assert soname.encode() + b"\0" in data
    broken = tmp_path / "voxlight-read-dicom"
    broken.write_bytes(data.replace(soname.encode() + b"\0", gone.encode() + b"\0"))
    broken.chmod(0o755)
    r = run("info", inputs["dicom"], env={"VOXLIGHT_READ_DICOM": str(broken)})
    assert r.returncode != 0
    assert "DICOM series need dcmtk (Debian package %s), and %s is missing" % (pk["DCMTK_PACKAGE"], gone) in r.stderr


def test_a_missing_helper_breaks_only_its_format(inputs, tmp_path):
    env = {"VOXLIGHT_READ_OIIO": str(tmp_path / "nowhere" / "voxlight-read-oiio")}
    r = run("info", inputs["stack"], env=env)
    assert r.returncode != 0
    assert re.search(r"TIFF/PNG stacks are read by the helper program .*nowhere/voxlight-read-oiio, which is "
                     r"missing \(it belongs next to the library", r.stderr), r.stderr
    loads("nrrd", inputs, env)
    loads("dicom", inputs, env)


def test_a_crashing_helper_is_an_error(inputs, tmp_path):
    env = {"VOXLIGHT_READ_DICOM": fake_helper(tmp_path, "voxlight-read-dicom", "kill -%d $$" % signal.SIGABRT)}
    r = run("info", inputs["dicom"], env=env)
    assert r.returncode != 0
    assert "the DICOM reader crashed (signal 6: SIGABRT)" in r.stderr, r.stderr
    loads("stack", inputs, env)
    loads("nrrd", inputs, env)


def test_info_prints_what_the_reader_decided(inputs, tmp_path):
    """vxl_volume.notes cross the helper's pipe and `info` prints them on a
    notes: line; a volume whose reader decided nothing has none."""
    notes = "PixelSpacing missing: 1 mm assumed; 2 slices interpolated where slices are missing"
    r = run("info", inputs["stack"], env={"VOXLIGHT_READ_OIIO": notes_helper(tmp_path, notes)})
    assert r.returncode == 0, r.stderr
    assert re.search(r"^notes:\s+%s$" % re.escape(notes), r.stdout, re.M), r.stdout
    assert "dimensions:  4 x 3 x 2" in r.stdout
    r = run("info", inputs["nrrd"])
    assert r.returncode == 0 and "notes:" not in r.stdout, r.stdout


def test_a_tiff_whose_strips_claim_gigabytes_is_called_corrupt():
    """A 288-byte TIFF found by fuzzing claims 1,986,356,271 rows per strip in
    a 3-row page: OpenImageIO would allocate 31 GB for one strip before
    reading a byte. The helper refuses it first, and the message says why."""
    bad = ROOT / "tests" / "crashers" / "tiff" / "oiio_rows_per_strip_31gb.tif"
    out = run("info", str(bad))
    assert out.returncode == 1, out.stdout + out.stderr
    assert "corrupt TIFF: 1986356271 rows per strip in a 3-row image" in out.stderr, out.stderr
    assert "crashed" not in out.stderr and "signal" not in out.stderr
