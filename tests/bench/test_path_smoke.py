"""Smoke run of the path model's study (bench/path_study.c, docs/lighting.md)
at a small size: it runs to the end, prints the first frame's time and one
row per sample count, and the error falls as the samples grow (16 samples
against 1: the noise of independent samples falls as 1/sqrt(N), so by about
4x; 2x is asserted). No speed is asserted."""
import re
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
BUILD = ROOT / "build"


def test_path_study_prints_every_row_and_the_error_falls():
    res = subprocess.run([str(BUILD / "voxlight-pathbench"), "--size", "32", "--reference", "32", "--samples", "1,4,16"],
                         capture_output=True, text=True, timeout=600)
    assert res.returncode == 0, res.stderr
    assert re.search(r"first frame \(1 sample, cold\) [0-9.]+ ms", res.stdout), res.stdout
    rows = re.findall(r"^\| (\d+) \| ([0-9.]+) \| ([0-9.]+) \| ([0-9.]+) \|$", res.stdout, re.M)
    assert [int(r[0]) for r in rows] == [1, 4, 16], res.stdout
    rmse = [float(r[2]) for r in rows]
    assert rmse[0] > 0 and rmse[2] < rmse[0] / 2, rmse
