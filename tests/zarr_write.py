"""Writes OME-Zarr test stores (Zarr v2 / OME-NGFF v0.4 and Zarr v3 / v0.5)
from numpy arrays, independently of the C reader (csrc/io/zarr*.c): gzip and
zlib with Python's own modules, zstd and blosc through ctypes on the shared
libraries of libzstd-dev and libblosc-dev (which build.sh installs), so no
Python package beyond numpy is needed.

`python3 tests/zarr_write.py OUTDIR` writes the stores tests/test_zarr.c
reads, plus OUTDIR/manifest.tsv: one line per case, either
  OK  PATH  FRAME  BUDGET  EXPECTED.f64  DX DY DZ  SX SY SZ  TX TY TZ  FRAMES
(the volume the reader must return, float64 little-endian, x fastest, and
its geometry) or
  ERR PATH  FRAME  BUDGET  CODE  TEXT
(the load must fail with VXL_ERR_CODE and a message containing TEXT).
write_store() is the reusable part (tests/cli/test_cli_zarr.py uses it)."""
import ctypes
import gzip
import itertools
import json
import sys
import zlib
from pathlib import Path

import numpy as np

_zstd = _blosc = None


def zstd_compress(raw, level=3):
    global _zstd
    if _zstd is None:
        _zstd = ctypes.CDLL("libzstd.so.1")
        _zstd.ZSTD_compressBound.restype = ctypes.c_size_t
        _zstd.ZSTD_compress.restype = ctypes.c_size_t
        _zstd.ZSTD_isError.restype = ctypes.c_uint
    cap = _zstd.ZSTD_compressBound(ctypes.c_size_t(len(raw)))
    out = ctypes.create_string_buffer(cap)
    n = _zstd.ZSTD_compress(out, ctypes.c_size_t(cap), raw, ctypes.c_size_t(len(raw)), level)
    assert not _zstd.ZSTD_isError(ctypes.c_size_t(n))
    return out.raw[:n]


def blosc_compress(raw, typesize, cname="lz4", shuffle=1):
    global _blosc
    if _blosc is None:
        _blosc = ctypes.CDLL("libblosc.so.1")
    cap = len(raw) + 16
    out = ctypes.create_string_buffer(cap)
    n = _blosc.blosc_compress_ctx(5, shuffle, ctypes.c_size_t(typesize), ctypes.c_size_t(len(raw)), raw, out,
                                  ctypes.c_size_t(cap), cname.encode(), ctypes.c_size_t(0), 1)
    assert n > 0, n
    return out.raw[:n]


def encode(codec, raw, typesize):
    return {"raw": lambda: raw, "gzip": lambda: gzip.compress(raw, mtime=0), "zlib": lambda: zlib.compress(raw),
            "zstd": lambda: zstd_compress(raw), "blosc": lambda: blosc_compress(raw, typesize)}[codec]()


V2_DTYPE = {"uint8": "u1", "int8": "i1", "uint16": "u2", "int16": "i2", "uint32": "u4", "int32": "i4",
            "float32": "f4", "float64": "f8"}


def _fill_json(fill):
    if isinstance(fill, float) and np.isnan(fill):
        return "NaN"
    return fill


def _chunk_key(idx, version, sep, v3_encoding):
    key = sep.join(str(i) for i in idx)
    if version == 3 and v3_encoding == "default":
        return "c" + sep + key
    return key


def write_array(folder, data, version, codec, chunks, sep="/", endian="<", fill=0, missing=(),
                v3_encoding="default", dimension_names=None):
    """One Zarr array of data (C order). Chunks whose index is in missing are
    not written (the reader must give fill there; the caller makes data
    equal fill there)."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    dt = data.dtype
    stored = dt.newbyteorder(">" if endian == ">" else "<") if dt.itemsize > 1 else dt
    if version == 2:
        comp = None if codec == "raw" else (
            {"id": "blosc", "cname": "lz4", "clevel": 5, "shuffle": 1, "blocksize": 0} if codec == "blosc"
            else {"id": codec, "level": 5})
        meta = {"zarr_format": 2, "shape": list(data.shape), "chunks": list(chunks),
                "dtype": ("|" if dt.itemsize == 1 else endian) + V2_DTYPE[dt.name], "compressor": comp,
                "fill_value": _fill_json(fill), "order": "C", "filters": None, "dimension_separator": sep}
        (folder / ".zarray").write_text(json.dumps(meta))
    else:
        codecs = [{"name": "bytes", "configuration": {"endian": "big" if endian == ">" else "little"}}]
        if codec == "blosc":
            codecs.append({"name": "blosc", "configuration": {"cname": "lz4", "clevel": 5, "shuffle": "shuffle",
                                                              "typesize": dt.itemsize, "blocksize": 0}})
        elif codec == "zstd":
            codecs.append({"name": "zstd", "configuration": {"level": 3, "checksum": False}})
        elif codec == "gzip":
            codecs.append({"name": "gzip", "configuration": {"level": 5}})
        meta = {"zarr_format": 3, "node_type": "array", "shape": list(data.shape), "data_type": dt.name,
                "chunk_grid": {"name": "regular", "configuration": {"chunk_shape": list(chunks)}},
                "chunk_key_encoding": {"name": v3_encoding, "configuration": {"separator": sep}},
                "fill_value": _fill_json(fill), "codecs": codecs, "attributes": {}}
        if dimension_names:
            meta["dimension_names"] = dimension_names
        (folder / "zarr.json").write_text(json.dumps(meta))
    grid = [range((s + c - 1) // c) for s, c in zip(data.shape, chunks)]
    for idx in itertools.product(*grid):
        if tuple(idx) in missing:
            continue
        block = np.full(chunks, fill, dtype=dt)
        sl = tuple(slice(i * c, min((i + 1) * c, s)) for i, c, s in zip(idx, chunks, data.shape))
        part = data[sl]
        block[tuple(slice(0, p) for p in part.shape)] = part
        raw = block.astype(stored).tobytes()
        p = folder / _chunk_key(idx, version, sep, v3_encoding)
        p.parent.mkdir(parents=True, exist_ok=True)
        p.write_bytes(encode(codec, raw, dt.itemsize))


AXIS_TYPE = {"t": "time", "c": "channel", "z": "space", "y": "space", "x": "space"}


def write_store(root, levels, axes="zyx", version=2, codec="gzip", chunks=None, sep="/", endian="<", fill=0,
                scales=None, translation=None, missing=(), v3_encoding="default"):
    """An OME-Zarr image: levels are arrays (finest first) with axes in
    `axes` order; scales[l] is level l's scale per axis (default 2^l on
    z, y, x), translation one list for all levels. missing: chunk indices
    of level 0 left unwritten."""
    root = Path(root)
    root.mkdir(parents=True, exist_ok=True)
    nd = len(axes)
    chunks = chunks or [min(4, s) for s in levels[0].shape]
    datasets = []
    for l, data in enumerate(levels):
        sc = scales[l] if scales else [1.0 if a in "tc" else float(2 ** l) for a in axes]
        tr = [{"type": "scale", "scale": list(sc)}]
        if translation:
            tr.append({"type": "translation", "translation": list(translation)})
        datasets.append({"path": str(l), "coordinateTransformations": tr})
        ch = [min(c, s) for c, s in zip(chunks, data.shape)]
        write_array(root / str(l), data, version, codec, ch, sep, endian, fill, missing if l == 0 else (),
                    v3_encoding, list(axes) if version == 3 else None)
    axes_json = [{"name": a, "type": AXIS_TYPE[a], **({"unit": "micrometer"} if a in "zyx" else {})} for a in axes]
    ms = [{"version": "0.4" if version == 2 else "0.5", "name": root.name, "axes": axes_json, "datasets": datasets}]
    assert nd == levels[0].ndim
    if version == 2:
        (root / ".zgroup").write_text(json.dumps({"zarr_format": 2}))
        (root / ".zattrs").write_text(json.dumps({"multiscales": ms}))
    else:
        ms[0].pop("version")
        (root / "zarr.json").write_text(json.dumps({"zarr_format": 3, "node_type": "group",
                                                    "attributes": {"ome": {"version": "0.5", "multiscales": ms}}}))
    return root


def pyramid(data, n, axes):
    """n levels, each 2x smaller on z, y, x (every second element)."""
    sl = tuple(slice(None, None, 2) if a in "zyx" else slice(None) for a in axes)
    out = [data]
    for _ in range(n - 1):
        out.append(np.ascontiguousarray(out[-1][sl]))
    return out


def ramp(shape, dtype, seed):
    """Values that differ voxel to voxel in every axis (a transposition or
    shift shows), spanning the type's range where it is an integer."""
    rng = np.random.default_rng(seed)
    if np.dtype(dtype).kind == "f":
        return (rng.standard_normal(shape) * 1000).astype(dtype)
    info = np.iinfo(dtype)
    return rng.integers(info.min, int(info.max) + 1, size=shape, dtype=np.int64).astype(dtype)


def _select(data, axes, t, c):
    idx = tuple(t if a == "t" else c if a == "c" else slice(None) for a in axes)
    v = data[idx]
    order = [a for a in axes if a in "zyx"]
    return np.ascontiguousarray(np.transpose(v, [order.index(a) for a in "zyx"]))


class Manifest:
    def __init__(self, out):
        self.out = Path(out)
        self.lines = []

    def ok(self, name, store, levels, axes, level, t=0, c=0, budget=0, fragment=None, scales=None,
           translation=None):
        vol = _select(levels[level], axes, t, c).astype("<f8")
        exp = self.out / f"{name}.f64"
        exp.write_bytes(vol.tobytes())
        sc = scales[level] if scales else [1.0 if a in "tc" else float(2 ** level) for a in axes]
        # write_store's axes are in micrometers: the reader's affine is in mm
        s = [sc[axes.index(a)] * 1e-3 for a in "xyz"]
        tr = [translation[axes.index(a)] * 1e-3 if translation else 0.0 for a in "xyz"]
        nt = levels[0].shape[axes.index("t")] if "t" in axes else 1
        path = str(store) + (fragment if fragment is not None else f"#level={level}&c={c}")
        self.lines.append("\t".join(["OK", path, str(t), str(budget), str(exp),
                                     *map(str, vol.shape[::-1]), *map(repr, s), *map(repr, tr), str(nt)]))

    def err(self, path, code, text, t=0, budget=0):
        self.lines.append("\t".join(["ERR", str(path), str(t), str(budget), code, text]))

    def write(self):
        (self.out / "manifest.tsv").write_text("\n".join(self.lines) + "\n")


def write_cases(out):
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    m = Manifest(out)
    # every codec and dtype, both versions, both separators, both byte orders
    cases = [  # name, version, codec, dtype, sep, endian, v3 key encoding
        ("v2_raw_u8", 2, "raw", "uint8", ".", "<", "default"),
        ("v2_gzip_u16", 2, "gzip", "uint16", ".", "<", "default"),
        ("v2_zlib_i8", 2, "zlib", "int8", "/", "<", "default"),
        ("v2_zstd_u32_be", 2, "zstd", "uint32", "/", ">", "default"),
        ("v2_blosc_i16_be", 2, "blosc", "int16", ".", ">", "default"),
        ("v2_blosc_f32", 2, "blosc", "float32", "/", "<", "default"),
        ("v2_gzip_f64_be", 2, "gzip", "float64", "/", ">", "default"),
        ("v3_raw_i32", 3, "raw", "int32", "/", "<", "default"),
        ("v3_gzip_u16", 3, "gzip", "uint16", "/", "<", "default"),
        ("v3_zstd_f32_be", 3, "zstd", "float32", "/", ">", "default"),
        ("v3_blosc_i16_dot", 3, "blosc", "int16", ".", "<", "default"),
        ("v3_zstd_u8_v2keys", 3, "zstd", "uint8", ".", "<", "v2"),
    ]
    axes = "zyx"
    tr = [1.5, -2.0, 3.25]
    for i, (name, ver, codec, dt, sep, end, enc) in enumerate(cases):
        data = ramp((9, 10, 11), dt, i)
        lv = pyramid(data, 3, axes)
        store = write_store(out / f"{name}.zarr", lv, axes, ver, codec, [4, 3, 5], sep, end, 0,
                            translation=tr, v3_encoding=enc)
        m.ok(name + "_l0", store, lv, axes, 0, translation=tr)
        m.ok(name + "_l2", store, lv, axes, 2, translation=tr)
    # t, c, z, y, x with anisotropic scales: channel and time choice
    axes = "tczyx"
    data = ramp((3, 2, 5, 6, 7), "uint16", 99)
    lv = pyramid(data, 2, axes)
    scales = [[1.0, 1.0, 2.0, 0.5, 0.25], [1.0, 1.0, 4.0, 1.0, 0.5]]
    for ver in (2, 3):
        store = write_store(out / f"tczyx_v{ver}.zarr", lv, axes, ver, "zstd", [1, 1, 2, 4, 3], "/", "<", 0,
                            scales=scales)
        m.ok(f"tczyx_v{ver}_t2c1", store, lv, axes, 0, t=2, c=1, scales=scales)
        m.ok(f"tczyx_v{ver}_t1c0_l1", store, lv, axes, 1, t=1, c=0, scales=scales)
        m.err(str(store) + "#c=2", "INVALID_ARGUMENT", "channel 2 asked for, the image has 2 channels")
        m.err(store, "INVALID_ARGUMENT", "frame 3 asked for, the image has 3 time points", t=3)
        m.err(str(store) + "#level=2", "INVALID_ARGUMENT", "level 2 asked for, the image has 2")
    # c, z, y, x without t (channel first)
    axes = "czyx"
    data = ramp((3, 4, 5, 6), "int16", 7)
    lv = pyramid(data, 1, axes)
    store = write_store(out / "czyx.zarr", lv, axes, 2, "blosc", [2, 3, 3, 3], ".", "<")
    m.ok("czyx_c2", store, lv, axes, 0, c=2)
    # missing chunks read as fill_value
    for ver in (2, 3):
        axes = "zyx"
        data = ramp((8, 8, 8), "int16", 5)
        data[0:4, 4:8, 0:4] = -7  # chunk (0, 1, 0)
        data[4:8, 0:4, 4:8] = -7  # chunk (1, 0, 1)
        lv = [data]
        store = write_store(out / f"missing_v{ver}.zarr", lv, axes, ver, "gzip", [4, 4, 4], "/", "<", -7,
                            missing={(0, 1, 0), (1, 0, 1)})
        m.ok(f"missing_v{ver}", store, lv, axes, 0)
    # automatic level: the finest under the budget (level 0 needs 32768 B
    # of 16-bit texels, level 1 4096 B, level 2 512 B)
    axes = "zyx"
    data = ramp((32, 32, 16), "uint16", 3)
    lv = pyramid(data, 3, axes)
    store = write_store(out / "auto.zarr", lv, axes, 2, "zstd", [8, 8, 8])
    m.ok("auto_fits0", store, lv, axes, 0, fragment="")
    m.ok("auto_l1", store, lv, axes, 1, budget=20000, fragment="")
    m.ok("auto_l2", store, lv, axes, 2, budget=1000, fragment="")
    m.err(store, "LIMIT", "over the memory budget", budget=100)
    m.err(str(store) + "#level=0", "LIMIT", "needs 0.0 MiB, over the memory budget", budget=20000)
    # hostile or unsupported stores
    bad = out / "bad"
    data = ramp((4, 4, 4), "uint16", 1)

    def clone(name, **kw):
        args = dict(axes="zyx", version=2, codec="gzip", chunks=[2, 2, 2])
        args.update(kw)
        return write_store(bad / name, [data], **args)
    s = clone("json_broken")
    (s / "0" / ".zarray").write_text('{"zarr_format": 2, "shape": [4, 4,')
    m.err(s, "FORMAT", "not valid JSON")
    s = clone("json_deep")
    (s / ".zattrs").write_text("[" * 100000 + "]" * 100000)
    m.err(s, "FORMAT", "nested deeper than")
    s = clone("chunk_too_long")
    (s / "0" / "0" / "1" / "0").write_bytes(gzip.compress(bytes(2 * 8 + 2)))
    m.err(s, "FORMAT", "decompresses to more than the 16 bytes")
    s = clone("chunk_short", codec="zstd")
    (s / "0" / "1" / "1" / "1").write_bytes(zstd_compress(bytes(10)))
    m.err(s, "FORMAT", "decompresses to 10 bytes, not the 16")
    s = clone("chunk_corrupt", codec="blosc")
    p = s / "0" / "0" / "0" / "0"
    b = bytearray(p.read_bytes())
    b[12] ^= 0x7F  # the compressed size in blosc's header
    p.write_bytes(bytes(b))
    m.err(s, "FORMAT", "blosc")
    s = clone("raw_wrong_size", codec="raw")
    (s / "0" / "0" / "0" / "1").write_bytes(bytes(15))
    m.err(s, "FORMAT", "an uncompressed chunk of 15 bytes, not the 16")
    s = clone("chunk_huge_file", codec="raw")
    (s / "0" / "0" / "0" / "1").write_bytes(bytes(1 << 20))
    m.err(s, "FORMAT", "more than any encoding of the chunk's 16 bytes")
    s = clone("sharded", version=3)
    meta = json.loads((s / "0" / "zarr.json").read_text())
    meta["codecs"] = [{"name": "sharding_indexed", "configuration": {}}]
    (s / "0" / "zarr.json").write_text(json.dumps(meta))
    m.err(s, "FORMAT", "sharded arrays")
    s = write_store(bad / "two_d", [data[0]], axes="yx", version=2, codec="gzip")
    m.err(s, "FORMAT", "2D images are not volumes")
    s = clone("huge_shape")
    meta = json.loads((s / "0" / ".zarray").read_text())
    meta["shape"] = [1 << 40, 1 << 40, 1 << 40]
    (s / "0" / ".zarray").write_text(json.dumps(meta))
    m.err(str(s) + "#level=0", "LIMIT", "over the memory budget")
    s = clone("huge_chunk")
    meta = json.loads((s / "0" / ".zarray").read_text())
    meta["chunks"] = [1 << 20, 1 << 20, 1 << 20]
    (s / "0" / ".zarray").write_text(json.dumps(meta))
    m.err(s, "LIMIT", "a chunk of this array would be over")
    s = clone("chunk_over_budget")
    meta = json.loads((s / "0" / ".zarray").read_text())
    meta["chunks"] = [64, 64, 64]  # 512 KiB decoded for a 4x4x4 array
    (s / "0" / ".zarray").write_text(json.dumps(meta))
    m.err(s, "LIMIT", "one chunk needs 0.5 MiB, over the memory budget", budget=100000)
    s = clone("too_many_chunks")
    meta = json.loads((s / "0" / ".zarray").read_text())
    meta["shape"], meta["chunks"] = [1, 1 << 13, 1 << 13], [1, 1, 1]
    (s / "0" / ".zarray").write_text(json.dumps(meta))
    m.err(str(s) + "#level=0", "LIMIT", "chunks to read for one volume", budget=1 << 30)
    s = clone("bad_dtype")
    meta = json.loads((s / "0" / ".zarray").read_text())
    meta["dtype"] = "<c8"
    (s / "0" / ".zarray").write_text(json.dumps(meta))
    m.err(s, "FORMAT", "unsupported dtype '<c8'")
    s = clone("escape_path")
    attrs = json.loads((s / ".zattrs").read_text())
    attrs["multiscales"][0]["datasets"][0]["path"] = "../../etc"
    (s / ".zattrs").write_text(json.dumps(attrs))
    m.err(s, "FORMAT", "dataset 0 has no usable \"path\"")
    s = clone("shape_mismatch")
    meta = json.loads((s / "0" / ".zarray").read_text())
    meta["shape"], meta["chunks"] = [4, 4], [2, 2]
    (s / "0" / ".zarray").write_text(json.dumps(meta))
    m.err(s, "FORMAT", "2 dimensions, but the multiscales name 3 axes")
    m.write()


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: zarr_write.py OUTDIR")
    write_cases(sys.argv[1])
