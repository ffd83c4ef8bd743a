"""The render modes' benchmark (bench/modes_study.c) that `./build.sh bench`
runs for docs/benchmark.md: at its smoke size it must give a row per mode
and step, projections whose error against the double-precision reference
falls as the step shrinks, and ISO depths within a tenth of a voxel of the
sphere and within 1e-3 voxels of the trilinear field's own crossing. Nothing
here is timed."""
import csv
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
BENCH = ROOT / "build" / "voxlight-modesbench"
STEPS = [2.0, 1.0, 0.5, 0.25, 0.125]


def test_quick_modes_bench(tmp_path):
    out, md = tmp_path / "modes.csv", tmp_path / "modes.md"
    r = subprocess.run([str(BENCH), "--quick", "--out", str(out), "--md", str(md)], cwd=ROOT, capture_output=True,
                       text=True, timeout=900)
    assert r.returncode == 0, r.stderr
    rows = list(csv.DictReader(out.open()))
    by = {(x["mode"], float(x["step"])): x for x in rows}
    modes = ["mip", "minip", "average", "iso", "iso-vs-trilinear"]
    assert set(by) == {(m, s) for m in modes for s in STEPS}
    for m in ["mip", "minip", "average"]:
        err = [float(by[(m, s)]["error_mean"]) for s in STEPS]
        assert err[-1] < err[0] / 4 and err[-1] < 2e-3, (m, err)
    for s in STEPS:
        assert float(by[("iso", s)]["error_max"]) < 0.1
        assert float(by[("iso-vs-trilinear", s)]["error_max"]) < 1e-3
    text = md.read_text()
    assert text.startswith("| mode | step") and text.count("\n") == 2 + len(rows)
