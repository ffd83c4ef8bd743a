"""`voxlight info|render` on OME-Zarr stores (csrc/io/zarr*.c in the helper
voxlight-read-zarr) written by tests/zarr_write.py: the dispatch by folder
and by "#level=N&c=N", what info reports (dims of the chosen level, frames =
the t extent, the scale/translation affine), a render, one error line for a
bad store, and the message when the helper is missing. The values themselves
are checked voxel by voxel in tests/test_zarr.c."""
import os
import struct
import subprocess
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
CLI = ROOT / "build" / "voxlight"
sys.path.insert(0, str(ROOT / "tests"))
from zarr_write import pyramid, write_store  # noqa: E402


def run(*args, env=None):
    e = dict(os.environ)
    e.pop("VOXLIGHT_BACKEND", None)
    e.update(env or {})
    return subprocess.run([str(CLI), *map(str, args)], capture_output=True, text=True, env=e, timeout=300)


def ball(shape, dtype=np.uint16):
    z, y, x = np.indices(shape)
    c = [(s - 1) / 2 for s in shape]
    r = np.sqrt(sum((g - m) ** 2 for g, m in zip((z, y, x), c)))
    return (1000 * np.clip(shape[0] / 3 - r, 0, None)).astype(dtype)


def field(out, name):
    return next(l.split(":", 1)[1].strip() for l in out.splitlines() if l.startswith(name + ":"))


def test_info_level_channel_time_and_affine(tmp_path):
    axes = "tczyx"
    data = np.stack([np.stack([ball((8, 10, 12)) * (1 + t + c) for c in range(2)]) for t in range(3)])
    store = write_store(tmp_path / "img.zarr", pyramid(data, 2, axes), axes, version=3, codec="zstd",
                        chunks=[1, 1, 4, 4, 4], scales=[[1, 1, 2.0, 0.5, 0.25], [1, 1, 4.0, 1.0, 0.5]],
                        translation=[0, 0, 10.0, 20.0, 30.0])
    r = run("info", store)
    assert r.returncode == 0, r.stderr
    assert field(r.stdout, "dimensions") == "12 x 10 x 8"
    assert field(r.stdout, "frames").startswith("3 ")
    assert field(r.stdout, "value range") == f"0 .. {data[0, 0].max()}"  # t 0, c 0 by default
    lines = r.stdout.splitlines()
    row = lines.index(next(l for l in lines if l.startswith("affine:")))
    affine = np.array([[float(v) for v in l.strip(" []").split()] for l in lines[row + 1:row + 5]])
    # the store's micrometers in mm
    mm = np.diag([1e-3, 1e-3, 1e-3, 1]) @ [[0.25, 0, 0, 30], [0, 0.5, 0, 20], [0, 0, 2, 10], [0, 0, 0, 1]]
    assert np.allclose(affine, mm, rtol=1e-6, atol=1e-12)
    r = run("info", str(store) + "#level=1&c=1", "--frame", "2")
    assert r.returncode == 0, r.stderr
    assert field(r.stdout, "dimensions") == "6 x 5 x 4"
    assert field(r.stdout, "value range").endswith(" .. " + str(int(data[2, 1, ::2, ::2, ::2].max())))


def test_render_a_v2_blosc_store(tmp_path):
    store = write_store(tmp_path / "ball.zarr", pyramid(ball((24, 24, 24)), 2, "zyx"), "zyx", version=2,
                        codec="blosc", chunks=[8, 8, 8], sep=".")
    out = tmp_path / "out.png"
    r = run("render", store, "-o", out, "--size", "48x48")
    assert r.returncode == 0, r.stderr
    b = out.read_bytes()
    assert b[:8] == b"\x89PNG\r\n\x1a\n" and struct.unpack(">II", b[16:24]) == (48, 48)


def test_bad_store_is_one_error_line_naming_the_file(tmp_path):
    store = write_store(tmp_path / "bad.zarr", [ball((4, 4, 4))], "zyx", version=2, codec="gzip")
    (store / "0" / ".zarray").write_text('{"zarr_format": 2, "shape": [4, 4')
    for cmd in (["info", store], ["render", store, "-o", tmp_path / "x.png", "--size", "16x16"]):
        r = run(*cmd)
        assert r.returncode == 1
        lines = [l for l in r.stderr.splitlines() if l.startswith("voxlight: error:")]
        assert len(lines) == 1, r.stderr
        assert "bad.zarr/0/.zarray" in lines[0] and "not valid JSON" in lines[0], lines[0]


def test_missing_helper_is_named(tmp_path):
    store = write_store(tmp_path / "ok.zarr", [ball((4, 4, 4))], "zyx", version=2, codec="raw")
    r = run("info", store, env={"VOXLIGHT_READ_ZARR": str(tmp_path / "nowhere")})
    assert r.returncode == 1
    assert "OME-Zarr stores are read by the helper program" in r.stderr and "nowhere" in r.stderr, r.stderr


def test_missing_library_names_both_packages(tmp_path):
    """A stand-in helper printing the dynamic loader's message, as the real
    one would without libblosc: the error names the library and packages."""
    store = write_store(tmp_path / "ok.zarr", [ball((4, 4, 4))], "zyx", version=2, codec="raw")
    fake = tmp_path / "voxlight-read-zarr"
    fake.write_text("#!/bin/sh\necho 'voxlight-read-zarr: error while loading shared libraries: libblosc.so.1: "
                    "cannot open shared object file: No such file or directory' >&2\nexit 127\n")
    fake.chmod(0o755)
    r = run("info", store, env={"VOXLIGHT_READ_ZARR": str(fake)})
    assert r.returncode == 1
    assert "OME-Zarr stores need libblosc and libzstd" in r.stderr, r.stderr
    assert "libblosc.so.1 is missing: apt-get install libblosc1 libzstd1" in r.stderr, r.stderr


def test_a_metadata_file_picked_inside_the_store_opens_the_store(tmp_path):
    """What a file browser hands over when the user picks zarr.json or
    .zattrs; a level's own zarr.json is refused with a pointer to the image."""
    data = ball((4, 5, 6))
    v3 = write_store(tmp_path / "a.zarr", [data], "zyx", version=3, codec="gzip")
    v2 = write_store(tmp_path / "b.zarr", [data], "zyx", version=2, codec="gzip")
    for p in (v3 / "zarr.json", str(v2 / ".zattrs") + "#level=0"):
        r = run("info", p)
        assert r.returncode == 0, r.stderr
        assert field(r.stdout, "dimensions") == "6 x 5 x 4"
    r = run("info", v3 / "0" / "zarr.json")
    assert r.returncode == 1 and "is a Zarr array, not an OME-Zarr image group" in r.stderr, r.stderr
