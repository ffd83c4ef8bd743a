"""Seeds for fuzz_zarr (tests/fuzz/fuzz_zarr.c, whose first byte picks the
mode): the metadata and chunks of stores written by tests/zarr_write.py,
every codec and both Zarr versions. Usage: zarr_seeds.py OUTDIR."""
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from zarr_write import encode, write_store  # noqa: E402

DTYPES = ["uint8", "int8", "uint16", "int16", "uint32", "int32", "float32", "float64"]
CODECS = ["raw", "zlib", "zstd", "blosc"]


def main(out):
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    data = (np.arange(2 * 3 * 4, dtype=np.uint16) * 997).reshape(2, 3, 4)
    with tempfile.TemporaryDirectory() as tmp:
        for ver in (2, 3):
            for codec in ("gzip", "zstd", "blosc", "raw"):
                s = write_store(Path(tmp) / f"v{ver}_{codec}", [data, data[::2, ::2, ::2].copy()], "zyx", ver, codec,
                                [2, 3, 4])
                group = (s / ("zarr.json" if ver == 3 else ".zattrs")).read_bytes()
                array = (s / "0" / ("zarr.json" if ver == 3 else ".zarray")).read_bytes()
                (out / f"group_v{ver}_{codec}").write_bytes(bytes([ver - 2]) + group)
                (out / f"array_v{ver}_{codec}").write_bytes(bytes([2 + ver - 2]) + array)
                if ver == 2:
                    chunk = (s / "0" / "0" / "0" / "0").read_bytes()
                    one = write_store(Path(tmp) / f"one_{codec}", [data], "zyx", 2, codec, [2, 3, 4], ".")
                    store = ((one / ".zattrs").read_bytes() + b"\0" + (one / "0" / ".zarray").read_bytes() + b"\0"
                             + (one / "0" / "0.0.0").read_bytes())
                    (out / f"store_{codec}").write_bytes(bytes([5]) + store)
    # a group with an omero window per channel and axes in other units (the
    # streamed source's value range and the mm conversion), and a float
    # store whose source normalises over that window
    omero = (b'{"multiscales": [{"version": "0.4", "axes": [{"name": "c", "type": "channel"}, '
             b'{"name": "z", "type": "space", "unit": "nanometer"}, {"name": "y", "type": "space", "unit": "inch"}, '
             b'{"name": "x", "type": "space", "unit": "parsec"}], "datasets": [{"path": "0", '
             b'"coordinateTransformations": [{"type": "scale", "scale": [1, 2, 3, 4]}]}]}], '
             b'"omero": {"channels": [{"window": {"min": -5, "max": 7.5}}, {"window": {"start": 1, "end": 0}}]}}')
    (out / "group_v2_omero_units").write_bytes(bytes([0]) + omero)
    # omero channel names, colours, display windows and visibility (a
    # multi-channel read's metadata), good and malformed
    channels = (b'"omero": {"channels": [{"label": "DAPI", "color": "0000FF", "window": {"start": 10, "end": 500}, '
                b'"active": true}, {"label": "\\u00b5 GFP", "color": "#00ff00", "active": false}, '
                b'{"label": 7, "color": "GG0000", "window": {"start": 5, "end": 5}, "active": "yes"}]}}')
    (out / "group_v2_omero_channels").write_bytes(bytes([0]) + omero[:omero.index(b'"omero"')] + channels)
    with tempfile.TemporaryDirectory() as tmp:
        f = (np.arange(24, dtype=np.float32) - 7).reshape(2, 3, 4)
        one = write_store(Path(tmp) / "float", [f], "zyx", 2, "zlib", [2, 3, 4], ".")
        window = b', "omero": {"channels": [{"window": {"min": -3, "max": 9}}]}}'
        attrs = (one / ".zattrs").read_bytes().rstrip(b"}") + window
        store = attrs + b"\0" + (one / "0" / ".zarray").read_bytes() + b"\0" + (one / "0" / "0.0.0").read_bytes()
        (out / "store_float_window").write_bytes(bytes([5]) + store)
    # single chunks: codec, dtype, byte order, shape 2x3x4
    for ci, codec in enumerate(CODECS):
        for di, dt in enumerate(DTYPES):
            a = (np.arange(24) * 3).astype(dt)
            raw = a.tobytes()
            stored = encode("gzip" if codec == "zlib" else codec, raw, a.itemsize)
            (out / f"chunk_{codec}_{dt}").write_bytes(bytes([4, ci, di, 0, 1, 2, 3]) + stored)


if __name__ == "__main__":
    main(sys.argv[1])
