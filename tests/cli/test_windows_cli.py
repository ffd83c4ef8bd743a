"""The CLI cross-compiled for Windows (build/windows-x64/voxlight.exe, with
voxlight.dll, zlib1.dll, voxlight-read-zarr.exe and voxlight-read-dicom.exe
beside it) under Wine:
each format written in Voxlight's own C reads and renders as the Linux CLI
does, from a folder whose name is not ASCII (UTF-8 arguments through the
wide-character command line and file calls); the formats whose readers need
a C++ library with no Windows build are refused by name, never a crash.
The Linux CLI on the same files is the reference: `info` must print the
same report and `render` the same PNG."""
import os
import subprocess
import sys
import zlib
import struct
from pathlib import Path

import numpy as np
import pytest

from test_cli_formats import write_mha, write_nrrd, write_tiff
from wine_run import run_windows

ROOT = Path(__file__).resolve().parents[2]
CLI = ROOT / "build" / "voxlight"
sys.path.insert(0, str(ROOT / "tests"))
sys.path.insert(0, str(ROOT / "tests" / "python"))
from nifti_write import write_nifti  # noqa: E402
from zarr_write import pyramid, write_store  # noqa: E402


def run_linux(*args):
    env = dict(os.environ)
    env.pop("VOXLIGHT_BACKEND", None)
    return subprocess.run([str(CLI), *map(str, args)], capture_output=True, text=True, env=env, timeout=300)


def png_pixels(path):
    """(h, w, channels) uint8/uint16 of a PNG the CLI wrote (no filters
    beyond what zlib and the row filter bytes hold: rows are read as written)."""
    b = Path(path).read_bytes()
    assert b[:8] == b"\x89PNG\r\n\x1a\n"
    i, idat = 8, b""
    while i < len(b):
        n, kind = struct.unpack(">I4s", b[i:i + 8])
        if kind == b"IHDR":
            w, h, bits, colour = struct.unpack(">IIBB", b[i + 8:i + 18])
        elif kind == b"IDAT":
            idat += b[i + 8:i + 8 + n]
        i += 12 + n
    return w, h, bits, colour, zlib.decompress(idat)


@pytest.fixture(scope="module")
def inputs(tmp_path_factory):
    """One file per format the Windows build reads, in a folder named José."""
    d = tmp_path_factory.mktemp("win") / "Scans José ü"
    d.mkdir()
    z, y, x = np.indices((24, 24, 24))
    r = np.sqrt((z - 11.5) ** 2 + (y - 11.5) ** 2 + (x - 11.5) ** 2)
    ball = (1000 * np.clip(8.5 - r, 0, 1)).astype(np.int16)  # a ball of radius 8, one voxel soft
    files = {}
    files["nifti"] = d / "ball.nii.gz"
    write_nifti(files["nifti"], ball.transpose(2, 1, 0), np.diag([0.8, 0.8, 1.2, 1.0]))
    files["nrrd"] = d / "ball.nrrd"
    write_nrrd(files["nrrd"], ball, gz=True)
    files["metaimage"] = d / "ball.mha"
    write_mha(files["metaimage"], ball, compressed=True)
    files["zarr"] = write_store(d / "ball.zarr", pyramid(ball.astype(np.uint16), 2, "zyx"), "zyx", version=2,
                                codec="gzip", chunks=[8, 8, 8])
    files["tiff"] = d / "ball.tif"
    write_tiff(files["tiff"], list(ball.astype(np.float32)))
    # detached headers: the data file is found beside the header, whose
    # path the Windows program gets with backslashes
    files["nhdr"] = d / "ball.nhdr"
    (d / "ball_nrrd.raw").write_bytes(ball.astype("<i2").tobytes())
    files["nhdr"].write_text("NRRD0004\ntype: short\ndimension: 3\nsizes: 24 24 24\nencoding: raw\n"
                             "endian: little\ndata file: ball_nrrd.raw\n\n")
    files["mhd"] = d / "ball.mhd"
    (d / "ball_mhd.raw").write_bytes(ball.astype("<i2").tobytes())
    files["mhd"].write_text("ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = False\n"
                            "DimSize = 24 24 24\nElementType = MET_SHORT\nElementDataFile = ball_mhd.raw\n")
    return files


def run_tool(*args):
    subprocess.run([str(a) for a in args], check=True, capture_output=True, timeout=300)


@pytest.fixture(scope="module")
def dicom_inputs(tmp_path_factory):
    """DICOM made on Linux, each in its own folder under one named José: an
    enhanced multi-frame CT (pydicom, tests/make_enhanced_dicom.py: shuffled
    frames, per-frame and shared functional groups) as written, deflated,
    in RLE and in lossless JPEG (SV1) and JPEG-LS (dcmtk's encoders), and a
    colour file (tests/make_colour_dicom.py, YBR_FULL) and a PALETTE COLOR
    one. Windows reads them with our own parser (voxlight-read-dicom.exe),
    Linux with dcmtk."""
    d = tmp_path_factory.mktemp("windicom") / "Scans José DICOM"
    d.mkdir()
    py = "/usr/bin/python3"
    files = {}

    def folder(name):
        (d / name).mkdir()
        return d / name

    files["enhanced"] = folder("enhanced") / "ct.dcm"
    run_tool(py, ROOT / "tests" / "make_enhanced_dicom.py", files["enhanced"], 20, 16, 12, 1,
             0.8, 0.6, 0, 0, 0, -1, -10, 20, 30, -1.2, 1.6, 0, 7)  # oblique, 2 mm along the normal
    for name, tool in (("deflated", ["dcmconv", "+td"]), ("rle", ["dcmcrle"]), ("jpeg_lossless", ["dcmcjpeg"]),
                       ("jpeg_ls", ["dcmcjpls"])):
        files[name] = folder(name) / "ct.dcm"
        run_tool(*tool, files["enhanced"], files[name])
    for mode in ("ybr", "palette"):
        files[mode] = folder(mode) / "colour.dcm"
        run_tool(py, ROOT / "tests" / "make_colour_dicom.py", files[mode], mode)
    return files


def without_paths(text, *paths):
    """The report's lines that do not name the input (which each OS spells its own way)."""
    return [l for l in text.splitlines() if not any(str(p.name) in l for p in paths)]


@pytest.mark.parametrize("fmt,extra", [("nifti", []), ("nrrd", []), ("metaimage", []), ("zarr", []),
                                       ("zarr", ["--streaming", "on"]), ("tiff", ["--streaming", "on"]),
                                       ("nhdr", []), ("mhd", [])])
def test_info_matches_linux(inputs, fmt, extra):
    src = inputs[fmt]
    lin = run_linux("info", src, *extra)
    assert lin.returncode == 0, lin.stderr
    win = run_windows("voxlight.exe", "info", src, *extra)
    assert win.returncode == 0, win.stdout + win.stderr
    assert without_paths(win.stdout, src) == without_paths(lin.stdout, src)


@pytest.mark.parametrize("fmt,extra", [("nifti", []), ("zarr", []), ("tiff", ["--streaming", "on"])])
def test_render_matches_linux(inputs, tmp_path, fmt, extra):
    src = inputs[fmt]
    out_l, out_w = tmp_path / "linux.png", src.parent / ("windows-%s.png" % fmt)
    lin = run_linux("render", src, "-o", out_l, "--size", "64x64", *extra)
    assert lin.returncode == 0, lin.stderr
    win = run_windows("voxlight.exe", "render", src, "-o", out_w, "--size", "64x64", *extra, display=True)
    assert win.returncode == 0, win.stdout + win.stderr
    assert ", wgl, " in win.stderr, win.stderr  # rendered through WGL
    w_l, h_l, bits_l, c_l, px_l = png_pixels(out_l)
    w_w, h_w, bits_w, c_w, px_w = png_pixels(out_w)
    assert (w_w, h_w, bits_w, c_w) == (w_l, h_l, bits_l, c_l)
    a = np.frombuffer(px_l, np.uint8).astype(int)
    b = np.frombuffer(px_w, np.uint8).astype(int)
    assert (a != 0).mean() > 0.1  # the ball is in the picture
    assert np.abs(a - b).max() <= 1, "PNG bytes differ by up to %d" % np.abs(a - b).max()


@pytest.mark.parametrize("kind", ["enhanced", "deflated", "rle", "jpeg_lossless", "ybr", "palette"])
def test_dicom_info_matches_linux(dicom_inputs, kind):
    """Our own parser on Windows reports what dcmtk's does on Linux: size,
    spacing, affine, value range, notes."""
    src = dicom_inputs[kind]
    lin = run_linux("info", src)
    assert lin.returncode == 0, lin.stderr
    win = run_windows("voxlight.exe", "info", src)
    assert win.returncode == 0, win.stdout + win.stderr
    assert without_paths(win.stdout, src) == without_paths(lin.stdout, src)


@pytest.mark.parametrize("kind", ["enhanced", "rle", "ybr"])
def test_dicom_render_matches_linux(dicom_inputs, tmp_path, kind):
    src = dicom_inputs[kind]
    out_l, out_w = tmp_path / "linux.png", tmp_path / "windows.png"
    lin = run_linux("render", src, "-o", out_l, "--size", "48x48")
    assert lin.returncode == 0, lin.stderr
    win = run_windows("voxlight.exe", "render", src, "-o", out_w, "--size", "48x48", display=True)
    assert win.returncode == 0, win.stdout + win.stderr
    a = np.frombuffer(png_pixels(out_l)[4], np.uint8).astype(int)
    b = np.frombuffer(png_pixels(out_w)[4], np.uint8).astype(int)
    assert (a != 0).mean() > 0.05  # the volume is in the picture
    assert np.abs(a - b).max() <= 1, "PNG bytes differ by up to %d" % np.abs(a - b).max()


def test_jpeg_ls_dicom_is_one_clear_line_on_windows(dicom_inputs):
    """JPEG-LS is decoded by dcmtk's codec alone: Windows names the syntax
    and the tool that decompresses it, in one line."""
    line = one_error_line(run_windows("voxlight.exe", "info", dicom_inputs["jpeg_ls"]))
    assert "JPEG-LS Lossless is not decoded on this system" in line and "dcmdjpls" in line, line


def test_an_uncompressed_tiff_streams_on_windows_without_asking(inputs):
    """Windows has no OpenImageIO helper: a TIFF our C can read by offset is
    streamed under the default (auto), as Linux streams it when asked."""
    src = inputs["tiff"]
    lin = run_linux("info", src, "--streaming", "on")
    assert lin.returncode == 0, lin.stderr
    win = run_windows("voxlight.exe", "info", src)
    assert win.returncode == 0, win.stdout + win.stderr
    assert without_paths(win.stdout, src) == without_paths(lin.stdout, src)


def test_a_matcap_png_is_decoded_on_windows(inputs, tmp_path):
    """--matcap's PNG is inflated by the zlib1.dll beside voxlight.exe."""
    from test_cli_modes import write_png
    cap = tmp_path / "cap.png"
    yy, xx = np.mgrid[0:32, 0:32]
    write_png(cap, np.stack([xx * 8, yy * 8, np.full_like(xx, 128)], -1).astype(np.uint8))
    out_l, out_w = tmp_path / "l.png", tmp_path / "w.png"
    args = ["--size", "48x48", "--mode", "iso", "--iso-value", "0.3", "--matcap", cap]
    lin = run_linux("render", inputs["nifti"], "-o", out_l, *args)
    assert lin.returncode == 0, lin.stderr
    win = run_windows("voxlight.exe", "render", inputs["nifti"], "-o", out_w, *args, display=True)
    assert win.returncode == 0, win.stdout + win.stderr
    a = np.frombuffer(png_pixels(out_l)[4], np.uint8).astype(int)
    b = np.frombuffer(png_pixels(out_w)[4], np.uint8).astype(int)
    assert np.abs(a - b).max() <= 1


def one_error_line(win):
    assert win.returncode == 1, win.stdout + win.stderr
    lines = [l for l in win.stderr.splitlines() if l.startswith("voxlight: error:")]
    assert len(lines) == 1, win.stderr
    return lines[0]


def test_formats_without_a_windows_reader_are_refused_by_name(inputs, tmp_path):
    """TIFF read whole (streaming off) needs OpenImageIO; zstd and blosc
    chunks need Debian's libzstd and libblosc. A damaged DICOM file is one
    line from our own parser."""
    line = one_error_line(run_windows("voxlight.exe", "info", inputs["tiff"], "--streaming", "off"))
    assert "TIFF/PNG stacks are not read on Windows yet" in line and "OpenImageIO" in line, line
    dcm = tmp_path / "slice.dcm"
    dcm.write_bytes(b"\0" * 128 + b"DICM" + b"\0" * 64)
    line = one_error_line(run_windows("voxlight.exe", "info", dcm))
    assert "slice.dcm" in line and "not a readable DICOM file" in line, line
    ball = np.zeros((8, 8, 8), np.uint16)
    ball[2:6, 2:6, 2:6] = 1000
    for codec in ("zstd", "blosc"):
        store = write_store(tmp_path / ("%s.zarr" % codec), [ball], "zyx", version=2, codec=codec, chunks=[4, 4, 4])
        line = one_error_line(run_windows("voxlight.exe", "info", store))
        assert "%s-compressed chunks are not read on Windows yet" % codec in line, line


def test_a_missing_file_is_one_error_line(tmp_path):
    win = run_windows("voxlight.exe", "info", tmp_path / "nowhere José.nii.gz")
    assert win.returncode == 1
    assert "nowhere José.nii.gz" in win.stderr and "voxlight: error:" in win.stderr, win.stderr
