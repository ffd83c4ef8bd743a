"""Shared helpers of the Blender test scripts (run inside Blender).

Each script calls install_addon(), registers tests with @test and ends with
run(), which prints one `RESULT name: N passed, M failed` line (parsed by
tools/run_blender_tests.sh) and exits non-zero on failure. Scripts run with
--python-exit-code 1 so an unexpected exception also fails them.
"""

import os
import sys
import tempfile
import time
import traceback
import types

import bpy
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, "tests", "python"))

from nifti_write import phantom, write_nifti  # noqa: E402,F401

# VOXLIGHT_TEST_GPU_INIT=1: initialise the gpu module first, as a background
# script that draws with it must in Blender 5.2 and later (gpu.init()); the
# add-on's renders must work with and without that. tools/run_blender_tests.sh
# sets it only where gpu.init exists, so a missing one fails here.
if os.environ.get("VOXLIGHT_TEST_GPU_INIT") == "1":
    import gpu
    gpu.init()

CH2 = "/usr/share/mricron/templates/ch2better.nii.gz"
TMP = tempfile.mkdtemp(prefix="voxlight-blender-test-")
_tests = []


def zip_path():
    build = os.environ.get("BUILD", "build")
    if not os.path.isabs(build):
        build = os.path.join(ROOT, build)
    return os.environ.get("VOXLIGHT_ZIP", os.path.join(build, "voxlight-linux-x64.zip"))


# The add-on's module name: "voxlight" as a legacy add-on (3.x),
# "bl_ext.<repo>.voxlight" as an extension (4.2+). Set by install_addon().
MODULE = None
EXTENSION_REPO = "user_default"  # the local repo every 4.2+ Blender starts with


def uses_extensions():
    """Blender 4.2+ installs the zip as an extension (manifest read and
    validated); older ones as a legacy add-on (bl_info)."""
    return bpy.app.version >= (4, 2, 0)


def installed_module():
    return sys.modules[MODULE]


def install_addon(path=None, check_library=True, legacy=False):
    """Install the zip the way a user does (overwriting an installed copy,
    which may be enabled), enable it and return the add-on's package
    module. legacy: install as a legacy add-on even where Blender has
    extensions (4.2+ still offers "Install legacy Add-on")."""
    global MODULE
    z = path or zip_path()
    assert os.path.isfile(z), "%s missing: run tools/package_addon.sh" % z
    t = time.time()
    as_extension = uses_extensions() and not legacy
    if as_extension:
        repos = bpy.context.preferences.extensions.repos
        repo = next(r for r in repos if r.module == EXTENSION_REPO)
        assert not repo.use_remote_url, "%s is not a local repository" % EXTENSION_REPO
        private = os.environ.get("BLENDER_USER_EXTENSIONS")
        if private:  # never touch the user's own extensions
            assert os.path.realpath(repo.directory).startswith(os.path.realpath(private)), \
                repo.directory
        MODULE = "bl_ext.%s.voxlight" % EXTENSION_REPO
        import addon_utils
        # Over an enabled add-on, Blender disables, replaces and enables it;
        # a first install is enabled separately, to time the add-on's load.
        was_enabled = addon_utils.check(MODULE)[1]
        res = bpy.ops.extensions.package_install_files(
            filepath=z, repo=EXTENSION_REPO, enable_on_install=was_enabled, overwrite=True)
        assert res == {"FINISHED"}, res
        if not was_enabled:
            enable()
    else:
        res = bpy.ops.preferences.addon_install(filepath=z, overwrite=True)
        assert res == {"FINISHED"}, res
        MODULE = "voxlight"
        import addon_utils
        if addon_utils.check(MODULE)[1]:
            disable()  # an update: the user unticks and ticks the add-on
        enable()
    import addon_utils
    assert addon_utils.check(MODULE)[1], "%s is not enabled" % MODULE
    print("install_addon: Blender %s, %s as %s in %.2f s" % (
        bpy.app.version_string, "extension" if as_extension else "legacy add-on", MODULE,
        time.time() - t), flush=True)
    mod = installed_module()
    if check_library:
        ok, msg = mod.library_status()
        assert ok, msg
        # The library must be the one shipped inside the installed add-on.
        lib_dir = os.path.dirname(mod.core.native.load_library().source_path)
        assert lib_dir == os.path.dirname(mod.__file__), (lib_dir, mod.__file__)
    return mod


def enable():
    """Enable the installed add-on; returns its module."""
    t = time.time()
    res = bpy.ops.preferences.addon_enable(module=MODULE)
    assert res == {"FINISHED"}, res
    print("enable: %.3f s" % (time.time() - t), flush=True)
    return installed_module()


def disable():
    res = bpy.ops.preferences.addon_disable(module=MODULE)
    assert res == {"FINISHED"}, res


def is_ours(module_name):
    """Whether a function's __module__ belongs to the add-on."""
    return module_name == MODULE or (module_name or "").startswith(MODULE + ".")


def ball_file(name="ball.nii.gz", n=32, spacing=(2.0, 2.0, 2.0)):
    """The test phantom as a NIfTI with its centre at the scanner origin."""
    aff = np.diag(list(spacing) + [1.0])
    aff[:3, 3] = [-(n - 1) / 2.0 * s for s in spacing]
    return write_nifti(os.path.join(TMP, name), phantom(n), aff)


def test(fn):
    _tests.append(fn)
    return fn


def test_oldest_and_newest(fn):
    """A test that runs in the oldest and the newest Blender of a suite run
    only (tools/run_blender_tests.sh sets VOXLIGHT_BLENDER_COVERAGE=api in
    the releases between): for slow tests of what the library does
    (memory, streaming) or of a renderer generation the two ends already
    cover (EEVEE Legacy in 3.4, EEVEE Next in the newest), where the middle
    releases add run time but no Blender API the ends do not call. Run by
    hand, without the variable, it always runs."""
    if os.environ.get("VOXLIGHT_BLENDER_COVERAGE") != "api":
        _tests.append(fn)
    return fn


def run(name):
    passed = failed = 0
    for fn in _tests:
        t = time.time()
        try:
            fn()
        except Exception:
            failed += 1
            traceback.print_exc()
            print("FAIL %s (%.1fs)" % (fn.__name__, time.time() - t), flush=True)
        else:
            passed += 1
            print("PASS %s (%.1fs)" % (fn.__name__, time.time() - t), flush=True)
    print("RESULT %s: %d passed, %d failed" % (name, passed, failed), flush=True)
    if failed:
        sys.exit(1)


def reopen(objects, filename):
    """Save the file under TMP, drop the add-on's volumes and open it again,
    as a user reopening their work; returns the objects of the reopened
    file, in the order given."""
    names = [ob.name for ob in objects]
    path = os.path.join(TMP, filename)
    bpy.ops.wm.save_as_mainfile(filepath=path)
    installed_module().core.runtime.release_all()
    bpy.ops.wm.open_mainfile(filepath=path)
    return [bpy.data.objects[n] for n in names]


def reset_scene():
    """Empty the scene (factory startup has a cube, camera and light)."""
    for ob in list(bpy.data.objects):
        bpy.data.objects.remove(ob)
    scene = bpy.context.scene
    scene.frame_set(1)
    # Settings a previous test may have changed go back to their defaults.
    for prop in scene.voxlight.bl_rna.properties:
        if prop.identifier != "rna_type":
            scene.voxlight.property_unset(prop.identifier)
    # The suite's scenes are lit by their lamps and the headlight, with the
    # material's ambient term; the tests of the World's light turn it on.
    scene.voxlight.use_world_light = False
    scene.render.pixel_aspect_x = scene.render.pixel_aspect_y = 1.0
    scene.render.resolution_percentage = 100
    return scene


def black_cycles_scene(size, samples=4):
    """An empty scene rendering size x size pixels in Cycles on the CPU with
    a black world and the Standard view transform, so a pixel's colour is
    what was rendered and composited."""
    scene = reset_scene()
    scene.render.engine = "CYCLES"
    scene.cycles.samples = samples
    scene.cycles.use_denoising = False  # Debian's Cycles has no OIDN
    scene.cycles.device = "CPU"
    scene.render.resolution_x = scene.render.resolution_y = size
    scene.render.film_transparent = False
    if scene.world.node_tree is not None:  # (World.use_nodes is deprecated in 5.0)
        scene.world.node_tree.nodes["Background"].inputs["Color"].default_value = (0, 0, 0, 1)
    scene.world.color = (0.0, 0.0, 0.0)
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    return scene


def add_camera(location, target=(0.0, 0.0, 0.0), lens=50.0, name="Camera"):
    from mathutils import Vector
    cam = bpy.data.objects.new(name, bpy.data.cameras.new(name))
    cam.data.lens = lens
    cam.location = location
    direction = Vector(target) - Vector(location)
    cam.rotation_euler = direction.to_track_quat("-Z", "Y").to_euler()
    bpy.context.scene.collection.objects.link(cam)
    bpy.context.scene.camera = cam
    return cam


def add_plane(size, location, rotation=(0.0, 0.0, 0.0), name="Plane", color=(0.1, 0.9, 0.1)):
    """A flat opaque quad of the given size (x, y) facing +Z before rotation."""
    me = bpy.data.meshes.new(name)
    sx, sy = size[0] / 2.0, size[1] / 2.0
    me.from_pydata([(-sx, -sy, 0), (sx, -sy, 0), (sx, sy, 0), (-sx, sy, 0)], [], [(0, 1, 2, 3)])
    me.update()  # without it the viewport draws stale triangles
    ob = bpy.data.objects.new(name, me)
    ob.location = location
    ob.rotation_euler = rotation
    mat = bpy.data.materials.new(name)
    mat.diffuse_color = (*color, 1.0)
    if bpy.app.version < (5, 0, 0):  # 5.0: materials always use nodes (use_nodes deprecated)
        mat.use_nodes = True
    bsdf = mat.node_tree.nodes.get("Principled BSDF")
    if bsdf is not None:
        bsdf.inputs["Base Color"].default_value = (*color, 1.0)
        # "Emission" became "Emission Color" in 4.0, whose strength is 0 by default.
        emission = bsdf.inputs.get("Emission Color") or bsdf.inputs["Emission"]
        emission.default_value = (*color, 1.0)
        if "Emission Strength" in bsdf.inputs:
            bsdf.inputs["Emission Strength"].default_value = 1.0
    me.materials.append(mat)
    bpy.context.scene.collection.objects.link(ob)
    return ob


def import_volume(path, **kw):
    before = set(bpy.data.objects)
    res = bpy.ops.voxlight.import_volume(filepath=str(path), **kw)
    assert res == {"FINISHED"}, res
    new = set(bpy.data.objects) - before
    assert len(new) == 1, new
    return new.pop()


def load_png(path):
    """Pixels of an image file as (h, w, 4) float, row 0 = bottom."""
    img = bpy.data.images.load(path, check_existing=False)
    try:
        w, h = img.size
        px = np.empty(w * h * 4, np.float32)
        img.pixels.foreach_get(px)
        return px.reshape(h, w, 4)
    finally:
        bpy.data.images.remove(img)


class Layout:
    """Stands in for a UILayout in panel tests (its rows, columns and boxes
    are itself): `drawn` lists the properties, operators, lists and texts
    drawn."""

    def __init__(self):
        self.drawn = []

    def prop(self, data, name, **kw):
        self.drawn.append(name)

    def operator(self, idname, **kw):
        self.drawn.append(idname)
        return types.SimpleNamespace()

    def label(self, text="", **kw):
        self.drawn.append(text)

    def template_list(self, list_type, *args, **kw):
        self.drawn.append(list_type)

    def row(self, **kw):
        return self

    column = box = split = row
