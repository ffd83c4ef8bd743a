"""The library is loaded from a private copy (plugin/core/native.py), so that
installing the add-on over itself never writes over a mapped file, and an
updated library is really loaded. Without Blender: each scenario runs in a
child Python, because writing over a mapped library crashes its process."""

import os
import shutil
import subprocess
import sys
import textwrap

import pytest

from voxlight.core import native

HERE = os.path.dirname(os.path.abspath(__file__))


@pytest.fixture()
def addon_dir(tmp_path):
    """A folder laid out like the installed add-on: the library and a helper
    without its execute bit (as Blender's zip install leaves it)."""
    d = tmp_path / "addon"
    d.mkdir()
    shutil.copyfile(os.environ["VOXLIGHT_LIB"], d / "libvoxlight.so")
    helper = d / "voxlight-read-test"
    helper.write_text("#!/bin/sh\nexit 0\n")
    helper.chmod(0o644)
    return d


def _child(code, cache, **env):
    e = dict(os.environ, VOXLIGHT_CACHE_DIR=str(cache), **env)
    e.pop("VOXLIGHT_LIB", None)
    prelude = "import sys; sys.path.insert(0, %r); import conftest; from voxlight.core import native\n" % HERE
    return subprocess.run([sys.executable, "-c", prelude + textwrap.dedent(code)], env=e,
                          capture_output=True, text=True, timeout=120)


def test_overwriting_the_installed_library_does_not_crash(addon_dir, tmp_path):
    lib = addon_dir / "libvoxlight.so"
    r = _child("""
        lib = native.load_library(%r)
        assert lib.path != lib.source_path, lib.path
        names = lib.filter_names()
        # What an add-on install does to the file it extracts over.
        size = len(open(%r, "rb").read())
        with open(%r, "r+b") as f:
            f.truncate(0)
            f.write(b"\\xcc" * size)
        assert lib.filter_names() == names
        print("SURVIVED", lib.path)
    """ % (str(lib), str(lib), str(lib)), tmp_path / "cache")
    assert r.returncode == 0 and "SURVIVED" in r.stdout, (r.returncode, r.stdout, r.stderr)


def test_copy_holds_the_helpers_executable(addon_dir, tmp_path, monkeypatch):
    monkeypatch.setenv("VOXLIGHT_CACHE_DIR", str(tmp_path / "cache"))
    path = native.private_copy(str(addon_dir / "libvoxlight.so"))
    folder = os.path.dirname(path)
    assert folder.startswith(str(tmp_path / "cache")), folder
    assert os.access(os.path.join(folder, "voxlight-read-test"), os.X_OK)
    with open(path, "rb") as a, open(addon_dir / "libvoxlight.so", "rb") as b:
        assert a.read() == b.read()


def test_changed_library_gets_another_copy_and_loads(addon_dir, tmp_path):
    lib = str(addon_dir / "libvoxlight.so")
    r = _child("""
        first = native.load_library(%r)
        with open(%r, "ab") as f:   # an update: other bytes, same meaning
            f.write(b"\\0update\\0")
        second = native.load_library(%r, reload=True)
        assert second.path != first.path, (first.path, second.path)
        maps = open("/proc/self/maps").read()
        assert second.path in maps and %r not in maps
        assert second.filter_names()
        print("OK")
    """ % (lib, lib, lib, lib), tmp_path / "cache")
    assert r.returncode == 0 and "OK" in r.stdout, (r.stdout, r.stderr)


def test_stale_copies_go_and_held_ones_stay(addon_dir, tmp_path):
    cache = tmp_path / "cache"
    lib = str(addon_dir / "libvoxlight.so")
    holder = subprocess.Popen(
        [sys.executable, "-c", "import sys; sys.path.insert(0, %r); import conftest\n"
         "from voxlight.core import native\nprint(native.load_library(%r).path, flush=True)\n"
         "sys.stdin.read()" % (HERE, lib)],
        env=dict(os.environ, VOXLIGHT_CACHE_DIR=str(cache)), stdin=subprocess.PIPE,
        stdout=subprocess.PIPE, text=True)
    try:
        held = os.path.dirname(holder.stdout.readline().strip())
        assert os.path.isdir(held), held
        stale = cache / ("f" * 24)
        shutil.copytree(held, stale)
        native.clean_stale_copies(str(cache))
        assert not stale.exists()
        assert os.path.isdir(held)  # another process uses it
    finally:
        holder.communicate("", timeout=60)
    native.clean_stale_copies(str(cache))
    assert not os.path.exists(held)


def test_unwritable_cache_falls_back_to_loading_in_place(addon_dir, tmp_path, monkeypatch):
    monkeypatch.setattr(native, "cache_roots", lambda *a: [str(tmp_path / "file" / "x")])
    (tmp_path / "file").write_text("not a folder")
    assert native.private_copy(str(addon_dir / "libvoxlight.so")) is None
