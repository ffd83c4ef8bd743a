"""Seeds for fuzz_dicom beyond make_seeds' single-frame files: enhanced
multi-frame files (functional groups, 4D time points, JPEG 2000 frames
behind a basic offset table), written by tests/make_enhanced_dicom.py with
pydicom, classic multi-frame RLE and JPEG-LS copies made by dcmtk, and
PALETTE COLOR files (16-bit and packed 8-bit tables) from
tests/make_colour_dicom.py.

usage: dicom_seeds.py OUT_DIR
"""
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
GEOMETRY = ["0.8", "0.6", "0", "0", "0", "-1", "-10", "20", "30", "-1.2", "1.6", "0"]


def enhanced(path, times, seed, codec=""):
    args = [sys.executable, str(ROOT / "tests" / "make_enhanced_dicom.py"), str(path), "6", "5", "4", str(times),
            *GEOMETRY, str(seed)] + ([codec] if codec else [])
    subprocess.run(args, check=True)


def main(out):
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    enhanced(out / "enhanced.dcm", 1, 1)
    enhanced(out / "enhanced_4d.dcm", 2, 2)
    enhanced(out / "enhanced_j2k.dcm", 1, 3, "j2k")
    for name, tool in (("enhanced_rle.dcm", ["dcmcrle"]), ("enhanced_jpls.dcm", ["dcmcjpls", "-ot"])):
        subprocess.run([*tool, str(out / "enhanced.dcm"), str(out / name)], check=True)
    for mode in ("palette", "palette8"):
        subprocess.run([sys.executable, str(ROOT / "tests" / "make_colour_dicom.py"), str(out / (mode + ".dcm")), mode],
                       check=True)


if __name__ == "__main__":
    main(sys.argv[1])
