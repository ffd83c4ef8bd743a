"""The extension zip of each platform (tools/package_addon.sh): its
manifest names that platform alone, and every binary in it is built for
it, so Blender never installs a package whose library cannot load."""
import re
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
ZIP = ROOT / "build" / "voxlight-linux-x64.zip"
ELF = b"\x7fELF"


def test_linux_zip_names_its_platform_and_holds_linux_binaries_only():
    with zipfile.ZipFile(ZIP) as z:
        manifest = z.read("voxlight/blender_manifest.toml").decode()
        assert re.search(r'^platforms = \["linux-x64"\]$', manifest, re.M), manifest
        binaries = [n for n in z.namelist() if not n.endswith("/") and not n.endswith((".py", ".md", ".toml"))]
        assert "voxlight/libvoxlight.so" in binaries
        for name in binaries:
            head = z.read(name)[:20]
            assert head[:4] == ELF, name
            # e_machine at byte 18: 62 is x86-64
            assert int.from_bytes(head[18:20], "little") == 62, name
        assert not any(n.endswith((".dll", ".exe")) for n in binaries)
