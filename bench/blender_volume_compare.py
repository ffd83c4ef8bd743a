"""Cycles against Voxlight on a converted volume (docs/physical_model.md,
"Cycles against Voxlight"): the test phantom (tests/blender/_util.py's noisy
ball), rendered by Voxlight's F12 and, after Convert to Blender Volume, by
Cycles from the same camera at several sample counts. Prints a markdown
table: Cycles' samples and time, RMSE and PSNR (linear RGB, 0..1, before the
view transform, whole image) against Voxlight, and against Cycles' own
render at the most samples (its noise alone); then the mean values, with the
library's own image before the add-on's F12 decodes it from sRGB.

  --shading off      pure emission-absorption (the exact case)
  --shading scatter  one sun, Voxlight's scatter model with no surface term
                     (gradient reference 1000) and no ambient light, against
                     Cycles' single scattering (one volume bounce) with the
                     sun's strength 4 pi * diffuse times Voxlight's

blender -b --factory-startup --python bench/blender_volume_compare.py -- [--shading off|scatter]
        [--size 128] [--samples 1,4,16,64,256] [--resolution 0] [--opacity 0.2]
(the add-on installed from build/voxlight-linux-x64.zip, as the Blender tests do)
"""

import argparse
import math
import os
import sys
import time

import bpy
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(os.path.dirname(HERE), "tests", "blender"))
import _util as u  # noqa: E402


def _args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    ap = argparse.ArgumentParser()
    ap.add_argument("--shading", choices=("off", "scatter"), default="off")
    ap.add_argument("--size", type=int, default=128)
    ap.add_argument("--samples", default="1,4,16,64,256")
    ap.add_argument("--resolution", type=int, default=0)
    ap.add_argument("--opacity", type=float, default=0.2)
    return ap.parse_args(argv)


def _render(scene, size, name):
    scene.render.filepath = os.path.join(u.TMP, name + ".exr")
    t = time.perf_counter()
    bpy.ops.render.render(write_still=True)
    seconds = time.perf_counter() - t
    img = bpy.data.images.load(scene.render.filepath, check_existing=False)
    px = np.empty(size * size * 4, np.float32)
    img.pixels.foreach_get(px)
    bpy.data.images.remove(img)
    return px.reshape(size, size, 4)[..., :3], seconds


def _rmse(a, b):
    return float(np.sqrt(np.mean((a - b) ** 2)))


def _psnr(rmse):
    return 20 * math.log10(1.0 / rmse) if rmse > 0 else float("inf")


def main():
    a = _args()
    vx = u.install_addon()
    scene = u.black_cycles_scene(a.size)
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    ob = u.import_volume(u.ball_file())
    ob.voxlight.jitter = False
    ob.voxlight.opacity_scale = a.opacity
    u.add_camera((0.0, -2.0, 0.0))
    if a.shading == "off":
        ob.voxlight.shading = False
        scene.cycles.max_bounces = 0
    else:
        ob.voxlight.shading = True
        ob.voxlight.shading_model = "scatter"
        ob.voxlight.gradient_ref = 1000.0
        ob.voxlight.ambient = 0.0
        sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
        sun.rotation_euler = (math.radians(50), 0.0, math.radians(30))
        scene.collection.objects.link(sun)
        sun.data.angle = 0.0
        sun.data.energy = 1.0  # Voxlight: L = 1
        scene.cycles.max_bounces = scene.cycles.volume_bounces = 1
    ours, t_ours = _render(scene, a.size, "voxlight")
    # the library's own image (scene-linear, what F12 composites) through the scripting API
    library = vx.render_volume(ob)[..., :3]
    vo = bpy.ops.voxlight.convert_to_blender_volume(resolution=a.resolution)
    vo = bpy.context.view_layer.objects.active
    ob.hide_render = True
    if a.shading == "scatter":
        # docs/physical_model.md section 3: Cycles' irradiance = 4 pi diffuse L
        sun.data.energy = 4 * math.pi * ob.voxlight.diffuse
    counts = [int(s) for s in a.samples.split(",")]
    rows = []
    for s in counts:
        scene.cycles.samples = s
        img, t = _render(scene, a.size, "cycles_%d" % s)
        rows.append((s, t, img))
    best = rows[-1][2]
    print("\nshading %s, %dx%d, grid resolution %s, opacity scale %g; Voxlight F12 %.2f s (Blender %s)"
          % (a.shading, a.size, a.size, a.resolution or "one cell per voxel", a.opacity, t_ours,
             bpy.app.version_string))
    print("| Cycles samples | Cycles s | RMSE vs Voxlight | PSNR vs Voxlight (dB) | RMSE vs Cycles %d |" % counts[-1])
    print("|---|---|---|---|---|")
    for s, t, img in rows:
        r = _rmse(img, ours)
        print("| %d | %.2f | %.4f | %.1f | %.4f |" % (s, t, r, _psnr(r), _rmse(img, best)))
    print("mean value: Voxlight F12 (linear) %.4f, the library's own image (linear) %.4f, Cycles %d "
          "samples %.4f; RMSE of the library's image against it %.4f"
          % (ours.mean(), library.mean(), counts[-1], best.mean(), _rmse(library, best)))


main()
