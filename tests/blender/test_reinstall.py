"""Updating the add-on in a running Blender: install, enable, install the
same zip again over the enabled add-on, re-enable, render; then an updated
zip (another library), and a zip whose library has another ABI. Blender
must never crash, the library must never be mapped from the folder an
install writes into, and the add-on must always say what is wrong.

blender -b --factory-startup --python-exit-code 1 --python tests/blender/test_reinstall.py
(or build/bpy/X.Y/bin/python tests/blender/test_reinstall.py)
"""

import os
import shutil
import subprocess
import sys
import zipfile

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import _util as u  # noqa: E402
from _util import test  # noqa: E402

vx = u.install_addon()


def _render_ball(mod):
    u.reset_scene()
    ob = u.import_volume(u.ball_file())
    u.add_camera((0.0, -2.5, 0.3))
    img = mod.render_volume(ob, resolution=(32, 32))
    assert img[..., 3].max() > 0.5, img[..., 3].max()


def _mapped_files():
    with open("/proc/self/maps") as f:
        return {line.split(None, 5)[5].strip() for line in f if len(line.split(None, 5)) == 6}


def _nothing_mapped_from_the_addon(mod):
    """An install writes into the add-on's folder: nothing there may be
    mapped into this process (writing over a mapped library crashes)."""
    folder = os.path.realpath(os.path.dirname(mod.__file__))
    mapped = [p for p in _mapped_files() if os.path.realpath(p).startswith(folder + os.sep)]
    assert not mapped, mapped
    lib = mod.core.native.load_library()
    assert os.path.realpath(lib.path) in {os.path.realpath(p) for p in _mapped_files()}, lib.path


def _variant_zip(name, replace_library):
    """A copy of the built zip with voxlight/libvoxlight.so replaced by
    replace_library(original bytes) -> bytes."""
    out = os.path.join(u.TMP, name)
    with zipfile.ZipFile(u.zip_path()) as src, zipfile.ZipFile(out, "w", zipfile.ZIP_DEFLATED) as dst:
        for info in src.infolist():
            data = src.read(info.filename)
            if info.filename.endswith("/libvoxlight.so"):
                data = replace_library(data)
            dst.writestr(info, data)
    return out


@test
def zip_has_directory_entries():
    # Blender's legacy overwrite removes the zip's top-level entries: the
    # voxlight/ entry makes it remove the old folder instead of writing the
    # new files over it.
    with zipfile.ZipFile(u.zip_path()) as z:
        names = z.namelist()
    assert "voxlight/" in names, names[:5]
    helpers = [n for n in names if os.path.basename(n).startswith("voxlight-read-")
               or n.endswith("/voxlight-vdb-read")]
    assert helpers, names


@test
def library_is_a_private_copy_with_its_helpers():
    lib = vx.core.native.load_library()
    assert lib.path != lib.source_path
    private = os.environ.get("BLENDER_USER_EXTENSIONS")
    if u.uses_extensions() and private:  # the extension's own user folder
        assert os.path.realpath(lib.path).startswith(os.path.realpath(private) + os.sep), lib.path
    src, copy = os.path.dirname(lib.source_path), os.path.dirname(lib.path)
    for name in vx.core.native.helper_names(src):
        assert os.access(os.path.join(copy, name), os.X_OK), name
        assert os.access(os.path.join(src, name), os.X_OK), name  # execute bit restored
    _nothing_mapped_from_the_addon(vx)


@test
def reinstall_same_zip_then_reenable_and_render():
    global vx
    _render_ball(vx)
    before = vx.core.native.load_library().path
    vx = u.install_addon()  # over the enabled add-on
    u.disable()
    vx = u.enable()
    _render_ball(vx)
    assert vx.core.native.load_library().path == before  # same content, same copy
    _nothing_mapped_from_the_addon(vx)
    # And again, the way a user may click it twice.
    vx = u.install_addon()
    vx = u.install_addon()
    _render_ball(vx)


@test
def updated_library_is_loaded_after_reinstall():
    global vx
    before = vx.core.native.load_library().path
    # Bytes after the end of an ELF file change its hash, not its meaning.
    z = _variant_zip("updated.zip", lambda data: data + b"\0voxlight update test\0")
    vx = u.install_addon(z)
    lib = vx.core.native.load_library()
    assert lib.path != before, "the old library is still in use"
    with open(lib.path, "rb") as a, open(lib.source_path, "rb") as b:
        assert a.read() == b.read()
    _render_ball(vx)
    _nothing_mapped_from_the_addon(vx)


@test
def library_of_another_abi_is_refused_with_a_message():
    global vx
    src = os.path.join(u.TMP, "abi2.c")
    so = os.path.join(u.TMP, "abi2.so")
    with open(src, "w") as f:
        f.write("unsigned vxl_abi_version(void) { return 2; }\n")
    subprocess.run(["cc", "-shared", "-fPIC", "-o", so, src], check=True)
    with open(so, "rb") as f:
        abi2 = f.read()
    vx = u.install_addon(_variant_zip("abi2.zip", lambda data: abi2), check_library=False)
    ok, msg = vx.library_status()
    assert not ok and "ABI version 2" in msg, msg
    # The UI is up to show it, and an import says it instead of a traceback.
    assert "VOXLIGHT_PT_volume" in dir(bpy.types)
    before = set(bpy.data.objects)
    try:
        bpy.ops.voxlight.import_volume(filepath=u.ball_file())
        raise AssertionError("import worked without a usable library")
    except RuntimeError as e:
        assert "ABI version 2" in str(e), e
    assert set(bpy.data.objects) == before
    # Installing the right zip over it brings everything back.
    vx = u.install_addon()
    _render_ball(vx)


@test
def private_copies_are_cleaned_when_unused():
    lib = vx.core.native.load_library()
    root = os.path.dirname(os.path.dirname(lib.path))
    stale = os.path.join(root, "0" * 24)
    shutil.copytree(os.path.dirname(lib.path), stale)
    vx.core.native.clean_stale_copies(root)
    assert not os.path.exists(stale)
    assert os.path.isfile(lib.path)  # the copy in use stays
    _render_ball(vx)


def legacy_install_over_itself_survives_too():
    """4.2+ still installs legacy add-ons (bl_info) from the same zip; that
    installer extracts over the old files, the path that crashed. (In 3.x
    every test above already takes it.)"""
    global vx
    u.disable()  # the extension: both at once would register the same names
    try:
        vx = u.install_addon(legacy=True)
        assert u.MODULE == "voxlight", u.MODULE
        _render_ball(vx)
        vx = u.install_addon(legacy=True)  # over the enabled add-on
        _render_ball(vx)
        _nothing_mapped_from_the_addon(vx)
    finally:
        u.disable()


if u.uses_extensions():
    test(legacy_install_over_itself_survives_too)

u.run("test_reinstall")
