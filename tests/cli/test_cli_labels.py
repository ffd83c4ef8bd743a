"""`voxlight labels FILE` prints a label lookup table as the library reads
it, so a user can check a file before rendering with it; a bad
file is one `voxlight: error:` line naming the file and line."""
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
CLI = ROOT / "build" / "voxlight"
MRICRON = Path("/usr/share/mricron/templates")


def labels(*args):
    return subprocess.run([str(CLI), "labels", *map(str, args)], capture_output=True, text=True, timeout=60)


def rows(stdout):
    """The table's lines after the two header lines, split into columns."""
    return [line.split(None, 6) for line in stdout.splitlines()[2:]]


def test_itksnap_table_is_printed_sorted_with_opacity_and_visibility(tmp_path):
    p = tmp_path / "heart.label"
    p.write_text("# ITK-SnAP Label Description File\n"
                 '    7   255  128    0      0.5  1  1    "Left atrium"\n'
                 '    0     0    0    0        0  0  0    "Clear Label"\n')
    out = labels(p)
    assert out.returncode == 0, out.stderr
    assert out.stdout.splitlines()[0] == f"2 labels in {p}"
    assert rows(out.stdout) == [["0", "0", "0", "0", "0", "no", "Clear Label"],
                                ["7", "255", "128", "0", "128", "yes", "Left atrium"]]


def test_freesurfer_transparency_is_shown_as_alpha(tmp_path):
    p = tmp_path / "FreeSurferColorLUT.txt"
    p.write_text("#No. Label Name: R G B A\n2 Left-Cerebral-White-Matter 245 245 245 0\n"
                 "1000 ctx-lh-unknown 25 5 25 255\n")
    out = labels(p)
    assert out.returncode == 0, out.stderr
    assert rows(out.stdout) == [["2", "245", "245", "245", "255", "yes", "Left-Cerebral-White-Matter"],
                                ["1000", "25", "5", "25", "0", "yes", "ctx-lh-unknown"]]


def test_the_mricron_atlas_pair():
    out = labels(MRICRON / "aal.nii.lut")
    assert out.returncode == 0, out.stderr
    table = rows(out.stdout)
    assert out.stdout.startswith("116 labels in ")
    assert table[0] == ["1", "204", "204", "204", "255", "yes", "Precentral_L"]
    assert table[-1][0] == "116" and table[-1][6] == "Vermis_10"


def test_bad_files_are_one_error_line(tmp_path):
    p = tmp_path / "broken.ctbl"
    p.write_text("# Color table file\n1 a 1 2 3 255\n2 b 1 2 300 255\n")
    out = labels(p)
    assert out.returncode == 1 and out.stdout == ""
    assert out.stderr.count("\n") == 1
    assert out.stderr.startswith("voxlight: error: ") and f"'{p}' line 3" in out.stderr
    out = labels(tmp_path / "missing.txt")
    assert out.returncode == 1 and "missing.txt" in out.stderr
    out = labels()
    assert out.returncode == 1 and "labels takes one FILE" in out.stderr


def test_usage_names_the_command():
    out = subprocess.run([str(CLI), "--help"], capture_output=True, text=True, timeout=60)
    assert "voxlight labels FILE" in out.stdout
