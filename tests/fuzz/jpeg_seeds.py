"""Seeds of the DICOM codec fuzz target's JPEG Lossless side
(tests/fuzz/fuzz_dicom_codecs.c, prefix as dicom_codec_input.h says):
slices written by tests/python/dicom_write.py, compressed by dcmtk's own
encoder (dcmcjpeg: SV1 and the other predictors), their one fragment cut
out of the file. Usage: jpeg_seeds.py OUTDIR"""
import struct
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "python"))
from dicom_write import write_dicom  # noqa: E402


def fragment(dcm):
    """The bytes of the first fragment after the basic offset table."""
    b = dcm.read_bytes()
    at = b.rindex(b"\xe0\x7f\x10\x00")  # (7FE0,0010), the last one: PixelData
    i = at + 12  # tag, VR OB, 2 reserved, undefined length
    n = struct.unpack("<I", b[i + 4:i + 8])[0]  # the offset table item
    i += 8 + n
    assert b[i:i + 4] == b"\xfe\xff\x00\xe0", "no fragment item"
    n = struct.unpack("<I", b[i + 4:i + 8])[0]
    return b[i + 8:i + 8 + n]


def main(out):
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(7)
    rows, cols = 12, 16
    yy, xx = np.mgrid[0:rows, 0:cols]
    images = {"smooth": (xx * 900 + yy * 400).astype(np.uint16),
              "noise": rng.integers(0, 65535, (rows, cols)).astype(np.uint16)}
    with tempfile.TemporaryDirectory() as tmp:
        for name, px in images.items():
            src = Path(tmp) / f"{name}.dcm"
            write_dicom(src, "1.2.3.4", px, 0.0)
            for tag, args in (("sv1", []), ("sv4", ["+el", "+sv", "4"]), ("sv7", ["+el", "+sv", "7"])):
                dst = Path(tmp) / f"{name}_{tag}.dcm"
                subprocess.run(["dcmcjpeg", *args, str(src), str(dst)], check=True)
                prefix = bytes([rows - 1, cols - 1, 1, 1])  # 2-byte pixels, JPEG
                (out / f"seed_{name}_{tag}").write_bytes(prefix + fragment(dst))


if __name__ == "__main__":
    main(sys.argv[1])
