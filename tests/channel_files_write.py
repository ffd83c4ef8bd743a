"""Writes the multi-channel files of the helper-process and MetaImage readers
(docs/channels.md "Loading") from numpy arrays, independently of the C
readers: an OME-Zarr store with a c axis and "omero" metadata (through
tests/zarr_write.py), TIFFs with several samples a pixel, an OME-TIFF whose
OME-XML puts its channels in separate pages, and a MetaImage of interleaved
channels. The TIFF writer is written here from the TIFF 6.0 tags (no
tifffile on Debian 12), uncompressed and little-endian.

`python3 tests/channel_files_write.py OUTDIR` writes the files
tests/test_channel_readers.c reads, each beside NAME.u16 (or .f32): its
channels planar, (C, Z, Y, X) with y pointing up as the volume's j axis does,
the voxels the reader must return. tests/cli/test_cli_channels.py imports the
writers."""
import json
import struct
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from zarr_write import write_store  # noqa: E402

TIFF_TYPES = {np.dtype("uint8"): 1, np.dtype("uint16"): 1, np.dtype("int16"): 2, np.dtype("float32"): 3}
# OME's DimensionOrder for each way write_ome_tiff orders the pages
OME_TYPES = {np.dtype("uint8"): "uint8", np.dtype("uint16"): "uint16", np.dtype("int16"): "int16",
             np.dtype("float32"): "float"}


def channel_data(c, shape, dtype, seed):
    """Channel c of a deterministic stack: a ball at a place of its own over
    a ramp, so a channel swap, a transposition or a flip shows."""
    rng = np.random.default_rng(seed + c)
    z, y, x = np.indices(shape, dtype=np.float64)
    centre = [(0.3 + 0.2 * ((c + k) % 3)) * s for k, s in enumerate(shape)]
    r = np.sqrt(sum((g - m) ** 2 for g, m in zip((z, y, x), centre)))
    v = 40.0 * (r < min(shape) * 0.35) + x + 2 * y + 3 * z + rng.integers(0, 5, shape)
    return (v * (c + 1)).astype(dtype)


def stack(channels, shape, dtype, seed=1):
    """(C, Z, Y, X): every channel's voxels, y up (volume order)."""
    return np.stack([channel_data(c, shape, dtype, seed) for c in range(channels)])


def write_tiff(path, pages, samples=1, description=None, photometric=1):
    """A little-endian TIFF of uncompressed pages; each page is (rows top
    first, cols) for one sample, or (rows, cols, samples) interleaved
    (PlanarConfiguration 1). photometric: 1 BlackIsZero, 2 RGB. A sample
    beyond the photometric's own is an ExtraSamples entry of 0
    (unspecified), as microscopes write them. description: the first page's
    ImageDescription (OME-XML)."""
    dt = pages[0].dtype
    bits = dt.itemsize * 8
    out = bytearray(b"II*\0\0\0\0\0")
    prev = 4
    own = 3 if photometric == 2 else 1

    def blob(data):
        at = len(out)
        out.extend(data)
        if len(out) % 2:
            out.extend(b"\0")
        return at
    for k, p in enumerate(pages):
        h, w = p.shape[:2]
        data_at = blob(p.astype(dt.newbyteorder("<")).tobytes())
        desc_at = blob(description.encode() + b"\0") if description and k == 0 else 0
        bits_at = blob(struct.pack("<%dH" % samples, *([bits] * samples))) if samples > 2 else 0
        fmt_at = blob(struct.pack("<%dH" % samples, *([TIFF_TYPES[dt]] * samples))) if samples > 2 else 0
        extra = samples - own
        extra_at = blob(struct.pack("<%dH" % extra, *([0] * extra))) if extra > 2 else 0

        def short_array(values_at, count, value):
            # one or two SHORTs fit the entry; more live at values_at
            if count > 2:
                return (3, count, struct.pack("<I", values_at))
            return (3, count, struct.pack("<%dH" % count, *([value] * count)).ljust(4, b"\0"))
        entries = [(256, 4, 1, struct.pack("<I", w)), (257, 4, 1, struct.pack("<I", h)),
                   (258, *short_array(bits_at, samples, bits)), (259, 3, 1, struct.pack("<HH", 1, 0)),
                   (262, 3, 1, struct.pack("<HH", photometric, 0))]
        if desc_at:
            entries.append((270, 2, len(description.encode()) + 1, struct.pack("<I", desc_at)))
        entries += [(273, 4, 1, struct.pack("<I", data_at)), (277, 3, 1, struct.pack("<HH", samples, 0)),
                    (278, 4, 1, struct.pack("<I", h)), (279, 4, 1, struct.pack("<I", p.nbytes)),
                    (284, 3, 1, struct.pack("<HH", 1, 0))]
        if extra > 0:
            entries.append((338, *short_array(extra_at, extra, 0)))
        entries.append((339, *short_array(fmt_at, samples, TIFF_TYPES[dt])))
        ifd = len(out)
        struct.pack_into("<I", out, prev, ifd)
        out += struct.pack("<H", len(entries))
        for tag, typ, count, value in entries:
            out += struct.pack("<HHI", tag, typ, count) + value
        prev = len(out)
        out += b"\0\0\0\0"
    Path(path).write_bytes(bytes(out))


def write_sample_tiff(path, vol):
    """vol (C, Z, Y, X), y up: one page a slice, the channels as samples."""
    pages = [np.ascontiguousarray(np.moveaxis(vol[:, z, ::-1, :], 0, -1)) for z in range(vol.shape[1])]
    write_tiff(path, pages, samples=vol.shape[0])


def ome_color(rgb):
    """OME-XML's Color: 0xRRGGBBAA as a signed 32-bit integer."""
    v = (rgb[0] << 24) | (rgb[1] << 16) | (rgb[2] << 8) | 0xFF
    return v - (1 << 32) if v >= 1 << 31 else v


def write_ome_tiff(path, vol, names, colors, order="XYZCT"):
    """vol (C, Z, Y, X), y up: an OME-TIFF of one page a (z, c) plane, the
    pages in `order` (XYZCT: z fastest, XYCZT: c fastest), each channel's
    Name and Color in the OME-XML."""
    c_n, z_n, y_n, x_n = vol.shape
    chans = "".join('<Channel ID="Channel:0:%d" Name="%s" Color="%d" SamplesPerPixel="1"/>'
                    % (c, names[c], ome_color(colors[c])) for c in range(c_n))
    xml = ('<?xml version="1.0" encoding="UTF-8"?><OME xmlns="http://www.openmicroscopy.org/Schemas/OME/2016-06">'
           '<Image ID="Image:0" Name="cells"><Pixels ID="Pixels:0" DimensionOrder="%s" Type="%s" SizeX="%d" '
           'SizeY="%d" SizeZ="%d" SizeC="%d" SizeT="1" PhysicalSizeX="0.5" PhysicalSizeY="0.5" '
           'PhysicalSizeZ="2.0">%s<TiffData/></Pixels></Image></OME>'
           % (order, OME_TYPES[vol.dtype], x_n, y_n, z_n, c_n, chans))
    planes = [(c, z) for z in range(z_n) for c in range(c_n)] if order == "XYCZT" else \
        [(c, z) for c in range(c_n) for z in range(z_n)]
    write_tiff(path, [np.ascontiguousarray(vol[c, z, ::-1, :]) for c, z in planes], description=xml)


def write_mha(path, vol):
    """vol (C, Z, Y, X): MetaImage with ElementNumberOfChannels, each voxel's
    channels together."""
    kind = {np.dtype("uint8"): "MET_UCHAR", np.dtype("uint16"): "MET_USHORT", np.dtype("int16"): "MET_SHORT",
            np.dtype("float32"): "MET_FLOAT"}[vol.dtype]
    c, z, y, x = vol.shape
    hdr = ("ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = False\n"
           "CompressedData = False\nElementSpacing = 0.5 0.5 2\nElementNumberOfChannels = %d\n"
           "DimSize = %d %d %d\nElementType = %s\nElementDataFile = LOCAL\n" % (c, x, y, z, kind))
    raw = np.moveaxis(vol, 0, -1).astype(vol.dtype.newbyteorder("<")).tobytes()
    Path(path).write_bytes(hdr.encode() + raw)


def write_omero_zarr(path, vol, names, colors, windows, active):
    """vol (C, Z, Y, X): an OME-Zarr v0.4 store with axes c, z, y, x and its
    omero channels (colors as RRGGBB)."""
    root = write_store(path, [vol], "czyx", version=2, codec="zstd", chunks=[1, 4, 4, 4])
    attrs = json.loads((root / ".zattrs").read_text())
    attrs["omero"] = {"channels": [{"label": names[c], "color": "%02X%02X%02X" % tuple(colors[c]),
                                    "window": {"min": 0, "max": 65535, "start": windows[c][0],
                                               "end": windows[c][1]},
                                    "active": active[c]} for c in range(vol.shape[0])]}
    (root / ".zattrs").write_text(json.dumps(attrs))
    return root


NAMES = ["DAPI", "GFP", "mCherry", "Cy5", "BF"]
COLORS = [(0, 0, 255), (0, 255, 0), (255, 0, 255), (255, 128, 0), (255, 255, 255)]


def write_cases(out):
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    shape = (5, 6, 7)  # z, y, x

    def keep(name, vol):
        vol.astype("<" + vol.dtype.str[1:]).tofile(out / ("%s.%s" % (name, "f32" if vol.dtype.kind == "f" else "u16")))
    vol = stack(3, shape, np.uint16)
    write_omero_zarr(out / "omero.zarr", vol, NAMES, COLORS, [(10, 500), (20, 600), (30, 700)], [True, False, True])
    keep("omero", vol)
    vol = stack(5, shape, np.uint16, seed=3)
    write_mha(out / "five.mha", vol)
    keep("five", vol)
    vol = stack(2, shape, np.uint16, seed=5)
    write_sample_tiff(out / "two_samples.tif", vol)
    keep("two_samples", vol)
    vol = stack(3, shape, np.uint16, seed=7)
    write_sample_tiff(out / "three_samples.tif", vol)
    keep("three_samples", vol)
    vol = stack(3, shape, np.uint16, seed=9)
    write_ome_tiff(out / "cells.ome.tif", vol, NAMES, COLORS, "XYZCT")
    write_ome_tiff(out / "cells_czt.ome.tif", vol, NAMES, COLORS, "XYCZT")
    keep("cells", vol)


if __name__ == "__main__":
    write_cases(sys.argv[1])
