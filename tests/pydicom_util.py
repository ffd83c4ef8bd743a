"""What the pydicom-based DICOM writers of the tests share
(make_enhanced_dicom.py, make_colour_dicom.py): saving a data set as a Part
10 file with either pydicom, a frame through Debian's opj_compress, and an
HTJ2K frame through pip's imagecodecs (OpenJPH) in the venv build.sh makes
(build/imagecodecs), with the file saved under an HTJ2K transfer syntax."""
import os
import struct
import subprocess
import sys
import tempfile

import pydicom


def save(ds, out):
    """ds (with file_meta) written to out as explicit VR little endian."""
    if int(pydicom.__version__.split(".")[0]) >= 3:
        ds.save_as(out, enforce_file_format=True)
    else:  # pydicom 2 (Debian 12) takes the encoding from the data set
        ds.is_little_endian, ds.is_implicit_VR = True, False
        ds.save_as(out, write_like_original=False)


def j2k_frame(pnm):
    """A PGM/PPM image (bytes) as a lossless JPEG 2000 codestream from
    opj_compress (2 resolution levels: the test frames are small; three
    components get its reversible colour transform)."""
    with tempfile.TemporaryDirectory() as tmp:
        src, j2k = os.path.join(tmp, "f.pnm"), os.path.join(tmp, "f.j2k")
        ext = ".ppm" if pnm[:2] == b"P6" else ".pgm"
        os.rename(_write(src, pnm), src + ext)
        subprocess.run(["opj_compress", "-i", src + ext, "-o", j2k, "-n", "2"], check=True, capture_output=True)
        with open(j2k, "rb") as f:
            return f.read()


ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
HTJ2K_ENCODER = os.path.join(ROOT, "build", "imagecodecs", "bin", "python")
# Reads a PGM/PPM on stdin, writes its lossless HTJ2K codestream on stdout
# (three components get the reversible colour transform).
_HTJ2K = """import sys, numpy, imagecodecs
d = sys.stdin.buffer.read()
magic, size, top, px = d.split(b"\\n", 3)
w, h = map(int, size.split())
a = numpy.frombuffer(px, ">u2" if int(top) > 255 else "u1").astype(numpy.uint16 if int(top) > 255 else numpy.uint8)
a = a.reshape((h, w, 3) if magic == b"P6" else (h, w))
sys.stdout.buffer.write(imagecodecs.htj2k_encode(a))
"""


def htj2k_frame(pnm):
    """A PGM/PPM image (bytes, as j2k_frame takes) as a lossless HTJ2K
    codestream; fails naming build.sh when the encoder's venv is missing."""
    if not os.access(HTJ2K_ENCODER, os.X_OK):
        sys.exit("pydicom_util: no HTJ2K encoder at %s: run ./build.sh build (it installs pip's imagecodecs there)"
                 % HTJ2K_ENCODER)
    return subprocess.run([HTJ2K_ENCODER, "-c", _HTJ2K], input=pnm, check=True, capture_output=True).stdout


def save_htj2k(ds, frames, out, uid="1.2.840.10008.1.2.4.201"):
    """ds with the HTJ2K codestreams `frames` behind a basic offset table,
    saved under the HTJ2K transfer syntax uid (.201, .202 or .203). pydicom
    2 (Debian 12) refuses UIDs it does not know, so the file is written as
    JPEG 2000 (.90) and the meta header's UID (and its group length) then
    changed in place."""
    encapsulated(ds, frames, "1.2.840.10008.1.2.4.90")
    save(ds, out)
    with open(out, "rb") as f:
        d = bytearray(f.read())
    old = b"\x02\x00\x10\x00UI\x16\x001.2.840.10008.1.2.4.90"
    new_value = uid.encode() + b"\0" * (len(uid) % 2)
    at = d.index(old)
    d[at:at + len(old)] = b"\x02\x00\x10\x00UI" + struct.pack("<H", len(new_value)) + new_value
    group = d.index(b"\x02\x00\x00\x00UL\x04\x00") + 8
    struct.pack_into("<I", d, group, struct.unpack_from("<I", d, group)[0] + len(new_value) - 22)
    with open(out, "wb") as f:
        f.write(bytes(d))


def _write(path, data):
    with open(path, "wb") as f:
        f.write(data)
    return path


def encapsulated(ds, frames, uid):
    """ds's PixelData: the codestreams `frames` behind a basic offset table,
    under transfer syntax uid."""
    from pydicom.encaps import encapsulate
    ds.file_meta.TransferSyntaxUID = uid
    ds.PixelData = encapsulate(frames, has_bot=True)
    ds["PixelData"].is_undefined_length = True
    ds["PixelData"].VR = "OB"
