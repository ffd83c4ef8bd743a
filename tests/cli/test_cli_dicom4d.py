"""`voxlight info|render` on DICOM folders (series listing, --series) and 4D
NIfTI (frame count, --frame). DICOM files come from tests/python/dicom_write.py
(plain Python, independent of dcmtk and of the C test writer)."""
import os
import struct
import subprocess
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
CLI = ROOT / "build" / "voxlight"
sys.path.insert(0, str(ROOT / "tests" / "python"))
from dicom_write import write_dicom  # noqa: E402
from nifti_write import nifti1_bytes  # noqa: E402


def run(*args):
    e = dict(os.environ)
    e.pop("VOXLIGHT_BACKEND", None)
    return subprocess.run([str(CLI), *map(str, args)], capture_output=True, text=True, env=e, timeout=300)


def ball(n=12, scale=2000):
    g = np.indices((n, n, n)) - (n - 1) / 2
    return (scale * np.clip(1 - np.sqrt((g ** 2).sum(0)) / (n / 2.5), 0, None)).astype(np.uint16)


def write_series(folder, uid, modality, n=12, dz=1.5):
    folder.mkdir(exist_ok=True)
    vol = ball(n) + 1024
    for k in reversed(range(n)):  # files written in reverse: order comes from the positions
        write_dicom(folder / f"{uid}_{k:03d}.dcm", uid, vol[k], k * dz, modality)


def test_info_lists_series_and_render_needs_a_choice(tmp_path):
    d = tmp_path / "study"
    write_series(d, "1.2.840.99.1", "CT")
    write_series(d, "1.2.840.99.2", "MR", n=8)
    r = run("info", d)
    assert r.returncode == 0, r.stderr
    assert "DICOM series: 2" in r.stdout
    assert "[0] 1.2.840.99.1  CT  12 x 12 x 12" in r.stdout and "[1] 1.2.840.99.2  MR  8 x 8 x 8" in r.stdout
    assert "--series" in r.stdout

    r = run("render", d, "-o", tmp_path / "x.png", "--size", "32x32")
    assert r.returncode == 1 and "2 DICOM series" in r.stderr and "1.2.840.99.2" in r.stderr
    assert r.stderr.count("voxlight: error:") == 1

    r = run("info", d, "--series", "1.2.840.99.2")
    assert r.returncode == 0, r.stderr
    assert "dimensions:  8 x 8 x 8" in r.stdout and "format:      DICOM" in r.stdout
    assert "spacing:     0.6 x 0.8 x 1.5 mm" in r.stdout
    assert "value range: 0 .." in r.stdout  # rescale intercept -1024 cancels the +1024: Hounsfield units

    out = tmp_path / "ct.png"
    r = run("render", d, "--series", "0", "-o", out, "--size", "48x48", "--preset", "ct")
    assert r.returncode == 0, r.stderr
    assert out.stat().st_size > 100

    r = run("render", d, "--series", "5", "-o", out)
    assert r.returncode == 1 and "no series '5'" in r.stderr


def test_missing_slice_is_interpolated_and_info_says_so(tmp_path):
    d = tmp_path / "gap"
    write_series(d, "1.2.840.99.3", "CT")
    (d / "1.2.840.99.3_005.dcm").unlink()
    r = run("info", d)
    assert r.returncode == 0, r.stderr
    assert "dimensions:  12 x 12 x 12" in r.stdout  # the even grid keeps every position
    notes = [line for line in r.stdout.splitlines() if line.startswith("notes:")]
    assert len(notes) == 1 and "uneven slice spacing (a missing slice?): 3 mm" in notes[0], r.stdout
    assert "1.5 mm" in notes[0] and "1 of them interpolated" in notes[0]
    r = run("render", d, "-o", tmp_path / "x.png", "--size", "32x32")
    assert r.returncode == 0, r.stderr


def write_4d(path, frames=6, n=10):
    data = np.zeros((n, n, n, frames), np.float32)
    for t in range(frames):
        data[2 + t % 5: 5 + t % 5, 3:7, 3:7, t] = 100.0 * (t + 1)
    raw = bytearray(nifti1_bytes(data))
    struct.pack_into("<h", raw, 40, 4)  # dim[0] = 4
    Path(path).write_bytes(bytes(raw))
    return data


def test_4d_info_reports_frames_and_render_picks_one(tmp_path):
    p = tmp_path / "fmri.nii"
    write_4d(p)
    r = run("info", p)
    assert r.returncode == 0, r.stderr
    assert "frames:      6 (this is frame 0" in r.stdout and "value range: 0 .. 100" in r.stdout
    r = run("info", p, "--frame", "4")
    assert "this is frame 4" in r.stdout and "value range: 0 .. 500" in r.stdout
    imgs = []
    for f in (1, 4):
        out = tmp_path / f"f{f}.png"
        r = run("render", p, "--frame", f, "-o", out, "--size", "40x40", "--window", "0:600", "--no-jitter")
        assert r.returncode == 0, r.stderr
        imgs.append(out.read_bytes())
    assert imgs[0] != imgs[1]
    r = run("render", p, "--frame", "6", "-o", tmp_path / "x.png")
    assert r.returncode == 1 and "frame 6 requested, the file has 6" in r.stderr
    r = run("info", p, "--frame", "-1")
    assert r.returncode == 1 and "bad --frame" in r.stderr
