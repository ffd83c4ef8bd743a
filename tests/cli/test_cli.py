"""The `voxlight` command-line tool as a user runs it: real files in, PNG/EXR
out, and one clear error line (never a crash) for bad input."""
import ctypes
import gzip
import os
import re
import struct
import subprocess
import zlib
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
CLI = ROOT / "build" / "voxlight"
BRAIN = Path("/usr/share/mricron/templates/ch2better.nii.gz")


def osmesa_installed():
    """Whether libOSMesa loads here as the library loads it (Mesa 25.1 removed
    OSMesa; a release without it renders through Mesa's surfaceless EGL)."""
    try:
        ctypes.CDLL("libOSMesa.so.8")
        return True
    except OSError:
        return False


# The backend the tests name where they need a software one.
SOFTWARE = "osmesa" if osmesa_installed() else "egl"


def run(*args, env=None):
    e = dict(os.environ)
    e.pop("VOXLIGHT_BACKEND", None)
    if env:
        e.update(env)
    return subprocess.run([str(CLI), *map(str, args)], capture_output=True, text=True, env=e, timeout=300)


def write_nifti(path, data, slope=0.0, inter=0.0):
    """A minimal NIfTI-1 single file (.nii or .nii.gz) for float32/uint8/int16 data."""
    codes = {np.dtype("uint8"): (2, 8), np.dtype("int16"): (4, 16), np.dtype("float32"): (16, 32)}
    code, bits = codes[data.dtype]
    hdr = bytearray(348)
    struct.pack_into("<i", hdr, 0, 348)
    dims = [3, *data.shape[::-1], 1, 1, 1, 1]  # data is (z, y, x)
    struct.pack_into("<8h", hdr, 40, *dims)
    struct.pack_into("<hh", hdr, 70, code, bits)
    struct.pack_into("<8f", hdr, 76, 1, 1, 1, 1, 1, 1, 1, 1)
    struct.pack_into("<f", hdr, 108, 352.0)
    struct.pack_into("<ff", hdr, 112, slope, inter)
    hdr[344:348] = b"n+1\0"
    blob = bytes(hdr) + b"\0" * 4 + data.astype(data.dtype.newbyteorder("<")).tobytes()
    if str(path).endswith(".gz"):
        blob = gzip.compress(blob)
    Path(path).write_bytes(blob)


def png_size(path):
    b = Path(path).read_bytes()
    assert b[:8] == b"\x89PNG\r\n\x1a\n"
    return struct.unpack(">II", b[16:24])


def png_alpha_mean(path):
    """The mean alpha of our own 8-bit RGBA PNG, in [0, 1]."""
    rgba = png_rgba(path)
    return rgba[..., 3].sum() / (rgba.shape[0] * rgba.shape[1] * 255.0)


def png_rgba(path):
    """Decodes our own 8-bit RGBA PNG (no filters assumed beyond the standard
    ones): an array of (height, width, 4) bytes, the file's first row first."""
    b = Path(path).read_bytes()
    w, h = struct.unpack(">II", b[16:24])
    pos, idat = 8, b""
    while pos < len(b):
        n = struct.unpack(">I", b[pos:pos + 4])[0]
        typ = b[pos + 4:pos + 8]
        if typ == b"IDAT":
            idat += b[pos + 8:pos + 8 + n]
        pos += 12 + n
    raw = zlib.decompress(idat)
    stride = w * 4
    prev = bytearray(stride)
    rows = []
    for y in range(h):
        f = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - 4] if i >= 4 else 0
            up = prev[i]
            c = prev[i - 4] if i >= 4 else 0
            if f == 1:
                line[i] = (line[i] + a) & 255
            elif f == 2:
                line[i] = (line[i] + up) & 255
            elif f == 3:
                line[i] = (line[i] + (a + up) // 2) & 255
            elif f == 4:
                p = a + up - c
                pa, pb, pc = abs(p - a), abs(p - up), abs(p - c)
                pred = a if pa <= pb and pa <= pc else (up if pb <= pc else c)
                line[i] = (line[i] + pred) & 255
        rows.append(bytes(line))
        prev = line
    return np.frombuffer(b"".join(rows), np.uint8).reshape(h, w, 4)


@pytest.fixture
def ball(tmp_path):
    z, y, x = np.mgrid[0:24, 0:24, 0:24]
    r = np.sqrt((x - 11.5) ** 2 + (y - 11.5) ** 2 + (z - 11.5) ** 2)
    path = tmp_path / "ball.nii.gz"
    write_nifti(path, (200.0 / (1 + np.exp(r - 8))).astype(np.float32))
    return path


def assert_clean_error(res, *words):
    assert res.returncode == 1, res
    lines = res.stderr.strip().splitlines()
    assert lines and lines[-1].startswith("voxlight: error: "), res.stderr
    for w in words:
        assert w in res.stderr, (w, res.stderr)


def test_info_reports_the_brain():
    res = run("info", BRAIN)
    assert res.returncode == 0, res.stderr
    assert "301 x 370 x 316" in res.stdout
    assert "uint8" in res.stdout and "sform" in res.stdout
    assert "nan voxels:  0" in res.stdout


def test_render_png_with_options(ball, tmp_path):
    out = tmp_path / "ball.png"
    res = run("render", ball, "-o", out, "--size", "64x48", "--filter", "sobel8", "--sample-distance", "0.5",
              "--reuse-gradients", "--step", "0.25", "--azimuth", "40", "--elevation", "10", "--preset", "hot",
              "--window", "0:200", "--backend", SOFTWARE, "--memory-budget", "512M")
    assert res.returncode == 0, res.stderr
    assert png_size(out) == (64, 48)
    assert png_alpha_mean(out) > 0.05  # the ball is visible


def test_render_exr_and_every_filter(ball, tmp_path):
    for f in ["central", "forward3", "sobel8", "sobel14", "sobel26", "precomputed"]:
        out = tmp_path / f"{f}.exr"
        res = run("render", ball, "-o", out, "--size", "32x32", "--filter", f)
        assert res.returncode == 0, (f, res.stderr)
        assert out.read_bytes()[:4] == b"\x76\x2f\x31\x01"  # OpenEXR magic


def test_no_shading_differs(ball, tmp_path):
    a, b = tmp_path / "a.png", tmp_path / "b.png"
    assert run("render", ball, "-o", a, "--size", "32x32").returncode == 0
    assert run("render", ball, "-o", b, "--size", "32x32", "--no-shading").returncode == 0
    assert a.read_bytes() != b.read_bytes()


def test_missing_file(tmp_path):
    assert_clean_error(run("render", tmp_path / "nope.nii", "-o", tmp_path / "x.png"), "nope.nii")


def test_truncated_file(ball, tmp_path):
    data = gzip.decompress(ball.read_bytes())
    cut = tmp_path / "cut.nii"
    cut.write_bytes(data[: len(data) // 2])
    assert_clean_error(run("render", cut, "-o", tmp_path / "x.png"), "truncated")
    assert_clean_error(run("info", cut), "truncated")


def test_bad_dimensions(tmp_path):
    path = tmp_path / "bad.nii"
    write_nifti(path, np.zeros((2, 2, 2), np.uint8))
    b = bytearray(path.read_bytes())
    struct.pack_into("<h", b, 42, -5)
    path.write_bytes(bytes(b))
    assert_clean_error(run("info", path), "dim")


def test_absurd_size_names_the_budget(tmp_path):
    path = tmp_path / "huge.nii"
    write_nifti(path, np.zeros((2, 2, 2), np.uint8))
    b = bytearray(path.read_bytes())
    struct.pack_into("<3h", b, 42, 30000, 30000, 30000)
    path.write_bytes(bytes(b))
    assert_clean_error(run("info", path), "budget")


@pytest.mark.parametrize("args,word", [
    (["--filter", "sobel99"], "unknown filter"),
    (["--backend", "vulkan"], "unknown backend"),
    (["--size", "0x10"], "--size"),
    (["--window", "5"], "--window"),
    (["--step", "-1"], "--step"),
    (["--memory-budget", "lots"], "--memory-budget"),
    (["--bogus"], "unknown option"),
])
def test_bad_options(ball, tmp_path, args, word):
    assert_clean_error(run("render", ball, "-o", tmp_path / "x.png", *args), word)


def test_unavailable_backend_is_an_error(ball, tmp_path):
    # An EGL library that cannot be found: point the loader at nothing.
    res = run("render", ball, "-o", tmp_path / "x.png", "--backend", "egl",
              env={"LD_LIBRARY_PATH": str(tmp_path), "__EGL_VENDOR_LIBRARY_DIRS": str(tmp_path)})
    assert_clean_error(res, "egl")


def test_bad_output_extension(ball, tmp_path):
    assert_clean_error(run("render", ball, "-o", tmp_path / "x.jpg"), ".png")


def test_environment_selects_backend(ball, tmp_path):
    res = run("render", ball, "-o", tmp_path / "x.png", "--size", "16x16", env={"VOXLIGHT_BACKEND": SOFTWARE})
    assert res.returncode == 0 and SOFTWARE in res.stderr
    res = run("render", ball, "-o", tmp_path / "x.png", env={"VOXLIGHT_BACKEND": "nonsense"})
    assert_clean_error(res, "VOXLIGHT_BACKEND")


def test_auto_uses_what_is_installed(ball, tmp_path):
    """auto: a GPU through EGL, else OSMesa, else Mesa's surfaceless EGL.
    Without OSMesa, asking for it is one clear line naming the package."""
    res = run("render", ball, "-o", tmp_path / "x.png", "--size", "16x16")
    assert res.returncode == 0, res.stderr
    chosen = re.search(r"wrote .* \(16x16, ([\w-]+), ", res.stderr).group(1)
    if osmesa_installed():
        assert chosen in ("osmesa", "egl-device"), res.stderr
    else:
        assert chosen.startswith("egl-"), res.stderr
        assert_clean_error(run("render", ball, "-o", tmp_path / "y.png", "--backend", "osmesa"), "libosmesa6")
