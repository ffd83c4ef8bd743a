"""Minimal DICOM writer (plain Python, PS3.10 explicit VR little endian) for
test inputs, independent of dcmtk (which the library reads with) and of the C
test writer (tests/fuzz/dicom_writer.h)."""

import struct
from pathlib import Path


def _elem(group, elem, vr, value):
    if isinstance(value, str):
        value = value.encode()
        if len(value) % 2:
            value += b"\0" if vr == "UI" else b" "
    elif len(value) % 2:
        value += b"\0"
    if vr in ("OB", "OW"):
        return struct.pack("<HH2sHI", group, elem, vr.encode(), 0, len(value)) + value
    return struct.pack("<HH2sH", group, elem, vr.encode(), len(value)) + value


def write_dicom(path, uid, pixels, z, modality="CT", inter=-1024.0, spacing=(0.8, 0.6)):
    """One axial slice (pixels: rows x cols uint16) at height z."""
    rows, cols = pixels.shape
    meta = (_elem(2, 1, "OB", b"\0\1") + _elem(2, 2, "UI", "1.2.840.10008.5.1.4.1.1.2")
            + _elem(2, 3, "UI", f"{uid}.{int(z * 10)}") + _elem(2, 0x10, "UI", "1.2.840.10008.1.2.1"))
    us = lambda g, e, v: _elem(g, e, "US", struct.pack("<H", v))  # noqa: E731
    ds = (_elem(8, 0x60, "CS", modality) + _elem(8, 0x103E, "LO", f"{modality} test")
          + _elem(0x20, 0xE, "UI", uid) + _elem(0x20, 0x32, "DS", f"0\\0\\{z}")
          + _elem(0x20, 0x37, "DS", "1\\0\\0\\0\\1\\0") + us(0x28, 2, 1) + _elem(0x28, 4, "CS", "MONOCHROME2")
          + us(0x28, 0x10, rows) + us(0x28, 0x11, cols) + _elem(0x28, 0x30, "DS", f"{spacing[0]}\\{spacing[1]}")
          + us(0x28, 0x100, 16) + us(0x28, 0x101, 16) + us(0x28, 0x102, 15) + us(0x28, 0x103, 0)
          + _elem(0x28, 0x1052, "DS", str(inter)) + _elem(0x28, 0x1053, "DS", "1")
          + _elem(0x7FE0, 0x10, "OW", pixels.astype("<u2").tobytes()))
    group_len = _elem(2, 0, "UL", struct.pack("<I", len(meta)))
    Path(path).write_bytes(b"\0" * 128 + b"DICM" + group_len + meta + ds)
