"""The volume's F12 shadow on the scene follows what the volume shows: a
clip plane that removes one of two balls, or hiding that ball's label,
takes exactly that ball's shadow off the floor, and the shadow comes back
with the ball. (The shadow used to stay whole: the illumination volume it
is read from ignored cutaways and labels.)

The scene: a label map of two balls side by side along x (labels 1 and 2,
opaque), 1 unit above a white floor, a Sun straight down, an orthographic
camera looking down at 30 degrees from -Y; Cycles with a few samples. Each
ball's shadow centre is its centre dropped onto the floor, found from the
volume's placement, never hard-coded.

blender -b --factory-startup --python-exit-code 1 --python tests/blender/test_shadow_follows_cut.py
"""

import math
import os
import sys

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import _util as u  # noqa: E402
from _util import test  # noqa: E402

vx = u.install_addon()
W, H = 128, 96
DIMS = (40, 20, 20)
CENTRES = (10.0, 30.0)  # voxel x of labels 1 and 2 (balls of radius 7 voxels, 5 mm voxels)
LUT = ("#No. Label Name:                R   G   B   A\n"
       "0   Unknown                     0   0   0   0\n"
       "1   Left                      255 255 255   0\n"
       "2   Right                     255 255 255   0\n")


def _atlas():
    d = os.path.join(u.TMP, "two_balls")
    os.makedirs(d, exist_ok=True)
    i, j, k = np.meshgrid(*[np.arange(n, dtype=np.float64) for n in DIMS], indexing="ij")
    data = np.zeros(DIMS, np.uint8)
    for label, cx in enumerate(CENTRES, 1):
        data[(i - cx) ** 2 + (j - (DIMS[1] - 1) / 2) ** 2 + (k - (DIMS[2] - 1) / 2) ** 2 <= 7.0 ** 2] = label
    aff = np.diag([5.0, 5.0, 5.0, 1.0])
    aff[:3, 3] = [-(n - 1) * 2.5 for n in DIMS]
    path = u.write_nifti(os.path.join(d, "two_balls.nii.gz"), data, aff)
    with open(os.path.join(d, "two_balls_LUT.txt"), "w") as f:
        f.write(LUT)
    return path


def _scene():
    scene = u.reset_scene()
    scene.render.engine = "CYCLES"
    scene.cycles.samples = 4
    scene.cycles.use_denoising = False  # Debian's Cycles has no OIDN
    scene.render.film_transparent = False
    scene.view_settings.view_transform = "Standard"
    scene.render.resolution_x, scene.render.resolution_y = W, H
    floor = u.add_plane((8.0, 8.0), (0.0, 0.0, 0.0), name="Floor", color=(0.8, 0.8, 0.8))
    bsdf = floor.data.materials[0].node_tree.nodes["Principled BSDF"]
    if "Emission Strength" in bsdf.inputs:
        bsdf.inputs["Emission Strength"].default_value = 0.0
    else:
        (bsdf.inputs.get("Emission Color") or bsdf.inputs["Emission"]).default_value = (0, 0, 0, 1)
    bpy.context.scene.cursor.location = (0.0, 0.0, 1.0)
    ob = u.import_volume(_atlas())
    assert ob.voxlight_labels.enabled, "the atlas imports as a label map"
    ob.voxlight.jitter = False
    # Shown labels shadow with the transfer function's opacity: a window
    # below both ids makes both balls opaque.
    ob.voxlight.window_low, ob.voxlight.window_high = 0.0, 0.5
    ob.voxlight.opacity_scale = 8.0
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy = 3.0
    sun.data.angle = 0.0
    scene.collection.objects.link(sun)
    cam = u.add_camera((0.0, -6.0 * math.cos(math.radians(30)), 6.0 * math.sin(math.radians(30))),
                       target=(0.0, 0.0, 0.4))
    cam.data.type = "ORTHO"
    cam.data.ortho_scale = 3.5
    bpy.context.view_layer.update()
    return scene, ob


def _shadow_centres(ob):
    """World points on the floor straight under ball 1 and ball 2."""
    model = vx.params.model_matrix(ob)
    c = (np.array(DIMS, np.float64) - 1) / 2
    out = []
    for cx in CENTRES:
        p = (model @ np.array([cx, c[1], c[2], 1.0]))[:3]
        out.append(np.array([p[0], p[1], 0.0]))
    return out


def _pixel(scene, world):
    dg = bpy.context.evaluated_depsgraph_get()
    view, proj = vx.offline.camera_matrices(scene.camera, dg, W, H, scene)
    clip = proj @ view @ np.array([*world, 1.0])
    return (clip[0] / clip[3] + 1) * W / 2, (clip[1] / clip[3] + 1) * H / 2


def _light(img, scene, world, radius_px=3.0):
    """Mean linear brightness of a disc of the image around a world point."""
    cx, cy = _pixel(scene, world)
    ys, xs = np.mgrid[0:H, 0:W]
    disc = (xs + 0.5 - cx) ** 2 + (ys + 0.5 - cy) ** 2 < radius_px ** 2
    assert disc.sum() > 15, (cx, cy)
    c = np.clip(img[disc][:, :3], 0.0, 1.0)
    return float(np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4).mean())


def _darkening(scene, ob, name):
    """Per ball: the floor's brightness under it over the lit floor's."""
    scene.render.filepath = os.path.join(u.TMP, name + ".png")
    bpy.ops.render.render(write_still=True)
    img = u.load_png(scene.render.filepath)
    lit = _light(img, scene, np.array([0.0, -1.3, 0.0]))
    assert lit > 0.05, lit
    return [_light(img, scene, p) / lit for p in _shadow_centres(ob)]


@test
def a_clip_plane_takes_the_shadow_of_what_it_removes_off_the_floor():
    scene, ob = _scene()
    whole = _darkening(scene, ob, "cut_none")
    assert bpy.ops.voxlight.add_clip_plane() == {"FINISHED"}
    plane = ob.voxlight.clip_planes[-1].object
    first, second = _shadow_centres(ob)
    # The plane through the volume's centre, its normal (local +Z, the side
    # kept) towards ball 2: ball 1 is removed.
    plane.location = ((first + second) / 2)[:2].tolist() + [1.0]
    towards = second - first
    plane.rotation_euler = (0.0, math.copysign(math.pi / 2, towards[0]), 0.0)
    bpy.context.view_layer.update()
    cut = _darkening(scene, ob, "cut_plane")
    ob.voxlight.clip_planes[0].object = None
    bpy.context.view_layer.update()
    back = _darkening(scene, ob, "cut_removed")
    print("shadow/lit per ball: whole %s, cut %s, plane emptied %s" % (whole, cut, back), flush=True)
    assert whole[0] < 0.5 and whole[1] < 0.5, whole
    assert cut[0] > 0.85, cut   # ball 1 is cut away: no shadow under it
    assert cut[1] < 0.5, cut    # ball 2 still shadows
    assert back[0] < 0.5 and back[1] < 0.5, back


@test
def hiding_a_label_takes_its_shadow_off_the_floor():
    scene, ob = _scene()
    labels = ob.voxlight_labels.labels
    assert [lab.label_id for lab in labels] == [1, 2]
    whole = _darkening(scene, ob, "labels_all")
    labels[0].visible = False
    hidden = _darkening(scene, ob, "labels_hidden")
    labels[0].visible = True
    back = _darkening(scene, ob, "labels_back")
    print("shadow/lit per ball: all %s, label 1 hidden %s, shown again %s" % (whole, hidden, back), flush=True)
    assert whole[0] < 0.5 and whole[1] < 0.5, whole
    assert hidden[0] > 0.85, hidden
    assert hidden[1] < 0.5, hidden
    assert back[0] < 0.5 and back[1] < 0.5, back


u.run("test_shadow_follows_cut")
