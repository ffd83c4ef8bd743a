"""voxlight.dll, cross-compiled for Windows x64 (make windows), renders the
same scene as libvoxlight.so on Linux, through its WGL backend, under
Debian's Wine with Xvfb (Wine's OpenGL reaches Mesa's llvmpipe): the two
images must agree to float rounding. tests/render_scene.c is the program,
built for both."""
import os
import shutil
import subprocess
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
LINUX = ROOT / "build" / "tests" / "render_scene"
WINDOWS = ROOT / "build" / "windows-x64" / "render_scene.exe"


def wine():
    for c in ("/usr/lib/wine/wine64", shutil.which("wine64"), shutil.which("wine")):
        if c and os.access(c, os.X_OK):
            return c
    raise AssertionError("no Wine (./build.sh installs wine64)")


def load(path):
    b = path.read_bytes()
    w, h = np.frombuffer(b[:8], "<u4")
    n = int(w) * int(h)
    rgba = np.frombuffer(b[8:8 + 16 * n], "<f4").reshape(int(h), int(w), 4)
    depth = np.frombuffer(b[8 + 16 * n:], "<f4").reshape(int(h), int(w))
    return rgba, depth


def test_windows_render_equals_linux_render(tmp_path):
    assert WINDOWS.exists(), "build/windows-x64 has no render_scene.exe (make windows)"
    lin = subprocess.run([str(LINUX), str(tmp_path / "linux.bin")], capture_output=True, text=True, timeout=300)
    assert lin.returncode == 0, lin.stderr
    env = dict(os.environ, WINEPREFIX=str(ROOT / "build" / "wine"), WINEDEBUG="-all")
    env.pop("VOXLIGHT_BACKEND", None)
    # Wine maps the Linux root to Z:
    out = "Z:" + str(tmp_path / "windows.bin").replace("/", "\\")
    win = subprocess.run(["xvfb-run", "-a", "-s", "-screen 0 640x480x24", wine(), str(WINDOWS), out],
                         capture_output=True, text=True, env=env, timeout=600)
    assert win.returncode == 0, win.stdout + win.stderr
    assert "backend wgl" in win.stdout, win.stdout
    a, da = load(tmp_path / "linux.bin")
    b, db = load(tmp_path / "windows.bin")
    assert (a[..., 3] > 0.01).mean() > 0.1  # the scene shows the phantom at all
    assert np.abs(a - b).max() <= 1e-5, "rgba differs by %g" % np.abs(a - b).max()
    assert (np.isfinite(da) == np.isfinite(db)).all()
    both = np.isfinite(da)
    assert np.abs(da[both] - db[both]).max() <= 1e-4
