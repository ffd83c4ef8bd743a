"""Data larger than memory in `voxlight`: --streaming and
--cache-dir, what `info` says of a streamed volume, a streamed render equal
to a whole one, --memory-budget split between the volume and the renderer,
the progress of a .nii.gz's first open and Ctrl-C during it leaving no
cache behind."""
import gzip
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from test_cli import CLI, assert_clean_error, png_rgba, run, write_nifti


def blob_volume(n=40, seed=3):
    """(z, y, x) uint8: a few soft balls on an empty background, so a
    streamed render has empty bricks to skip and full ones to read."""
    rng = np.random.default_rng(seed)
    z, y, x = np.mgrid[0:n, 0:n, 0:n].astype(np.float32)
    vol = np.zeros((n, n, n), np.float32)
    for _ in range(4):
        c = rng.uniform(n * 0.25, n * 0.75, 3)
        r = rng.uniform(n * 0.1, n * 0.2)
        d = np.sqrt((x - c[0]) ** 2 + (y - c[1]) ** 2 + (z - c[2]) ** 2)
        vol = np.maximum(vol, 230.0 / (1.0 + np.exp(np.clip((d - r) * 1.5, -50.0, 50.0))))
    return vol.astype(np.uint8)


def info_field(stdout, name):
    for line in stdout.splitlines():
        if line.startswith(name + ":"):
            return line.split(":", 1)[1].strip()
    raise AssertionError("no %s line in:\n%s" % (name, stdout))


def render_pixels(path, out, *extra):
    res = run("render", path, "-o", out, "--size", "64x64", "--azimuth", "30", "--elevation", "20",
              "--no-jitter", *extra)
    assert res.returncode == 0, res.stderr
    return png_rgba(out).astype(np.int16), res.stderr


def assert_same_image(a, b):
    # The same voxels through another path: equal up to the rounding of
    # 8-bit output (a brick apron sampled by another texture).
    diff = np.abs(a - b)
    assert diff.max() <= 2 and diff.mean() < 0.05, (diff.max(), diff.mean())


def test_info_says_whether_a_volume_is_streamed(tmp_path):
    path = tmp_path / "blobs.nii"
    write_nifti(path, blob_volume())
    on = run("info", path, "--streaming", "on")
    assert on.returncode == 0, on.stderr
    assert info_field(on.stdout, "streamed").startswith("yes")
    assert int(info_field(on.stdout, "levels")) >= 1
    assert info_field(on.stdout, "resident").endswith("MiB") and info_field(on.stdout, "read").endswith("MiB")
    off = run("info", path, "--streaming", "off")
    assert off.returncode == 0, off.stderr
    assert info_field(off.stdout, "streamed").startswith("no")
    assert info_field(off.stdout, "levels") == "1"
    # the same volume either way
    for field in ("dimensions", "value range", "data type"):
        assert info_field(on.stdout, field) == info_field(off.stdout, field)


def test_streamed_render_equals_the_whole_one(tmp_path):
    path = tmp_path / "blobs.nii"
    write_nifti(path, blob_volume())
    whole, whole_err = render_pixels(path, tmp_path / "off.png", "--streaming", "off")
    streamed, streamed_err = render_pixels(path, tmp_path / "on.png", "--streaming", "on")
    assert whole[..., 3].mean() > 5  # the blobs are visible
    assert_same_image(whole, streamed)
    # render says what a streamed frame read; a whole volume reads nothing then
    assert "voxlight: streamed:" in streamed_err and "voxlight: streamed:" not in whole_err


def test_streamed_multipage_tiff_equals_the_whole_read(tmp_path):
    # an uncompressed multi-page TIFF streams by offset in the library;
    # read whole it goes through the OpenImageIO helper: the same volume
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
    import make_stream_data
    path = tmp_path / "body.tif"
    make_stream_data.main(["tiff", str(path), "--dims", "72,56,40"])
    on, off = run("info", path, "--streaming", "on"), run("info", path, "--streaming", "off")
    assert on.returncode == 0 and off.returncode == 0, on.stderr + off.stderr
    assert info_field(on.stdout, "streamed").startswith("yes") and info_field(off.stdout, "streamed").startswith("no")
    for field in ("dimensions", "value range", "data type"):
        assert info_field(on.stdout, field) == info_field(off.stdout, field)
    whole, _ = render_pixels(path, tmp_path / "off.png", "--streaming", "off")
    streamed, err = render_pixels(path, tmp_path / "on.png", "--streaming", "on")
    assert whole[..., 3].mean() > 5
    assert_same_image(whole, streamed)
    assert "voxlight: streamed:" in err


def test_gzip_first_open_caches_with_progress_then_reads_the_cache(tmp_path):
    src = tmp_path / "blobs.nii.gz"
    write_nifti(src, blob_volume(48))
    cache = tmp_path / "cache"
    cache.mkdir()
    first = run("info", src, "--streaming", "on", "--cache-dir", cache)
    assert first.returncode == 0, first.stderr
    assert info_field(first.stdout, "streamed").startswith("yes")
    # stderr is no terminal here: a few whole lines, from the start to the end
    progress = [l for l in first.stderr.splitlines() if l.startswith("voxlight: ") and l.endswith("%")]
    assert progress and progress[-1].endswith("100%"), first.stderr
    assert len(progress) <= 20 and "\r" not in first.stderr
    made = {p.name: p.stat().st_mtime_ns for p in cache.iterdir()}
    assert made, "no cache written"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["blobs.nii.gz", "cache"], \
        "the cache went beside the file, not into --cache-dir"
    # the second open reads the cache: nothing rebuilt or added
    again = run("info", src, "--streaming", "on", "--cache-dir", cache)
    assert again.returncode == 0, again.stderr
    assert {p.name: p.stat().st_mtime_ns for p in cache.iterdir()} == made
    whole, _ = render_pixels(src, tmp_path / "off.png", "--streaming", "off")
    streamed, _ = render_pixels(src, tmp_path / "on.png", "--streaming", "on", "--cache-dir", cache)
    assert_same_image(whole, streamed)


def test_memory_budget_is_split_between_volume_and_renderer(tmp_path):
    # 3.2 MiB of voxels. The volume gets half of --memory-budget, and auto
    # streams what exceeds half of the volume's share (voxlight.h): whole
    # under 64M, streamed under 8M (share 4 MiB, threshold 2 MiB).
    path = tmp_path / "blobs.nii"
    write_nifti(path, blob_volume(150))
    _, big = render_pixels(path, tmp_path / "big.png", "--memory-budget", "64M")
    _, small = render_pixels(path, tmp_path / "small.png", "--memory-budget", "8M")
    assert "voxlight: streamed:" not in big and "voxlight: streamed:" in small, (big, small)
    # Read whole (off), the volume must fit its half: 8M leaves it 4 MiB,
    # which holds it; 6M leaves 3 MiB, which does not.
    res = run("render", path, "-o", tmp_path / "x.png", "--streaming", "off", "--memory-budget", "8M")
    assert res.returncode == 0, res.stderr
    assert_clean_error(run("render", path, "-o", tmp_path / "x.png", "--streaming", "off", "--memory-budget", "6M"),
                       "budget")
    assert "--memory-budget SIZE (default 2G) bounds the volume and the renderer together" in \
        run("--help").stdout


def test_bad_streaming_options(tmp_path):
    path = tmp_path / "blobs.nii"
    write_nifti(path, blob_volume(8))
    assert_clean_error(run("info", path, "--streaming", "maybe"), "--streaming", "auto, off, on")
    assert_clean_error(run("render", path, "-o", tmp_path / "x.png", "--streaming", "ON!"), "--streaming")
    assert_clean_error(run("info", path, "--streaming"), "--streaming needs a value")
    assert_clean_error(run("info", path, "--cache-dir"), "--cache-dir needs a value")
    assert_clean_error(run("info", path, "--cache-dir", ""), "--cache-dir")


def test_ctrl_c_during_the_first_open_cancels_and_keeps_no_cache(tmp_path):
    """SIGINT as soon as the first progress line shows: the open stops, the
    tool says so and exits 130, and the cache folder stays empty."""
    rng = np.random.default_rng(5)
    # 64 MB of voxels, half noise: a first pass that takes a while
    vol = (rng.integers(0, 16, size=(256, 512, 512), dtype=np.uint8) * 16)
    vol[:, :, :256] = 0
    raw = tmp_path / "big.nii"
    write_nifti(raw, vol)
    src = tmp_path / "big.nii.gz"
    src.write_bytes(gzip.compress(raw.read_bytes(), compresslevel=1))
    raw.unlink()
    cache = tmp_path / "cache"
    cache.mkdir()
    proc = subprocess.Popen([str(CLI), "info", str(src), "--streaming", "on", "--cache-dir", str(cache)],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        first = proc.stderr.readline()
        assert first.startswith("voxlight: ") and first.rstrip().endswith("%"), first
        proc.send_signal(signal.SIGINT)
        out, err = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert proc.returncode == 130, (proc.returncode, first + err)
    assert "cancelled" in err and "big.nii.gz" in err, err
    assert "dimensions" not in out  # nothing was reported as opened
    time.sleep(0.1)
    assert list(cache.iterdir()) == [], "a cancelled first open left %s" % list(cache.iterdir())
    assert not list(tmp_path.glob("big.nii.gz?*")), "a cancelled first open left a file beside the source"


def test_progress_on_a_terminal_is_one_line_rewritten(tmp_path):
    import os
    import pty
    src = tmp_path / "blobs.nii.gz"
    write_nifti(src, blob_volume(48))
    cache = tmp_path / "cache"
    cache.mkdir()
    master, slave = pty.openpty()
    try:
        proc = subprocess.run([str(CLI), "info", str(src), "--streaming", "on", "--cache-dir", str(cache)],
                              stdout=subprocess.PIPE, stderr=slave, timeout=300)
        os.close(slave)
        slave = None
        err = b""
        while True:
            try:
                chunk = os.read(master, 65536)
            except OSError:  # the terminal's other end is closed: all read
                break
            if not chunk:
                break
            err += chunk
    finally:
        if slave is not None:
            os.close(slave)
        os.close(master)
    assert proc.returncode == 0, err
    text = err.decode()
    # updates go back to the line's start and clear its end; one newline ends it
    assert text.count("\r") > 1 and "\x1b[K" in text, repr(text)
    lines = [l for l in text.replace("\r\n", "\n").split("\n") if l]
    assert len(lines) == 1 and lines[0].rstrip().endswith("100%\x1b[K"), repr(text)
