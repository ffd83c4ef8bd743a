"""voxlight.dll, cross-compiled for Windows x64 (make windows), renders the
same scene as libvoxlight.so on Linux, through its WGL backend, under
Debian's Wine with Xvfb (Wine's OpenGL reaches Mesa's llvmpipe): the two
images must agree to float rounding. tests/render_scene.c is the program,
built for both."""
import subprocess
from pathlib import Path

import numpy as np

from wine_run import run_windows

ROOT = Path(__file__).resolve().parents[2]
LINUX = ROOT / "build" / "tests" / "render_scene"


def load(path):
    b = path.read_bytes()
    w, h = np.frombuffer(b[:8], "<u4")
    n = int(w) * int(h)
    rgba = np.frombuffer(b[8:8 + 16 * n], "<f4").reshape(int(h), int(w), 4)
    depth = np.frombuffer(b[8 + 16 * n:], "<f4").reshape(int(h), int(w))
    return rgba, depth


def test_windows_render_equals_linux_render(tmp_path):
    lin = subprocess.run([str(LINUX), str(tmp_path / "linux.bin")], capture_output=True, text=True, timeout=300)
    assert lin.returncode == 0, lin.stderr
    win = run_windows("render_scene.exe", tmp_path / "windows.bin", display=True)
    assert win.returncode == 0, win.stdout + win.stderr
    assert "backend wgl" in win.stdout, win.stdout
    a, da = load(tmp_path / "linux.bin")
    b, db = load(tmp_path / "windows.bin")
    assert (a[..., 3] > 0.01).mean() > 0.1  # the scene shows the phantom at all
    assert np.abs(a - b).max() <= 1e-5, "rgba differs by %g" % np.abs(a - b).max()
    assert (np.isfinite(da) == np.isfinite(db)).all()
    both = np.isfinite(da)
    assert np.abs(da[both] - db[both]).max() <= 1e-4
