"""Which lookup files beside a label image could name its labels:
the importer offers the first that exists, and the library
(vxl_label_table_load, docs/labels.md) tells the formats apart by content.

Pure Python, no bpy, no library: only names and, for find_lookup_files,
whether files exist."""

import os

# Image extensions whose stem names a lookup file (".gz" comes off first).
IMAGE_EXTENSIONS = (".nii", ".nrrd", ".nhdr", ".mha", ".mhd", ".mgz", ".mgh", ".img", ".hdr",
                    ".tif", ".tiff", ".vdb", ".dcm")

# Per stem, in priority order: MRIcron's palette first (it brings the .txt
# of the same stem with it), then its names alone (or any text table named
# so), Slicer, ITK-SNAP, and the LUT.txt spellings FreeSurfer users give.
STEM_SUFFIXES = (".lut", ".txt", ".ctbl", ".label", "LUT.txt", "_LUT.txt", "-LUT.txt",
                 "_ColorTable.ctbl", "_labels.txt", ".labels.txt")

# Folder-wide tables, after every same-stem candidate: FreeSurfer's own LUT
# (copied next to a subject's aseg/aparc), ITK-SNAP's usual export names.
FOLDER_NAMES = ("FreeSurferColorLUT.txt", "label_descriptions.txt", "labels.txt", "labels.label",
                "labels.ctbl")


def image_stems(image_path):
    """The stems a lookup file beside image_path may be named after, most
    specific first: "aal.nii.gz" -> ["aal.nii", "aal"] (mricron-data names
    aal.nii.lut and aal.nii.txt), "Segmentation.seg.nrrd" ->
    ["Segmentation.seg.nrrd", "Segmentation.seg", "Segmentation"]."""
    name = os.path.basename(image_path.rstrip(os.sep))
    if name.lower().endswith(".gz"):
        name = name[:-3]
    stems = [name]
    lower = name.lower()
    for ext in IMAGE_EXTENSIONS:
        if lower.endswith(ext) and len(name) > len(ext):
            stems.append(name[:-len(ext)])
            break
    if stems[-1].lower().endswith(".seg") and len(stems[-1]) > 4:
        stems.append(stems[-1][:-4])
    return [s for i, s in enumerate(stems) if s and s not in stems[:i]]


def candidate_lookup_files(image_path):
    """Every lookup file name worth trying for a label image, as paths in
    its folder, in priority order, whether or not they exist (the image
    itself excluded)."""
    folder = os.path.dirname(os.path.abspath(image_path))
    image = os.path.basename(image_path.rstrip(os.sep))
    names = [stem + suffix for stem in image_stems(image_path) for suffix in STEM_SUFFIXES]
    names += list(FOLDER_NAMES)
    out, seen = [], set()
    for n in names:
        if n != image and n not in seen:
            seen.add(n)
            out.append(os.path.join(folder, n))
    return out


def find_lookup_files(image_path, exists=os.path.isfile):
    """The candidates that exist, in priority order ([] when none does).
    exists is the test for one path (injectable for tests)."""
    return [p for p in candidate_lookup_files(image_path) if exists(p)]
