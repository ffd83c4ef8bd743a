"""How the importer treats a label image: whether a file is a
label map and which lookup file names its labels, and how its info line
reads. Pure Python, no bpy (tests/python/test_label_import.py); the
importer asks it before and after the load."""

import os

from . import label_files

MAX_LABEL_ID = 65535  # VXL_MAX_LABEL_ID (native_abi.MAX_LABEL_ID; no ctypes here)

# The data types vxl_renderer_set_labels takes (voxlight.h); library names.
LABEL_DTYPES = ("uint8", "uint16", "int16", "int32")

# The importer's "Import as" choices (identifier, name, description).
IMPORT_MODES = (
    ("AUTO", "Detect", "Labels when an integer volume has a lookup file beside it that "
                       "names most of its values (as a new labels object), else an intensity volume"),
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


# How much of a volume's distinct non-zero values a lookup file must name
# before AUTO takes the volume as its label map. A file named after the
# image was made for it, so "most" suffices; a folder-wide table (labels.txt,
# FreeSurferColorLUT.txt) may belong to another image in the folder, so it
# must name nearly all of them. An intensity volume has hundreds of values
# and a small table names few of them; a segmentation's ids are all named.
SAME_STEM_COVERAGE = 0.5
FOLDER_COVERAGE = 0.9
MAX_DISTINCT_BINS = MAX_LABEL_ID + 1  # a histogram bin per possible id, at most


def distinct_ids(info, histogram):
    """The distinct values of an integer volume whose values could be label
    ids (0..MAX_LABEL_ID), as a sorted list of ints, else None. histogram
    is Volume.histogram(bins, lo, hi): one bin per integer value."""
    if not is_label_dtype(info.get("dtype")):
        return None
    lo, hi = info.get("value_min"), info.get("value_max")
    if lo is None or hi is None or not (0 <= lo <= hi <= MAX_LABEL_ID):
        return None
    lo, hi = int(round(lo)), int(round(hi))
    bins = hi - lo + 1
    if bins > MAX_DISTINCT_BINS:
        return None
    counts = histogram(bins, lo - 0.5, hi + 0.5)
    return [lo + i for i, c in enumerate(counts) if c > 0]


def candidates(image_path, chosen="", exists=os.path.isfile):
    """[(lookup path, specific)] for guess(): the file the user chose (it
    counts as made for the image), else every one found beside the image;
    specific: named after the image (aal.nii.lut for aal.nii.gz) rather
    than a folder-wide table."""
    if chosen:
        return [(chosen, True)]
    return [(p, os.path.basename(p) not in label_files.FOLDER_NAMES)
            for p in label_files.find_lookup_files(image_path, exists=exists)]


def coverage(ids, named):
    """(named, total): how many of the volume's non-zero ids `named` names
    (0 is the background, never a label)."""
    present = [i for i in ids if i != 0]
    names = set(named)
    return sum(1 for i in present if i in names), len(present)


def guess(dtype, ids, found, read_ids):
    """AUTO's decision after the load: (kind "new" | "intensity", lookup
    path or "", why: a sentence for the import report).
    ids: distinct_ids of the volume (None: not integer label ids).
    found: candidates(), in priority order.
    read_ids(path): the ids a lookup file names, or None when it is none."""
    if ids is None:
        if not is_label_dtype(dtype):
            return "intensity", "", "%s data hold no label ids" % dtype
        return "intensity", "", "its values are no label ids (0..%d)" % MAX_LABEL_ID
    if not found:
        return "intensity", "", "no lookup file beside it"
    why = []
    for path, same in found:
        named = read_ids(path)
        base = os.path.basename(path)
        if named is None:
            why.append("%s is no lookup file" % base)
            continue
        n, total = coverage(ids, named)
        need = SAME_STEM_COVERAGE if same else FOLDER_COVERAGE
        where = "named after it" if same else "folder-wide"
        if total and n >= need * total:
            return "new", path, "%s (%s) names %d of its %d values" % (base, where, n, total)
        why.append("%s (%s) names %d of its %d values, under %d%%" % (
            base, where, n, total, round(need * 100)))
    return "intensity", "", "; ".join(why)


def values_line(data_min, data_max, kind_text, label_count=None):
    """The volume panel's line about its values: "Values LO .. HI, KIND" for
    an intensity volume; for a label map (label_count not None: how many
    labels it has) its ids are names, not measurements, so "label map, N
    labels" instead of their range and units."""
    if label_count is not None:
        n = int(label_count)
        return "label map, %d label%s" % (n, "" if n == 1 else "s")
    line = "Values %.4g .. %.4g" % (data_min, data_max)
    return "%s, %s" % (line, kind_text) if kind_text else line


def label_count(listed, ids=None, data_max=None):
    """How many labels a label map has: the non-zero ids it holds (`ids`,
    its distinct values, when known), else the entries of its lookup list
    (`listed`, the background left out), else ids 1 .. data_max (the
    palette the library gives a map without a table)."""
    if ids is not None:
        return sum(1 for i in ids if i != 0)
    if listed:
        return int(listed)
    return max(0, int(round(data_max or 0)))
