"""Writes one Enhanced CT file (multi-frame, functional groups) with pydicom,
a writer independent of the dcmtk we read with and of our C test writer.

usage: make_enhanced_dicom.py OUT COLS ROWS SLICES TIMES IOP(6) ORIGIN(3) STEP(3) SEED [j2k|htj2k|stacks|rgb]

Frame (k, t): slice k at ORIGIN + k * STEP, time point t; pixel (i, j) holds
1000 t + 100 k + 10 j + i, as tests/test_dicom_frames.c's single-frame copy
does. The frames are stored in an order shuffled by SEED, each with its own
Plane Position and Frame Content (TemporalPositionIndex t + 1 when TIMES > 1);
orientation, pixel measures and the rescale are in the shared groups.
With stacks, the TIMES groups are stacks instead (StackID t + 1, no
temporal index): one file holding several volumes. With j2k, each frame is a JPEG 2000 codestream from Debian's opj_compress
(lossless, 2 resolution levels: the frames are small), encapsulated with a basic offset table (transfer syntax
1.2.840.10008.1.2.4.90): an encoder independent of our decoder.
With htj2k, the same frames are lossless HTJ2K codestreams from pip's
imagecodecs (OpenJPH; tests/pydicom_util.py) under transfer syntax
1.2.840.10008.1.2.4.201 (HTJ2K Lossless Only).
With rgb, the frames are 8-bit RGB (samples of a pixel together) whose
pixel (i, j) of frame (k, t) is R = (10 j + i) mod 256, G = (40 k + 5) mod
256, B = (90 t + 7 k) mod 256, as tests/test_dicom_frames.c computes them.
"""

import random
import sys

import numpy as np
from pydicom.dataset import Dataset, FileMetaDataset
from pydicom.sequence import Sequence
from pydicom.uid import ExplicitVRLittleEndian, generate_uid

from pydicom_util import encapsulated, htj2k_frame, j2k_frame, save, save_htj2k


def item(**kw):
    d = Dataset()
    for k, v in kw.items():
        setattr(d, k, v)
    return d


def pgm(pixels):
    rows, cols = pixels.shape
    return b"P5\n%d %d\n65535\n" % (cols, rows) + pixels.astype(">u2").tobytes()


def main(argv):
    out, cols, rows, slices, times = argv[0], *map(int, argv[1:5])
    iop = [float(x) for x in argv[5:11]]
    origin = [float(x) for x in argv[11:14]]
    step = [float(x) for x in argv[14:17]]
    rng = random.Random(int(argv[17]))
    frames = [(k, t) for k in range(slices) for t in range(times)]
    rng.shuffle(frames)

    meta = FileMetaDataset()
    meta.MediaStorageSOPClassUID = "1.2.840.10008.5.1.4.1.1.2.1"  # Enhanced CT Image Storage
    meta.MediaStorageSOPInstanceUID = generate_uid()
    meta.TransferSyntaxUID = ExplicitVRLittleEndian
    ds = Dataset()
    ds.file_meta = meta
    ds.SOPClassUID = meta.MediaStorageSOPClassUID
    ds.SOPInstanceUID = meta.MediaStorageSOPInstanceUID
    ds.Modality = "CT"
    ds.SeriesDescription = "enhanced test"
    ds.StudyInstanceUID = generate_uid()
    ds.SeriesInstanceUID = generate_uid()
    ds.InstanceNumber = 1
    ds.Rows, ds.Columns = rows, cols
    mode = argv[18] if len(argv) > 18 else ""
    ds.SamplesPerPixel = 1
    ds.PhotometricInterpretation = "MONOCHROME2"
    ds.BitsAllocated, ds.BitsStored, ds.HighBit, ds.PixelRepresentation = 16, 16, 15, 0
    if mode == "rgb":
        ds.SamplesPerPixel, ds.PlanarConfiguration, ds.PhotometricInterpretation = 3, 0, "RGB"
        ds.BitsAllocated, ds.BitsStored, ds.HighBit = 8, 8, 7
    ds.NumberOfFrames = len(frames)
    ds.SharedFunctionalGroupsSequence = Sequence([item(
        PlaneOrientationSequence=Sequence([item(ImageOrientationPatient=iop)]),
        PixelMeasuresSequence=Sequence([item(PixelSpacing=[1.0, 1.0], SliceThickness=1.0)]),
        PixelValueTransformationSequence=Sequence([item(RescaleIntercept=-1024, RescaleSlope=1,
                                                        RescaleType="HU")]),
    )])
    per_frame, pixels = [], []
    j, i = np.mgrid[0:rows, 0:cols]
    for k, t in frames:
        content = item(StackID=str(t + 1) if mode == "stacks" else "1", InStackPositionNumber=k + 1)
        if times > 1 and mode != "stacks":
            content.TemporalPositionIndex = t + 1
        per_frame.append(item(
            PlanePositionSequence=Sequence([item(ImagePositionPatient=[origin[a] + k * step[a] for a in range(3)])]),
            FrameContentSequence=Sequence([content]),
        ))
        if mode == "rgb":
            rgb = [(10 * j + i) % 256, np.full_like(i, (40 * k + 5) % 256), np.full_like(i, (90 * t + 7 * k) % 256)]
            pixels.append(np.stack(rgb, -1).astype(np.uint8))
        else:
            pixels.append((1000 * t + 100 * k + 10 * j + i).astype("<u2"))
    ds.PerFrameFunctionalGroupsSequence = Sequence(per_frame)
    if mode == "htj2k":
        return save_htj2k(ds, [htj2k_frame(pgm(p)) for p in pixels], out)
    if mode == "j2k":  # JPEG 2000 Image Compression (Lossless Only)
        encapsulated(ds, [j2k_frame(pgm(p)) for p in pixels], "1.2.840.10008.1.2.4.90")
    else:
        ds.PixelData = np.stack(pixels).tobytes()
    save(ds, out)


if __name__ == "__main__":
    main(sys.argv[1:])
