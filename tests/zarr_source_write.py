"""Writes the OME-Zarr stores tests/test_zarr_source.c streams (the Zarr
brick source, csrc/io/zarr_source.c), with tests/zarr_write.py's writer.

`python3 tests/zarr_source_write.py OUTDIR` writes the stores and
OUTDIR/manifest.tsv, one line per store:
  NAME  PATH  FRAME  C  LEVELS  EXACT
LEVELS: the store levels the source must offer as its levels 0, 1, ...
(comma-separated; levels that do not halve every axis are skipped); EXACT:
1 when float values must come back unclamped (an omero window covering the
data), 0 when they are clamped to the coarsest level's range.
Plus broken stores the test names directly (bad_*)."""
import gzip
import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from zarr_write import pyramid, write_store, zstd_compress  # noqa: E402


def smooth(shape, dtype, seed):
    """Structure plus noise, spanning much of the type's range (a shift,
    transposition or wrong chunk shows)."""
    rng = np.random.default_rng(seed)
    z, y, x = np.meshgrid(*[np.linspace(0, 1, s) for s in shape], indexing="ij")
    f = np.sin(7 * x) * np.cos(5 * y) + 2 * z + rng.standard_normal(shape) * 0.3  # about -1.9 .. 3.9
    if np.dtype(dtype).kind == "f":
        return (f * 1000).astype(dtype)
    info = np.iinfo(dtype)
    v = (f + 2) / 6 * (int(info.max) - int(info.min)) + int(info.min)
    return np.clip(v, info.min, info.max).astype(dtype)


def add_window(root, lo, hi):
    attrs = root / ".zattrs"
    if attrs.exists():
        meta = json.loads(attrs.read_text())
        meta["omero"] = {"channels": [{"window": {"min": lo, "max": hi, "start": lo, "end": hi}}]}
        attrs.write_text(json.dumps(meta))
    else:
        meta = json.loads((root / "zarr.json").read_text())
        meta["attributes"]["ome"]["omero"] = {"channels": [{"window": {"min": lo, "max": hi}}]}
        (root / "zarr.json").write_text(json.dumps(meta))


def write_cases(out):
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    lines = []

    def case(name, levels, axes="zyx", version=2, codec="gzip", chunks=(8, 8, 8), frame=0, c=0, expect=None,
             exact=1, scales=None):
        root = write_store(out / f"{name}.zarr", levels, axes=axes, version=version, codec=codec,
                           chunks=list(chunks), scales=scales)
        expect = expect if expect is not None else list(range(len(levels)))
        lines.append("\t".join([name, str(root), str(frame), str(c), ",".join(map(str, expect)), str(exact)]))
        return root

    shape = (21, 29, 37)  # z, y, x: no axis a multiple of the chunk
    case("v2_gzip_u16", pyramid(smooth(shape, np.uint16, 1), 3, "zyx"))
    case("v2_zlib_u8", pyramid(smooth(shape, np.uint8, 2), 4, "zyx"), codec="zlib")
    case("v2_raw_i16", pyramid(smooth(shape, np.int16, 3), 3, "zyx"), codec="raw")
    case("v2_zstd_u16", pyramid(smooth(shape, np.uint16, 4), 3, "zyx"), codec="zstd", chunks=(4, 8, 16))
    case("v2_blosc_i8", pyramid(smooth(shape, np.int8, 5), 3, "zyx"), codec="blosc")
    f = pyramid(smooth(shape, np.float32, 6), 3, "zyx")
    add_window(case("v3_zstd_f32_window", f, version=3, codec="zstd"), float(f[0].min()), float(f[0].max()))
    case("v3_blosc_f32_coarse_range", pyramid(smooth(shape, np.float32, 7), 3, "zyx"), version=3, codec="blosc",
         exact=0)
    case("v3_gzip_u16", pyramid(smooth(shape, np.uint16, 8), 3, "zyx"), version=3, codec="gzip")
    tc = np.stack([np.stack([smooth(shape, np.uint8, 10 + 3 * t + ch) for ch in range(2)]) for t in range(3)])
    case("v3_zstd_u8_tczyx", pyramid(tc, 3, "tczyx"), axes="tczyx", version=3, codec="zstd", chunks=(1, 1, 8, 8, 8),
         frame=2, c=1)
    # an anisotropic level (x and y halved, z kept) is skipped; the last
    # level is floor-sized (dims // 4 rather than ceil)
    d = smooth(shape, np.uint16, 9)
    aniso = np.ascontiguousarray(d[:, ::2, ::2])
    half = np.ascontiguousarray(d[::2, ::2, ::2])
    quarter = np.ascontiguousarray(d[::4, ::4, ::4][: shape[0] // 4, : shape[1] // 4, : shape[2] // 4])
    sc = [[1, 1, 1], [1, 2, 2], [2, 2, 2], [4, 4, 4]]
    case("v2_gzip_u16_skip_aniso_floor", [d, aniso, half, quarter], expect=[0, 2, 3], scales=sc)
    # more chunks than the decoded-chunk cache holds at a 1 MiB budget
    case("v2_zstd_u16_many_chunks", pyramid(smooth((96, 96, 96), np.uint16, 11), 3, "zyx"), codec="zstd",
         chunks=(16, 16, 16))
    (out / "manifest.tsv").write_text("\n".join(lines) + "\n")

    # item 5: chunks that decompress to more than the array metadata says
    bad = write_store(out / "bad_gzip_level0.zarr", pyramid(smooth(shape, np.uint16, 12), 3, "zyx"), codec="gzip",
                      chunks=[8, 8, 8])
    (bad / "0" / "1" / "1" / "1").write_bytes(gzip.compress(bytes(8 * 8 * 8 * 2 * 2)))
    bad = write_store(out / "bad_zstd_level2.zarr", pyramid(smooth(shape, np.uint16, 13), 3, "zyx"), codec="zstd",
                      chunks=[8, 8, 8])
    (bad / "2" / "0" / "0" / "0").write_bytes(zstd_compress(bytes(8 * 8 * 8 * 2 + 2)))


if __name__ == "__main__":
    write_cases(sys.argv[1])
