"""libvoxlight.so loads inside Blender's process, on machines without our
build dependencies: it may need only the C runtime, of a glibc no newer
than official Blender's baseline (2.28). The readers that need
OpenImageIO or dcmtk live in the helper processes (csrc/io/reader_stream.h);
zlib is opened at run time (csrc/io/zlib_api.c)."""
import gzip
import os
import re
import subprocess
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
BUILD = ROOT / os.environ.get("VOXLIGHT_TEST_BUILD", "build")
LIB = BUILD / "libvoxlight.so"
# Not even the dynamic loader: thread-local storage in a shared object would
# add ld-linux for __tls_get_addr (csrc/core/error.c keeps its per-thread message
# behind a pthread key instead).
ALLOWED = re.compile(r"^(libc|libm|libdl|libpthread)\.so\.\d+$")
BASELINE = (2, 28)  # the glibc official Blender builds run on (docs/platforms.md)
CLI = BUILD / "voxlight"


def needed(path):
    out = subprocess.run(["readelf", "-d", str(path)], capture_output=True, text=True, check=True).stdout
    return re.findall(r"\(NEEDED\)\s+Shared library: \[([^\]]+)\]", out)


def test_library_needs_only_the_c_runtime():
    libs = needed(LIB)
    assert "libc.so.6" in libs  # the parse found the entries at all
    assert [n for n in libs if not ALLOWED.match(n)] == []
    assert not any(n.startswith(("libstdc++", "libgcc_s")) for n in libs)


def test_the_heavy_libraries_are_in_their_own_helpers():
    """One helper per library, so a missing one breaks only its formats."""
    oiio, dicom = needed(ROOT / "build" / "voxlight-read-oiio"), needed(ROOT / "build" / "voxlight-read-dicom")
    assert any(n.startswith("libOpenImageIO") for n in oiio) and not any(n.startswith("libdcm") for n in oiio)
    assert any(n.startswith("libdcmdata") for n in dicom) and not any(n.startswith("libOpenImageIO") for n in dicom)


def glibc_versions(path):
    """Every GLIBC_x.y version the file's dynamic symbols ask for."""
    out = subprocess.run(["objdump", "-T", str(path)], capture_output=True, text=True, check=True).stdout
    return {tuple(int(p) for p in v.split(".")) for v in re.findall(r"GLIBC_(\d+\.\d+(?:\.\d+)?)", out)}


def test_library_cli_and_zarr_helper_need_no_glibc_newer_than_blenders():
    """The OpenImageIO and dcmtk helpers link Debian's libraries and are
    exempt: on an older system they refuse with a message
    (test_reader_helpers.py, test_a_helper_too_new_for_the_systems_glibc_says_so)."""
    zarr = BUILD / "voxlight-read-zarr"
    assert [n for n in needed(zarr) if not ALLOWED.match(n)] == []
    for path in (LIB, CLI, zarr):
        versions = glibc_versions(path)
        assert versions, path  # the parse found the versions at all
        newer = sorted(v for v in versions if v[:2] > BASELINE)
        assert newer == [], "%s needs %s" % (path.name, ["GLIBC_" + ".".join(map(str, v)) for v in newer])


def _gz_volume(path):
    """A 16^3 uint8 NIfTI-1, gzip-compressed (here, with Python's zlib)."""
    raw = bytearray(352)
    raw[0:4] = np.array([348], "<i4").tobytes()
    raw[40:56] = np.array([3, 16, 16, 16, 1, 1, 1, 1], "<i2").tobytes()
    raw[70:74] = np.array([2, 8], "<i2").tobytes()      # datatype uint8, bitpix
    raw[76:108] = np.ones(8, "<f4").tobytes()           # pixdim
    raw[108:116] = np.array([352, 1], "<f4").tobytes()  # vox_offset, scl_slope
    raw[344:348] = b"n+1\0"
    data = (np.arange(16 ** 3) % 251).astype(np.uint8).tobytes()
    path.write_bytes(gzip.compress(bytes(raw) + data))


def _info(path, **env):
    e = dict(os.environ, **env)
    return subprocess.run([str(CLI), "info", str(path)], capture_output=True, text=True, env=e, timeout=120)


def test_gzip_volume_reads_through_the_loaded_zlib(tmp_path):
    vol = tmp_path / "v.nii.gz"
    _gz_volume(vol)
    r = _info(vol)
    assert r.returncode == 0, r.stderr
    assert "16" in r.stdout


def test_missing_zlib_is_a_clear_error(tmp_path):
    vol = tmp_path / "v.nii.gz"
    _gz_volume(vol)
    r = _info(vol, VOXLIGHT_LIBZ=str(tmp_path / "no-such-libz.so.1"))
    assert r.returncode != 0
    assert "zlib" in r.stderr and "cannot be loaded" in r.stderr, r.stderr


# Windows' own DLLs and its universal C runtime: what every Windows 10 and 11
# has, so a helper needs nothing shipped beside it (zlib1.dll is opened at
# run time, never imported).
WINDOWS_SYSTEM_DLL = re.compile(r"^(kernel32|shell32|user32|gdi32|advapi32|ntdll|ws2_32|bcrypt|ucrtbase|msvcrt)\.dll$"
                                r"|^api-ms-win-[a-z0-9-]+\.dll$", re.I)


def pe_imports(path):
    out = subprocess.run(["objdump", "-p", str(path)], capture_output=True, text=True, check=True).stdout
    return re.findall(r"DLL Name: (\S+)", out)


def test_windows_helpers_import_only_windows_dlls():
    """voxlight-read-dicom.exe is C++: zig's libc++ (and its unwinder) must
    be linked in, never a libc++.dll, libstdc++-6.dll or libgcc_s a Windows
    machine lacks; the Zarr helper likewise."""
    for name in ("voxlight-read-dicom.exe", "voxlight-read-zarr.exe"):
        dlls = pe_imports(BUILD / "windows-x64" / name)
        assert "KERNEL32.dll" in dlls, (name, dlls)  # the parse found the imports at all
        assert [d for d in dlls if not WINDOWS_SYSTEM_DLL.match(d)] == [], (name, dlls)
