"""Writes one colour DICOM file (two frames, 8 bits a sample) with pydicom,
a writer independent of dcmtk and of our decoders.

usage: make_colour_dicom.py OUT rgb|rgb-planar|ybr|ybr422|j2k|htj2k|htj2k-rpcl|palette|palette8
       make_colour_dicom.py FOLDER series
       make_colour_dicom.py FOLDER raw RAW COLS ROWS SLICES

Pixel (i, j) of frame k is R = (40 i + 10 k) % 256, G = (50 j + 30) % 256,
B = (7 i j + k) % 256 (tests/test_dicom_frames.c computes the same), stored
as RGB (samples of a pixel together, or as planes), as full-range YCbCr
(YBR_FULL; YBR_FULL_422 with the chroma of each two pixels averaged), or as
JPEG 2000 frames from opj_compress, which applies its reversible colour
transform (YBR_RCT), or as HTJ2K frames from pip's imagecodecs (OpenJPH,
the same transform) under 1.2.840.10008.1.2.4.203 (HTJ2K) or .202 (HTJ2K
with RPCL Options), or as PALETTE COLOR: one index per pixel into red,
green and blue tables of the pattern's distinct colours, 4096 16-bit
entries from index 0 ("palette") or 8-bit entries packed two to a word
from index 10 ("palette8").

"series" writes frames 0, 1, 2 and 4 of the same pattern (frame 3 left out)
as single-frame RGB files 2 mm apart into FOLDER, named in the reverse of
their order along the normal and with InstanceNumber shuffled, so a reader
must sort them by position and fill the missing slice.

"raw" writes the RGB voxels of the file RAW (8 bits a sample, R G B of a
voxel together, x fastest, then y, then z) as single-frame RGB files, slice
k at z = k mm with 1 mm pixels, oriented so that voxel (i, j, k) lands at
RAS (i, j, k) as a reader turns DICOM's LPS into RAS: the same affine as a
NIfTI without transforms.
"""
import sys

import numpy as np
from pydicom.dataset import Dataset, FileMetaDataset
from pydicom.uid import ExplicitVRLittleEndian, generate_uid

from pydicom_util import encapsulated, htj2k_frame, j2k_frame, save, save_htj2k

COLS, ROWS, FRAMES = 8, 6, 2


def rgb_frames(frames=FRAMES):
    j, i = np.mgrid[0:ROWS, 0:COLS]
    return [np.stack([(40 * i + 10 * k) % 256, (50 * j + 30) % 256, (7 * i * j + k) % 256], -1).astype(np.uint8)
            for k in range(frames)]


def ycbcr(rgb):
    """Full-range YCbCr (PS3.3 C.7.6.3.1.2), rounded to 8 bits."""
    r, g, b = (rgb[..., c].astype(float) for c in range(3))
    y = 0.299 * r + 0.587 * g + 0.114 * b
    cb = -0.168736 * r - 0.331264 * g + 0.5 * b + 128
    cr = 0.5 * r - 0.418688 * g - 0.081312 * b + 128
    return np.clip(np.rint(np.stack([y, cb, cr], -1)), 0, 255).astype(np.uint8)


def series(folder):
    frames = rgb_frames(5)
    series_uid, study_uid = generate_uid(), generate_uid()
    for n, k in enumerate([0, 1, 2, 4]):
        ds = base("1.2.840.10008.5.1.4.1.1.7")  # Secondary Capture, one frame a file
        ds.StudyInstanceUID, ds.SeriesInstanceUID = study_uid, series_uid
        ds.Rows, ds.Columns, ds.SamplesPerPixel, ds.PlanarConfiguration = ROWS, COLS, 3, 0
        ds.BitsAllocated, ds.BitsStored, ds.HighBit, ds.PixelRepresentation = 8, 8, 7, 0
        ds.PixelSpacing, ds.SliceThickness = [1, 1], 2
        ds.ImagePositionPatient, ds.ImageOrientationPatient = [0, 0, 2 * k], [1, 0, 0, 0, 1, 0]
        ds.InstanceNumber = [3, 1, 4, 2][n]
        ds.PhotometricInterpretation = "RGB"
        ds.PixelData = frames[k].tobytes()
        save(ds, "%s/IM%d.dcm" % (folder, 9 - n))


def from_raw(folder, raw, cols, rows, slices):
    with open(raw, "rb") as f:
        data = np.frombuffer(f.read(), np.uint8).reshape(slices, rows, cols, 3)
    series_uid, study_uid = generate_uid(), generate_uid()
    for k in range(slices):
        ds = base("1.2.840.10008.5.1.4.1.1.7")
        ds.StudyInstanceUID, ds.SeriesInstanceUID = study_uid, series_uid
        ds.Rows, ds.Columns, ds.SamplesPerPixel, ds.PlanarConfiguration = rows, cols, 3, 0
        ds.BitsAllocated, ds.BitsStored, ds.HighBit, ds.PixelRepresentation = 8, 8, 7, 0
        ds.PixelSpacing, ds.SliceThickness = [1, 1], 1
        # LPS: rows along -x, columns along -y (RAS +x, +y), slices along +z
        ds.ImagePositionPatient, ds.ImageOrientationPatient = [0, 0, k], [-1, 0, 0, 0, -1, 0]
        ds.InstanceNumber = k + 1
        ds.PhotometricInterpretation = "RGB"
        ds.PixelData = data[k].tobytes()
        save(ds, "%s/IM%04d.dcm" % (folder, k))


def base(sop_class):
    meta = FileMetaDataset()
    meta.MediaStorageSOPClassUID = sop_class
    meta.MediaStorageSOPInstanceUID = generate_uid()
    meta.TransferSyntaxUID = ExplicitVRLittleEndian
    ds = Dataset()
    ds.file_meta = meta
    ds.SOPClassUID, ds.SOPInstanceUID = meta.MediaStorageSOPClassUID, meta.MediaStorageSOPInstanceUID
    ds.Modality = "OT"
    return ds


def main(out, mode):
    if mode == "series":
        return series(out)
    if mode == "raw":
        return from_raw(out, sys.argv[3], *map(int, sys.argv[4:7]))
    meta = FileMetaDataset()
    meta.MediaStorageSOPClassUID = "1.2.840.10008.5.1.4.1.1.7.3"  # Multi-frame True Color Secondary Capture
    meta.MediaStorageSOPInstanceUID = generate_uid()
    meta.TransferSyntaxUID = ExplicitVRLittleEndian
    ds = Dataset()
    ds.file_meta = meta
    ds.SOPClassUID, ds.SOPInstanceUID = meta.MediaStorageSOPClassUID, meta.MediaStorageSOPInstanceUID
    ds.Modality = "OT"
    ds.StudyInstanceUID, ds.SeriesInstanceUID = generate_uid(), generate_uid()
    ds.Rows, ds.Columns, ds.NumberOfFrames = ROWS, COLS, FRAMES
    ds.SamplesPerPixel = 3
    ds.BitsAllocated, ds.BitsStored, ds.HighBit, ds.PixelRepresentation = 8, 8, 7, 0
    ds.PixelSpacing, ds.SliceThickness = [1, 1], 2
    ds.ImagePositionPatient, ds.ImageOrientationPatient = [0, 0, 0], [1, 0, 0, 0, 1, 0]
    frames = rgb_frames()
    ds.PlanarConfiguration = 0
    if mode == "rgb":
        ds.PhotometricInterpretation = "RGB"
        data = b"".join(f.tobytes() for f in frames)
    elif mode == "rgb-planar":
        ds.PhotometricInterpretation, ds.PlanarConfiguration = "RGB", 1
        data = b"".join(np.moveaxis(f, -1, 0).tobytes() for f in frames)
    elif mode == "ybr":
        ds.PhotometricInterpretation = "YBR_FULL"
        data = b"".join(ycbcr(f).tobytes() for f in frames)
    elif mode == "ybr422":
        ds.PhotometricInterpretation = "YBR_FULL_422"
        parts = []
        for f in frames:
            y = ycbcr(f).astype(float).reshape(ROWS, COLS // 2, 2, 3)
            chroma = np.rint(y[..., 1:].mean(2))  # one Cb, Cr for each two pixels
            parts.append(np.concatenate([y[..., 0], chroma], -1).astype(np.uint8).tobytes())
        data = b"".join(parts)
    elif mode == "j2k":
        ds.PhotometricInterpretation = "YBR_RCT"
        ppm = [b"P6\n%d %d\n255\n" % (COLS, ROWS) + f.tobytes() for f in frames]
        encapsulated(ds, [j2k_frame(p) for p in ppm], "1.2.840.10008.1.2.4.90")
    elif mode in ("htj2k", "htj2k-rpcl"):
        ds.PhotometricInterpretation = "YBR_RCT"
        ppm = [b"P6\n%d %d\n255\n" % (COLS, ROWS) + f.tobytes() for f in frames]
        uid = "1.2.840.10008.1.2.4.203" if mode == "htj2k" else "1.2.840.10008.1.2.4.202"
        return save_htj2k(ds, [htj2k_frame(p) for p in ppm], out, uid)
    elif mode in ("palette", "palette8"):
        ds.PhotometricInterpretation, ds.SamplesPerPixel = "PALETTE COLOR", 1
        del ds.PlanarConfiguration
        flat = np.concatenate([f.reshape(-1, 3) for f in frames])
        colours, index = np.unique(flat, axis=0, return_inverse=True)
        first = 10 if mode == "palette8" else 0
        bits = 8 if mode == "palette8" else 16
        if bits == 16:  # tables longer than a header read (dcmtk loads them when asked)
            colours = np.concatenate([colours, np.zeros((4096 - len(colours), 3), colours.dtype)])
        for name, c in zip(("Red", "Green", "Blue"), range(3)):
            setattr(ds, name + "PaletteColorLookupTableDescriptor", [len(colours), first, bits])
            entries = colours[:, c].astype(np.uint16)
            if bits == 8:
                data = entries.astype(np.uint8).tobytes()
                data += b"\0" * (len(data) % 2)
            else:
                data = (entries * 257).astype("<u2").tobytes()
            setattr(ds, name + "PaletteColorLookupTableData", data)
        data = (index.reshape(-1) + first).astype(np.uint8).tobytes()
    else:
        sys.exit("make_colour_dicom: unknown mode %s" % mode)
    if mode != "j2k":
        ds.PixelData = data
    save(ds, out)


if __name__ == "__main__":
    main(*sys.argv[1:3])
