"""A stand-in reader helper (csrc/io/reader_stream.h) whose reply carries
notes, for the CLI's and the add-on's tests: the reader that will set notes
(DICOM) does not yet, and none may be made to. Its volume is 4x3x2 float
zeros, whatever the input."""

import os

# The layout of vxl_reader_header (tests/python/test_vdb_isolation.py checks
# every field; this only carries the notes, given as the last argument).
_REPLY = """import struct, sys
h = struct.pack("=8s16I4d3d16d5Q512s2I32dQ768s", b"VXLRD04\\0", 0, 0, 1, 0, 0, 4, 3, 2, 7, 32, 0, 2, 1, 0, 1,
                0, 0.0, 1.0, 0.0, 1.0, 1.0, 1.0, 1.0, *[float(i % 5 == 0) for i in range(16)], 0, 0, 96, 96, 0,
                sys.argv[-1].encode(), 0, 0, *[0.0] * 32, 0, b"")
assert len(h) == 1848
sys.stdout.buffer.write(h + bytes(96))
"""


def notes_helper(folder, notes, name="voxlight-read-oiio"):
    """An executable in folder that answers every command with a 4x3x2
    volume carrying notes (one line, no single quote); its path."""
    assert "'" not in notes and "\n" not in notes
    script = os.path.join(str(folder), name + "-reply.py")
    with open(script, "w") as f:
        f.write(_REPLY)
    path = os.path.join(str(folder), name)
    with open(path, "w") as f:
        f.write("#!/bin/sh\nexec python3 '%s' '%s'\n" % (script, notes))
    os.chmod(path, 0o755)
    return path
