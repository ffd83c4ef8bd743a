"""`voxlight info` of colour read by the reader helpers (docs/colour.md,
"Loaders"): an RGB PNG stack (voxlight-read-oiio), a YBR_FULL_422 DICOM and
a PALETTE COLOR DICOM (voxlight-read-dicom, files from
tests/make_colour_dicom.py) and an RGBA MetaImage (in process) print their
components, the colour's memory and the reader's note; --opacity-source
reaches the helper, and alpha of RGB data is a clean error."""
import subprocess
import sys

import numpy as np
import pytest

from test_cli import ROOT, assert_clean_error, run
from test_cli_modes import write_png


def make_dicom(folder, mode):
    """One colour file alone in its folder (a file stands for its folder's series)."""
    folder.mkdir()
    path = folder / "c.dcm"
    subprocess.run([sys.executable, str(ROOT / "tests" / "make_colour_dicom.py"), str(path), mode], check=True)
    return path


@pytest.fixture(scope="module")
def inputs(tmp_path_factory):
    d = tmp_path_factory.mktemp("colour_readers")
    stack = d / "stack"
    stack.mkdir()
    rgb = np.zeros((4, 5, 3), np.uint8)
    rgb[..., 0], rgb[..., 1], rgb[..., 2] = 200, 100, 50
    for k in range(3):
        write_png(stack / ("slice_%d.png" % k), rgb)
    mha = d / "rgba.mha"
    mha.write_bytes(b"ObjectType = Image\nNDims = 3\nDimSize = 2 2 2\nElementNumberOfChannels = 4\n"
                    b"ElementType = MET_UCHAR\nElementDataFile = LOCAL\n" + bytes(range(32)))
    return {"stack": stack, "ybr": make_dicom(d / "ybr", "ybr422"),
            "palette": make_dicom(d / "palette", "palette"), "mha": mha}


@pytest.mark.parametrize("name, components, note", [
    ("stack", "3 (RGB", "TIFF/PNG RGB: colour from the data, opacity and gradients from luminance"),
    ("ybr", "3 (RGB", "DICOM YBR_FULL_422: colour from the data, opacity and gradients from luminance"),
    ("palette", "3 (RGB", "DICOM PALETTE COLOR: colour from the data"),
    ("mha", "4 (RGBA", "MetaImage RGBA: colour from the data"),
])
def test_info_prints_the_components_of_colour_from_every_reader(inputs, name, components, note):
    r = run("info", inputs[name])
    assert r.returncode == 0, r.stderr
    assert "components:  " + components in r.stdout
    assert note in r.stdout


def test_opacity_source_reaches_the_helpers(inputs):
    r = run("info", "--opacity-source", "channel:1", inputs["ybr"])
    assert r.returncode == 0, r.stderr
    assert "opacity and gradients from the green channel" in r.stdout
    r = run("info", "--opacity-source", "alpha", inputs["stack"])
    assert_clean_error(r, "opacity source alpha needs RGBA data; this has 3 channels")
