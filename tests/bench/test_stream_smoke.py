"""The streaming benchmark (bench/stream_study.c, docs/streaming.md
"Benchmark") on small versions of its inputs from tests/make_stream_data.py:
a sparse uncompressed NIfTI, a .nii.gz (first open writes the bricked cache,
the second reads it), an uncompressed multi-page TIFF (read by offset) and
an OME-Zarr pyramid.
Each must stream, refine to the end, read bytes, and report a CSV row and a
markdown row with every column. Nothing here is timed."""
import csv
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
BENCH = ROOT / "build" / "voxlight-streambench"
sys.path.insert(0, str(ROOT / "tests"))
import make_stream_data  # noqa: E402

CASES = [("sparse", "s.nii", "256,256,96"), ("gzip", "g.nii.gz", "130,75,24"), ("tiff", "t.tif", "130,75,24"),
         ("zarr", "z.zarr", "128,128,64")]


@pytest.mark.parametrize("kind,name,dims", CASES)
def test_stream_bench_smoke(tmp_path, kind, name, dims):
    data = tmp_path / name
    make_stream_data.main([kind, str(data), "--dims", dims])
    out, md = tmp_path / "stream.csv", tmp_path / "stream.md"
    r = subprocess.run([str(BENCH), str(data), "--memory-budget", "8M", "--size", "48", "--streaming", "on",
                        "--max-refine-s", "60", "--label", kind, "--out", str(out), "--md", str(md)],
                       cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    (row,) = list(csv.DictReader(out.open()))
    assert row["label"] == kind and row["dims"] == dims.replace(",", "x")
    assert row["streamed"] == "1" and int(row["levels"]) >= 2
    assert row["refined"] == "1", row  # refine_pending reached 0
    assert float(row["peak_rss_mb"]) > 0 and float(row["first_frame_ms"]) > 0 and float(row["f12_ms"]) > 0
    # a cache applies to the gzip file only: its second open reads it
    assert (row["open_cached_ms"] != "-") == (kind == "gzip")
    if kind != "gzip":
        assert float(row["bytes_read_mb"]) > 0
    lines = md.read_text().splitlines()
    assert lines[0].startswith("| file | dims") and len(lines) == 3 and lines[2].startswith(f"| {kind} |")
