"""How the importer treats a label image (issue 20): whether a file is a
label map and which lookup file names its labels. Pure Python, no bpy
(tests/python/test_label_import.py); the importer asks it before and after
the load."""

import os

from . import label_files

MAX_LABEL_ID = 65535  # VXL_MAX_LABEL_ID (native_abi.MAX_LABEL_ID; no ctypes here)

# The data types vxl_renderer_set_labels takes (voxlight.h); library names.
LABEL_DTYPES = ("uint8", "uint16", "int16", "int32")

# The importer's "Import as" choices (identifier, name, description).
IMPORT_MODES = (
    ("AUTO", "Detect", "Labels when an integer volume has a lookup file beside it "
                       "(as a new labels object), else an intensity volume"),
    ("INTENSITY", "Intensity Volume", "An ordinary volume, even with a lookup file beside it"),
    ("NEW", "New Labels Object", "A labels-only volume object: each label shaded as a surface"),
    ("ATTACH", "Label Map of Active Volume", "Attach the labels to the active volume object "
                                             "(its transfer function tinted per label)"),
)


def is_label_dtype(dtype):
    return str(dtype) in LABEL_DTYPES


def lookup_file(image_path, chosen="", exists=os.path.isfile):
    """The lookup file for image_path: `chosen` when given (even if it is
    missing, so the caller reports it), else the first found beside the
    image, else ""."""
    if chosen:
        return chosen
    found = label_files.find_lookup_files(image_path, exists=exists)
    return found[0] if found else ""


def plan(mode, image_path, chosen_lookup="", exists=os.path.isfile):
    """Before the load: ("intensity" | "new" | "attach", lookup path).
    AUTO picks "new" when a lookup file is beside the image; the data type
    is checked after the load (check)."""
    lut = lookup_file(image_path, chosen_lookup, exists)
    if mode == "INTENSITY":
        return "intensity", ""
    if mode == "AUTO":
        return ("new", lut) if lut else ("intensity", "")
    return ("attach" if mode == "ATTACH" else "new"), lut


def check(kind, mode, dtype, lookup, image_path, exists=os.path.isfile, value_range=None):
    """After the load: (kind, error). AUTO falls back to an intensity volume
    for a non-integer file; an explicit labels import of one, or without a
    lookup file, is an error (labels not listed in a lookup table are
    hidden, so nothing would show)."""
    if kind == "intensity":
        return kind, ""
    name = os.path.basename(image_path.rstrip(os.sep))
    if not is_label_dtype(dtype):
        if mode == "AUTO":
            return "intensity", ""
        return kind, ("%s holds %s data, not label ids (a label map is %s)"
                      % (name, dtype, ", ".join(LABEL_DTYPES)))
    if value_range is not None and not (0 <= value_range[0] and value_range[1] <= MAX_LABEL_ID):
        if mode == "AUTO":
            return "intensity", ""
        return kind, ("%s holds values %g..%g; label ids are 0..%d"
                      % (name, value_range[0], value_range[1], MAX_LABEL_ID))
    if not lookup:
        return kind, "no lookup file beside %s (tried %s, ...)" % (
            name, ", ".join(os.path.basename(p) for p in label_files.candidate_lookup_files(image_path)[:3]))
    if not exists(lookup):
        return kind, "lookup file %s not found" % lookup
    return kind, ""
