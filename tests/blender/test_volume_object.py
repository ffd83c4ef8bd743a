"""Headless Blender: a Volume object (OpenVDB written by pyopenvdb) with
"Render with Voxlight" on renders like an imported volume at
matrix_world x grid transform, in render_volume and in F12; off restores
Blender's display; broken files and sequences.

blender -b --factory-startup --python-exit-code 1 --python tests/blender/test_volume_object.py
"""

import os
import sys

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import _util as u  # noqa: E402
from _util import test  # noqa: E402
from vdb_write import write_vdb  # noqa: E402

vx = u.install_addon()
RES = (64, 64)
# grid transform: rotated about z, 0.05 units per voxel, offset
GRID = np.array([[0.0, -0.05, 0.0, 0.2],
                 [0.05, 0.0, 0.0, -0.1],
                 [0.0, 0.0, 0.05, 0.0],
                 [0.0, 0.0, 0.0, 1.0]])


def _ball(n=(20, 16, 12)):
    i, j, k = np.meshgrid(*[np.arange(m, dtype=np.float64) for m in n], indexing="ij")
    c = (np.asarray(n) - 1) / 2.0
    r = np.sqrt(((i - c[0]) / c[0]) ** 2 + ((j - c[1]) / c[1]) ** 2 + ((k - c[2]) / c[2]) ** 2)
    return (0.02 + np.clip(1.2 - r, 0.0, None)).astype(np.float32)


def _vdb(name="ball.vdb", array=None, ijk=(-10, -8, -6)):
    return write_vdb(os.path.join(u.TMP, name), [
        {"name": "density", "array": _ball() if array is None else array, "ijk": ijk, "affine": GRID}])


def _volume_object(path, name="Smoke"):
    vol = bpy.data.volumes.new(name)
    vol.filepath = path
    ob = bpy.data.objects.new(name, vol)
    bpy.context.scene.collection.objects.link(ob)
    return ob


def _scene():
    scene = u.reset_scene()
    u.add_camera((0.0, -3.0, 0.4))
    return scene


def _render(ob):
    ob.voxlight.jitter = False
    return vx.render_volume(ob, resolution=RES)


@test
def toggle_renders_like_an_imported_volume():
    _scene()
    path = _vdb()
    ob = _volume_object(path)
    ob.location = (0.1, 0.2, -0.1)
    ob.rotation_euler = (0.3, 0.0, 0.5)
    ob.scale = (1.5, 1.5, 1.5)
    old_display = ob.display_type
    ob.voxlight_vdb.enabled = True
    p = ob.voxlight
    assert ob.voxlight_vdb.error == "", ob.voxlight_vdb.error
    assert p.is_volume and tuple(p.dims) == (20, 16, 12)
    assert os.path.samefile(p.filepath, path)
    expected = GRID.copy()
    expected[:3, 3] = (GRID @ np.array([-10, -8, -6, 1.0]))[:3]  # voxel 0 is index (-10, -8, -6)
    v2l = np.array(p.voxel_to_local).reshape(4, 4).T
    assert np.allclose(v2l, expected, atol=1e-6), v2l
    assert ob.display_type == "BOUNDS" and not ob.show_in_front  # meshes hide the box
    img = _render(ob)
    assert img[..., 3].max() > 0.3 and img[0, 0, 3] < 0.01
    # The same file imported as an Empty (no centring, scene units) and
    # given the same object transform renders the same picture.
    em = u.import_volume(path, center=False)
    from mathutils import Matrix
    em.matrix_world = ob.matrix_world @ Matrix(v2l.tolist()) @ Matrix(
        np.linalg.inv(np.array(em.voxlight.voxel_to_local).reshape(4, 4).T).tolist())
    ref = _render(em)
    assert np.abs(img - ref).max() < 2e-3, np.abs(img - ref).max()
    # Moving the Volume object moves the render.
    ob.location.x += 0.3
    bpy.context.view_layer.update()
    moved = _render(ob)
    assert np.abs(moved - img).max() > 0.1
    ob.voxlight_vdb.enabled = False
    assert not p.is_volume and ob.display_type == old_display


@test
def f12_composites_the_volume_object():
    scene = _scene()
    scene.render.engine = "CYCLES"
    scene.cycles.samples = 1
    scene.cycles.use_denoising = False
    scene.cycles.device = "CPU"
    scene.render.resolution_x = scene.render.resolution_y = 64
    scene.world.color = (0.0, 0.0, 0.0)
    if scene.world.node_tree is not None:  # (World.use_nodes is deprecated in 5.0)
        scene.world.node_tree.nodes["Background"].inputs["Color"].default_value = (0, 0, 0, 1)
    scene.view_settings.view_transform = "Standard"
    ob = _volume_object(_vdb())
    ob.voxlight_vdb.enabled = True
    ob.voxlight.jitter = False
    scene.render.filepath = os.path.join(u.TMP, "volume_object_f12.png")
    bpy.ops.render.render(write_still=True)
    img = u.load_png(scene.render.filepath)
    expected = _render(ob)
    hit = expected[..., 3] > 0.5
    assert hit.sum() > 20, hit.sum()
    assert img[..., :3][hit].mean() > 0.2  # the volume shows where render_volume sees it
    assert img[1, 1, :3].max() < 0.02      # black elsewhere


@test
def broken_file_shows_an_error_and_changes_nothing():
    _scene()
    bad = os.path.join(u.TMP, "broken.vdb")
    with open(bad, "wb") as f:
        f.write(b" BDV" + b"\1" * 64)
    ob = _volume_object(bad, "Broken")
    display = ob.display_type
    ob.voxlight_vdb.enabled = True
    assert "broken.vdb" in ob.voxlight_vdb.error
    assert not ob.voxlight.is_volume and ob.display_type == display
    # fixed on disk: the panel's reload button loads it
    write_vdb(bad, [{"name": "density", "array": _ball(), "affine": GRID}])
    bpy.context.view_layer.objects.active = ob
    assert bpy.ops.voxlight.volume_object_reload() == {"FINISHED"}
    assert ob.voxlight.is_volume and ob.voxlight_vdb.error == "" and ob.display_type == "BOUNDS"
    ob.voxlight_vdb.enabled = False
    assert ob.voxlight_vdb.error == "" and ob.display_type == display


@test
def sequence_uses_the_current_frames_file():
    scene = _scene()
    _vdb("seq_0001.vdb", array=_ball((10, 10, 10)))
    path2 = _vdb("seq_0002.vdb", array=_ball((14, 12, 10)))
    ob = _volume_object(os.path.join(u.TMP, "seq_0001.vdb"), "Seq")
    vol = ob.data
    vol.is_sequence = True
    vol.frame_start = 1
    vol.frame_duration = 2
    scene.frame_set(2)
    ob.voxlight_vdb.enabled = True
    assert ob.voxlight_vdb.error == "", ob.voxlight_vdb.error
    assert tuple(ob.voxlight.dims) == (14, 12, 10), tuple(ob.voxlight.dims)
    assert os.path.samefile(ob.voxlight.filepath, path2)


@test
def survives_save_and_reload():
    _scene()
    ob = _volume_object(_vdb())
    ob.voxlight_vdb.enabled = True
    before = _render(ob)
    blend = os.path.join(u.TMP, "volume_object.blend")
    bpy.ops.wm.save_as_mainfile(filepath=blend)
    bpy.ops.wm.open_mainfile(filepath=blend)
    ob = bpy.data.objects["Smoke"]
    assert ob.voxlight_vdb.enabled and ob.voxlight.is_volume
    assert np.abs(_render(ob) - before).max() < 2e-3


u.run("test_volume_object")
