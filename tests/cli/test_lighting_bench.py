"""The lighting benchmark (bench/lighting_study.c, bench/plot_lighting.py)
that `./build.sh bench` runs for docs/lighting.md: at its smoke size it must
still produce every row of the cost table, phantom rows whose error against
the double-precision reference is finite and falls as the illumination
volume grows, and the figure and tables. Nothing here is timed."""
import csv
import math
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
BENCH = ROOT / "build" / "voxlight-lightbench"

COST_ROWS = {"phong", "shadowed-cached", "ratio-shadowed/phong", "shadowed-sun-moved", "shadowed-point-moved",
             "shadowed-ao4-cached", "scatter-ao4-cached", "shadowed-tf-changed", "sun-moved-at-128",
             "drag-start-128-to-64", "drag-settle-64-to-128", "sun-moved-at-256", "drag-start-256-to-64",
             "drag-settle-64-to-256"}


def test_quick_lighting_bench_and_plot(tmp_path):
    out = tmp_path / "lighting.csv"
    r = subprocess.run([str(BENCH), "--quick", "--out", str(out)], cwd=ROOT, capture_output=True, text=True,
                       timeout=900)
    assert r.returncode == 0, r.stderr
    rows = list(csv.DictReader(out.open()))
    brain = {x["config"]: x for x in rows if x["workload"] == "ch2better"}
    assert set(brain) == COST_ROWS
    for x in brain.values():
        assert float(x["frame_ms"]) > 0, x
    # the shadowed frames ran with the volumes the library chose (64) and the asked sizes
    assert int(brain["shadowed-cached"]["illumination_size"]) == 64
    assert int(brain["drag-settle-64-to-256"]["illumination_size"]) == 256

    blobs = [x for x in rows if x["workload"] == "blobs"]
    by = {(x["config"], int(x["illumination_size"])): x for x in blobs}
    assert ("phong", 0) in by
    for model in ("shadowed", "shadowed-ao4", "scatter-g0.3"):
        coarse, fine = by[(model, 16)], by[(model, 32)]
        for x in (coarse, fine):
            assert math.isfinite(float(x["rmse"])) and float(x["psnr_db"]) > 30, x
        # convergence towards the reference as the illumination volume grows
        assert float(fine["rmse"]) < float(coarse["rmse"]) * 1.02, (coarse, fine)

    png, md = tmp_path / "lighting.png", tmp_path / "lighting.md"
    r = subprocess.run(["/usr/bin/python3", str(ROOT / "bench" / "plot_lighting.py"), str(out), "--png", str(png),
                        "--md", str(md), "--command", "test"], cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    assert png.stat().st_size > 1000
    text = md.read_text()
    assert "| shadowed-cached | 64 |" in text and "| shadowed | 16 |" in text
    assert "costs %.2fx a Phong frame" % float(brain["ratio-shadowed/phong"]["frame_ms"]) in text
