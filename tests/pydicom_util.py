"""What the pydicom-based DICOM writers of the tests share
(make_enhanced_dicom.py, make_colour_dicom.py): saving a data set as a Part
10 file with either pydicom, and a frame through Debian's opj_compress."""
import os
import subprocess
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
