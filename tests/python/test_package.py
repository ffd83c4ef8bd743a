"""The extension zip of each platform (tools/package_addon.sh): its
manifest names that platform alone, and every binary in it is built for
it, so Blender never installs a package whose library cannot load.
BUILD names the build folder (build/ by default), as in conftest.py."""
import os
import re
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
BUILD = ROOT / os.environ.get("BUILD", "build")
ZIP = BUILD / "voxlight-linux-x64.zip"
WINDOWS_ZIP = BUILD / "voxlight-windows-x64.zip"
ELF = b"\x7fELF"
TEXT = (".py", ".md", ".toml")


def _binaries(z):
    return [n for n in z.namelist() if not n.endswith("/") and not n.endswith(TEXT)]


def _plugin_files(z):
    return {n: z.read(n) for n in z.namelist() if n.endswith(".py")}


def test_linux_zip_names_its_platform_and_holds_linux_binaries_only():
    with zipfile.ZipFile(ZIP) as z:
        manifest = z.read("voxlight/blender_manifest.toml").decode()
        assert re.search(r'^platforms = \["linux-x64"\]$', manifest, re.M), manifest
        binaries = _binaries(z)
        assert "voxlight/libvoxlight.so" in binaries
        for name in binaries:
            head = z.read(name)[:20]
            assert head[:4] == ELF, name
            # e_machine at byte 18: 62 is x86-64
            assert int.from_bytes(head[18:20], "little") == 62, name
        assert not any(n.endswith((".dll", ".exe")) for n in binaries)


def test_windows_zip_names_its_platform_and_holds_windows_binaries_only():
    # A missing zip is a failure: the build makes it whenever it builds
    # voxlight.dll, and without it Windows users have nothing to install.
    assert WINDOWS_ZIP.is_file(), "%s not made (tools/package_addon.sh, after make windows)" % WINDOWS_ZIP
    with zipfile.ZipFile(WINDOWS_ZIP) as z:
        manifest = z.read("voxlight/blender_manifest.toml").decode()
        assert re.search(r'^platforms = \["windows-x64"\]$', manifest, re.M), manifest
        binaries = _binaries(z)
        # zlib1.dll: voxlight.dll loads it from its own folder.
        assert {"voxlight/voxlight.dll", "voxlight/zlib1.dll"} <= set(binaries), binaries
        # the reader helpers our own C builds for Windows (DICOM on our own parser)
        assert {"voxlight/voxlight-read-zarr.exe", "voxlight/voxlight-read-dicom.exe"} <= set(binaries), binaries
        assert not any(n.endswith(".so") or ".so." in n for n in z.namelist())
        for name in binaries:
            data = z.read(name)
            assert data[:4] != ELF, name
            assert data[:2] == b"MZ", name
            # The PE header's offset is at 0x3c; its machine 0x8664 is x86-64.
            pe = int.from_bytes(data[0x3C:0x40], "little")
            assert data[pe:pe + 4] == b"PE\0\0", name
            assert int.from_bytes(data[pe + 4:pe + 6], "little") == 0x8664, name
            assert name.lower().endswith((".dll", ".exe")), name
        windows_plugin = _plugin_files(z)
    with zipfile.ZipFile(ZIP) as z:
        linux_plugin = _plugin_files(z)
    assert sorted(windows_plugin) == sorted(linux_plugin)
    assert windows_plugin == linux_plugin, "the two zips' add-on code differs"
