"""libvoxlight.so loads inside Blender's process, on machines without our
build dependencies (issue 13): it may need only the C runtime. The readers
that need OpenImageIO or dcmtk live in the helper processes
(csrc/io/reader_stream.h)."""
import re
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
LIB = ROOT / "build" / "libvoxlight.so"
# Not even the dynamic loader: thread-local storage in a shared object would
# add ld-linux for __tls_get_addr (csrc/core/error.c keeps its per-thread message
# behind a pthread key instead).
ALLOWED = re.compile(r"^(libc|libm|libz|libdl|libpthread)\.so\.\d+$")


def needed(path):
    out = subprocess.run(["readelf", "-d", str(path)], capture_output=True, text=True, check=True).stdout
    return re.findall(r"\(NEEDED\)\s+Shared library: \[([^\]]+)\]", out)


def test_library_needs_only_the_c_runtime():
    libs = needed(LIB)
    assert "libc.so.6" in libs  # the parse found the entries at all
    assert [n for n in libs if not ALLOWED.match(n)] == []
    assert not any(n.startswith(("libstdc++", "libgcc_s")) for n in libs)


def test_the_heavy_libraries_are_in_their_own_helpers():
    """One helper per library, so a missing one breaks only its formats."""
    oiio, dicom = needed(ROOT / "build" / "voxlight-read-oiio"), needed(ROOT / "build" / "voxlight-read-dicom")
    assert any(n.startswith("libOpenImageIO") for n in oiio) and not any(n.startswith("libdcm") for n in oiio)
    assert any(n.startswith("libdcmdata") for n in dicom) and not any(n.startswith("libOpenImageIO") for n in dicom)
