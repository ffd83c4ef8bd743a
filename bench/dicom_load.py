"""DICOM load time: a CT-like series (512x512 by default, SLICES slices),
uncompressed and JPEG Lossless SV1 (dcmtk's dcmcjpeg), loaded by Voxlight
with every core and with one (taskset -c 0), against dcmtk's dcmdjpeg
followed by our load, and dcm2niix where it is installed, in one run.

usage: python3 bench/dicom_load.py [--slices N] [--size N] [--work DIR]

Prints a markdown table (seconds, best of 3 runs of each load) and the
command that made it; docs/dicom.md keeps the table. The series is written
once into --work (default /tmp/vxl_dicom_bench) and reused by later runs.
Run it on a quiet machine: nothing else building.
"""
import argparse
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "python"))
from dicom_write import write_dicom  # noqa: E402

CLI = ROOT / "build" / "voxlight"


def phantom_slice(n, k, slices, rng):
    """An ellipse of soft tissue with a bright ring (bone) and noise: as
    compressible as a CT slice, in stored values (HU + 1024)."""
    y, x = (np.indices((n, n)) - n / 2) / (n / 2)
    z = (k / max(1, slices - 1)) - 0.5
    r = np.sqrt((x / 0.8) ** 2 + (y / 0.6) ** 2 + z ** 2)
    body = np.where(r < 1, 1064.0, 24.0)
    body = np.where((r > 0.85) & (r < 0.95), 2200.0, body)
    return np.clip(body + rng.normal(0, 12, body.shape), 0, 4095).astype(np.uint16)


def write_series(folder, n, slices):
    folder.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(1)
    for k in range(slices):
        write_dicom(folder / f"IM{k:05d}.dcm", "1.2.840.99.77", phantom_slice(n, k, slices, rng), z=round(0.7 * k, 4),
                    spacing=(0.7, 0.7))


def each_file(tool, src, dst):
    """tool SRC/f DST/f for every file, on every core (xargs -P)."""
    dst.mkdir(parents=True, exist_ok=True)
    names = "\n".join(sorted(p.name for p in src.iterdir()))
    subprocess.run(["xargs", "-P", str(os.cpu_count()), "-I{}", "sh", "-c", f"{tool} '{src}/{{}}' '{dst}/{{}}'"],
                   input=names, text=True, check=True)


def best_of(cmd, runs=3, setup=None):
    times = []
    for _ in range(runs):
        if setup:
            setup()
        t0 = time.perf_counter()
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        times.append(time.perf_counter() - t0)
    return min(times)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--slices", type=int, default=1000)
    ap.add_argument("--size", type=int, default=512)
    ap.add_argument("--work", default="/tmp/vxl_dicom_bench")
    a = ap.parse_args()
    work = Path(a.work) / f"{a.size}x{a.slices}"
    raw, jpeg, dj = work / "raw", work / "jpeg_lossless", work / "dcmdjpeg"
    if not (work / "done").exists():
        shutil.rmtree(work, ignore_errors=True)
        write_series(raw, a.size, a.slices)
        each_file("dcmcjpeg", raw, jpeg)
        (work / "done").touch()
    # `info` reads the whole volume (its value range); the default budget's
    # volume half (1 GiB) holds 512x512x1000 16-bit voxels
    ours = lambda d, one=False: (["taskset", "-c", "0"] if one else []) + [str(CLI), "info", str(d)]  # noqa
    rows = []
    for name, d in (("uncompressed", raw), ("JPEG Lossless SV1", jpeg)):
        rows.append((name, "Voxlight, all cores", best_of(ours(d))))
        rows.append((name, "Voxlight, one core", best_of(ours(d, True))))

    def decompress():
        shutil.rmtree(dj, ignore_errors=True)
        each_file("dcmdjpeg", jpeg, dj)
    t0 = time.perf_counter()
    decompress()
    t_dj = time.perf_counter() - t0
    rows.append(("JPEG Lossless SV1", "dcmtk dcmdjpeg (all cores) + Voxlight", t_dj + best_of(ours(dj))))
    if shutil.which("dcm2niix"):
        out = work / "nii"
        for name, d in (("uncompressed", raw), ("JPEG Lossless SV1", jpeg)):
            def clean():
                shutil.rmtree(out, ignore_errors=True)
                out.mkdir()
            rows.append((name, "dcm2niix", best_of(["dcm2niix", "-z", "n", "-o", str(out), str(d)], setup=clean)))
    mb = a.size * a.size * a.slices * 2 / 2 ** 20
    print(f"{a.size}x{a.size}x{a.slices} 16-bit ({mb:.0f} MiB of voxels), {os.cpu_count()} cores; "
          f"`python3 bench/dicom_load.py --slices {a.slices} --size {a.size}`\n")
    print("| series | reader | seconds |")
    print("|---|---|---|")
    for series, reader, t in rows:
        print(f"| {series} | {reader} | {t:.2f} |")


if __name__ == "__main__":
    main()
