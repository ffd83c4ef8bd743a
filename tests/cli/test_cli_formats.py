"""`voxlight info|render` on the formats beyond NIfTI: NRRD,
MetaImage, multi-page TIFF and numbered PNG series, plus one clear error line
for hostile headers. Files are written here in plain Python (struct/zlib),
independently of the C readers."""
import gzip
import os
import struct
import subprocess
import zlib
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
CLI = ROOT / "build" / "voxlight"


def run(*args):
    e = dict(os.environ)
    e.pop("VOXLIGHT_BACKEND", None)
    return subprocess.run([str(CLI), *map(str, args)], capture_output=True, text=True, env=e, timeout=300)


def blob(shape=(6, 5, 4), dtype=np.int16):
    """A (z, y, x) ball: something visible to render."""
    z, y, x = np.indices(shape)
    c = [(s - 1) / 2 for s in shape]
    r = np.sqrt((z - c[0]) ** 2 + (y - c[1]) ** 2 + (x - c[2]) ** 2)
    return (1000 * np.clip(2.5 - r, 0, None)).astype(dtype)


def write_nrrd(path, data, extra="", gz=False, big=False):
    kind = {np.dtype("int16"): "short", np.dtype("float32"): "float", np.dtype("uint8"): "uchar"}[data.dtype]
    hdr = (f"NRRD0004\ntype: {kind}\ndimension: 3\nsizes: {data.shape[2]} {data.shape[1]} {data.shape[0]}\n"
           f"encoding: {'gzip' if gz else 'raw'}\nendian: {'big' if big else 'little'}\n{extra}\n")
    raw = data.astype(data.dtype.newbyteorder(">" if big else "<")).tobytes()
    Path(path).write_bytes(hdr.encode() + (gzip.compress(raw) if gz else raw))


def write_mha(path, data, extra="", compressed=False):
    kind = {np.dtype("int16"): "MET_SHORT", np.dtype("float32"): "MET_FLOAT", np.dtype("uint8"): "MET_UCHAR"}[data.dtype]
    raw = data.astype(data.dtype.newbyteorder("<")).tobytes()
    hdr = (f"ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = False\n"
           f"CompressedData = {'True' if compressed else 'False'}\n{extra}"
           f"DimSize = {data.shape[2]} {data.shape[1]} {data.shape[0]}\nElementType = {kind}\nElementDataFile = LOCAL\n")
    Path(path).write_bytes(hdr.encode() + (zlib.compress(raw) if compressed else raw))


def write_png(path, img):
    """Grey 8- or 16-bit PNG; img is (rows top first, cols)."""
    bits = 16 if img.dtype == np.uint16 else 8
    rows = b"".join(b"\0" + r.astype(">u2" if bits == 16 else "u1").tobytes() for r in img)

    def chunk(t, d):
        return struct.pack(">I", len(d)) + t + d + struct.pack(">I", zlib.crc32(t + d) & 0xFFFFFFFF)

    ihdr = struct.pack(">IIBBBBB", img.shape[1], img.shape[0], bits, 0, 0, 0, 0)
    Path(path).write_bytes(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", zlib.compress(rows))
                           + chunk(b"IEND", b""))


def write_tiff(path, pages):
    """Multi-page little-endian TIFF of uint16 or float32 grey pages (rows top first)."""
    fmt = 3 if pages[0].dtype == np.float32 else 1
    bits = pages[0].dtype.itemsize * 8
    out = bytearray(b"II*\0\0\0\0\0")
    prev = 4
    for p in pages:
        h, w = p.shape
        data_at = len(out)
        out += p.astype(p.dtype.newbyteorder("<")).tobytes()
        if len(out) % 2:
            out += b"\0"
        ifd = len(out)
        struct.pack_into("<I", out, prev, ifd)
        entries = [(256, 4, w), (257, 4, h), (258, 3, bits), (259, 3, 1), (262, 3, 1), (273, 4, data_at),
                   (277, 3, 1), (278, 4, h), (279, 4, p.nbytes), (284, 3, 1), (339, 3, fmt)]
        out += struct.pack("<H", len(entries))
        for tag, typ, val in entries:
            out += struct.pack("<HHI", tag, typ, 1) + (struct.pack("<HH", val, 0) if typ == 3 else struct.pack("<I", val))
        prev = len(out)
        out += b"\0\0\0\0"
    Path(path).write_bytes(bytes(out))


def info(path):
    r = run("info", path)
    assert r.returncode == 0, r.stderr
    return r.stdout


def affine_rows(text):
    rows = [l.strip().strip("[]").split() for l in text.splitlines() if l.startswith("  [")]
    return np.array([[float(v) for v in r] for r in rows])


def test_nrrd_info_shows_dims_range_and_ras_affine(tmp_path):
    d = blob()
    p = tmp_path / "ball.nrrd"
    write_nrrd(p, d, "space: LPS\nspace directions: (2,0,0) (0,3,0) (0,0,4)\nspace origin: (10,20,30)\n", gz=True,
               big=True)
    out = info(p)
    assert "dimensions:  4 x 5 x 6" in out
    assert "int16" in out
    assert f"value range: 0 .. {d.max()}" in out
    A = affine_rows(out)
    assert np.allclose(A[:3, :], [[-2, 0, 0, -10], [0, -3, 0, -20], [0, 0, 4, 30]])


def test_nhdr_detached_and_mha_mhd(tmp_path):
    d = blob(dtype=np.float32)
    (tmp_path / "ball.raw").write_bytes(d.astype("<f4").tobytes())
    (tmp_path / "ball.nhdr").write_text("NRRD0004\ntype: float\ndimension: 3\nsizes: 4 5 6\nencoding: raw\n"
                                        "endian: little\ndata file: ball.raw\n")
    assert "dimensions:  4 x 5 x 6" in info(tmp_path / "ball.nhdr")
    write_mha(tmp_path / "ball.mha", d, "ElementSpacing = 0.5 1 2\n", compressed=True)
    out = info(tmp_path / "ball.mha")
    assert "dimensions:  4 x 5 x 6" in out and "0.5 x 1 x 2 mm" in out
    (tmp_path / "ball.mhd").write_text("NDims = 3\nDimSize = 4 5 6\nElementType = MET_FLOAT\n"
                                       "ElementDataFile = ball.raw\n")
    assert "dimensions:  4 x 5 x 6" in info(tmp_path / "ball.mhd")


def test_tiff_pages_and_png_series(tmp_path):
    d = blob(dtype=np.uint16)
    write_tiff(tmp_path / "pages.tif", list(d))
    out = info(tmp_path / "pages.tif")
    assert "dimensions:  4 x 5 x 6" in out and "uint16" in out
    series = tmp_path / "series"
    series.mkdir()
    for k, img in enumerate(d.astype(np.uint8) // 8):
        write_png(series / f"slice_{k + 1:04d}.png", img)
    assert "dimensions:  4 x 5 x 6" in info(series / "slice_0003.png")
    assert "dimensions:  4 x 5 x 6" in info(series)
    write_tiff(tmp_path / "float.tif", list(blob(dtype=np.float32)))
    assert "float32" in info(tmp_path / "float.tif")


@pytest.mark.parametrize("name", ["ball.nrrd", "ball.mha", "ball.tif", "series"])
def test_render_every_format(tmp_path, name):
    d = blob((24, 24, 24), np.int16)
    p = tmp_path / name
    if name.endswith(".nrrd"):
        write_nrrd(p, d, gz=True)
    elif name.endswith(".mha"):
        write_mha(p, d, compressed=True)
    elif name.endswith(".tif"):
        write_tiff(p, list(d.astype(np.float32)))
    else:
        p.mkdir()
        for k, img in enumerate(d.astype(np.uint16)):
            write_png(p / f"s{k:03d}.png", img)
    out = tmp_path / "out.png"
    r = run("render", p, "-o", out, "--size", "64x64")
    assert r.returncode == 0, r.stderr
    b = out.read_bytes()
    assert b[:8] == b"\x89PNG\r\n\x1a\n" and struct.unpack(">II", b[16:24]) == (64, 64)


@pytest.mark.parametrize("name,content,needle", [
    ("huge.nrrd", b"NRRD0004\ntype: float\ndimension: 3\nsizes: 100000 100000 100000\nencoding: raw\n"
                  b"endian: little\n\n", "memory budget"),
    ("huge.mha", b"NDims = 3\nDimSize = 100000 100000 100000\nElementType = MET_FLOAT\nElementDataFile = LOCAL\n",
     "memory budget"),
    ("short.nrrd", b"NRRD0004\ntype: uchar\ndimension: 3\nsizes: 4 4 4\nencoding: raw\n\n12", "truncated"),
    ("bad.mha", b"NDims = 3\nDimSize = 4 4\nElementType = MET_UCHAR\nElementDataFile = LOCAL\n", "DimSize"),
    ("junk.tif", b"II*\0garbage", "junk.tif"),
])
def test_hostile_files_give_one_error_line(tmp_path, name, content, needle):
    p = tmp_path / name
    p.write_bytes(content)
    for cmd in (["info", p], ["render", p, "-o", tmp_path / "x.png", "--size", "16x16"]):
        r = run(*cmd)
        assert r.returncode != 0
        lines = [l for l in r.stderr.splitlines() if l.startswith("voxlight: error:")]
        assert len(lines) == 1, r.stderr
        assert needle in lines[0] and name in lines[0], lines[0]


def test_missing_slice_in_series_is_reported(tmp_path):
    img = np.zeros((4, 4), np.uint8)
    for k in (1, 2, 4):
        write_png(tmp_path / f"s_{k:02d}.png", img)
    r = run("info", tmp_path / "s_01.png")
    assert r.returncode != 0 and "missing slices between 2" in r.stderr


@pytest.mark.parametrize("name,needle", [
    # libopenvdb aborts on an assertion here: only the helper process dies
    ("openvdb_delayed_load_mask_assert.vdb", "the OpenVDB reader crashed (signal 6: SIGABRT)"),
    ("openvdb_blosc_size_alloc.vdb", "std::bad_alloc"),
    ("openvdb_transform_string_alloc.vdb", "is not registered"),
])
def test_openvdb_upstream_failures_are_one_error_line(tmp_path, name, needle):
    """tests/fuzz/upstream/: files on which libopenvdb fails before our code
    runs, the first one with abort() (exit 134 before the helper process)."""
    p = ROOT / "tests" / "fuzz" / "upstream" / name
    for cmd in (["info", p], ["render", p, "-o", tmp_path / "x.png", "--size", "16x16"]):
        r = run(*cmd)
        assert r.returncode == 1, (r.returncode, r.stderr)
        lines = [l for l in r.stderr.splitlines() if l.startswith("voxlight: error:")]
        assert len(lines) == 1 and needle in lines[0] and name in lines[0], r.stderr
