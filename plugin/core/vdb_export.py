"""What Convert to Blender Volume does without bpy: the grid's size for a
resolution, its memory against the budget, and the OpenVDB file written by
the helper program voxlight-write-vdb (csrc/io/vdb_write.h: the stream on
its standard input), which ships beside the library where the platform has
OpenVDB (platform_rules: not on Windows)."""

import os
import struct
import subprocess

import numpy as np

from . import budget_split, platform_rules
from .native_private_copy import restore_execute_bit

STREAM_MAGIC = b"VXLVDBW1"
# Bytes per cell while converting: the library's density and colour (16),
# the writer's own copy of them read from the pipe (16) and OpenVDB's tree
# of the cells that hold something (up to 16 more: a float and three, in
# leaves of 8^3 cells).
BYTES_PER_CELL = 48


class ExportError(RuntimeError):
    """A conversion the add-on refuses or that failed, with the reason to show."""


def grid_dims(volume_dims, resolution):
    """Cells per axis: the volume's own voxels for resolution 0, else
    `resolution` cells along the longest axis and the others in proportion
    (at least 1)."""
    dims = [int(d) for d in volume_dims]
    if not resolution:
        return tuple(dims)
    scale = float(resolution) / max(dims)
    return tuple(max(1, int(round(d * scale))) for d in dims)


def check_budget(dims, volume_bytes, budget_bytes):
    """Raises ExportError when the grid, the CPU copy of the volume it is
    classified from and the writer's copy would exceed the memory budget
    (bytes; 0 = the library's default, as the renderer's)."""
    budget = int(budget_bytes) or budget_split.DEFAULT_BUDGET
    cells = int(np.prod(dims, dtype=np.int64))
    need = cells * BYTES_PER_CELL + int(volume_bytes)
    if need > budget:
        raise ExportError(
            "a %d x %d x %d grid needs about %d MiB (%d bytes per cell plus the volume's %d MiB), over the "
            "memory budget of %d MiB: lower Resolution or raise Scene > Voxlight > Memory Budget"
            % (dims[0], dims[1], dims[2], need >> 20, BYTES_PER_CELL, int(volume_bytes) >> 20, budget >> 20))


def writer_path(library_path, rules=None):
    """The shipped voxlight-write-vdb beside the library at library_path
    (the add-on's copy, not the private one), made executable again (zip
    installs drop the bit). Raises ExportError naming what is missing."""
    rules = rules or platform_rules.current()
    if not rules.vdb_writer:
        raise ExportError(rules.no_vdb_writer)
    path = os.path.join(os.path.dirname(os.path.abspath(library_path)), rules.vdb_writer)
    if not os.path.isfile(path):
        raise ExportError("%s is missing beside %s: reinstall the add-on (tools/package_addon.sh ships it)"
                          % (rules.vdb_writer, library_path))
    if not restore_execute_bit(path):
        raise ExportError("%s cannot be run (no execute permission)" % path)
    return path


def stream(dims, index_to_world, density, rgb):
    """The writer's input (csrc/io/vdb_write.h) as bytes; index_to_world a
    4x4 math matrix, density (z, y, x) and rgb (z, y, x, 3)."""
    m = np.asarray(index_to_world, np.float64).reshape(4, 4).T  # column-major
    return b"".join((STREAM_MAGIC, struct.pack("=3I", *[int(d) for d in dims]), m.astype("=f8").tobytes(),
                     np.ascontiguousarray(density, "=f4").tobytes(), np.ascontiguousarray(rgb, "=f4").tobytes()))


def write(writer, path, dims, index_to_world, density, rgb):
    """Runs the writer; returns the file's size in bytes. Raises ExportError
    with the writer's own message when it fails."""
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    try:
        res = subprocess.run([writer, path], input=stream(dims, index_to_world, density, rgb),
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    except OSError as e:
        raise ExportError("cannot start %s: %s" % (writer, e)) from None
    if res.returncode != 0:
        msg = res.stderr.decode("utf-8", "replace").strip()
        if res.returncode < 0:
            msg = msg or "ended by signal %d" % -res.returncode
        raise ExportError(msg or "%s failed with exit status %d" % (writer, res.returncode))
    return os.path.getsize(path)
