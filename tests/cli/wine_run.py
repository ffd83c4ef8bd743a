"""Running the Windows build (build/windows-x64, cross-compiled by
./build.sh) under Debian's Wine for the tests: the Wine prefix under build/,
Linux paths as Wine's Z: drive, and an Xvfb for programs that render (Wine's
OpenGL is GLX on Mesa's llvmpipe)."""
import os
import shutil
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
WINDOWS = ROOT / "build" / "windows-x64"


def wine():
    """Debian 12's wine64 has /usr/lib/wine/wine64; later Wines run 64-bit
    programs with plain wine (build.sh's wine_binary looks the same way)."""
    for c in ("/usr/lib/wine/wine64", shutil.which("wine64"), shutil.which("wine")):
        if c and os.access(c, os.X_OK):
            return c
    raise AssertionError("no Wine (./build.sh installs wine64)")


def windows_path(p):
    """A Linux path as a Windows program under Wine names it: Wine maps / to Z:."""
    return "Z:" + str(Path(p).resolve()).replace("/", "\\")


def run_windows(program, *args, display=False, timeout=600):
    """program (a file of build/windows-x64) with args, Path arguments turned
    into Windows paths; display: under Xvfb, for programs that open GL."""
    exe = WINDOWS / program
    assert exe.exists(), "build/windows-x64 has no %s (./build.sh builds it)" % program
    env = dict(os.environ, WINEPREFIX=str(ROOT / "build" / "wine"), WINEDEBUG="-all")
    env.pop("VOXLIGHT_BACKEND", None)
    cmd = [wine(), str(exe)] + [windows_path(a) if isinstance(a, Path) else str(a) for a in args]
    if display:
        cmd = ["xvfb-run", "-a", "-s", "-screen 0 640x480x24"] + cmd
    # undecodable output is shown, not an exception: a test then says what came out
    return subprocess.run(cmd, capture_output=True, text=True, errors="replace", env=env, timeout=timeout)
