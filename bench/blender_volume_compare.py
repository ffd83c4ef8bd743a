"""Cycles against Voxlight on a converted volume (docs/physical_model.md,
"Cycles against Voxlight"; docs/lighting.md, "Cycles as the ground truth").

A phantom is rendered by Voxlight's F12 and, after Convert to Blender Volume,
by Cycles from the same camera at several sample counts. Errors are RMSE and
PSNR over the whole image, linear RGB (0..1) before the view transform.

  --shading off      pure emission-absorption (the exact case)
  --shading scatter  Voxlight's scatter model (single scattering) against
                     Cycles with no volume bounce (direct light at the first
                     scattering event only)
  --shading path     Voxlight's path model with --bounces B collisions a
                     path against Cycles with B - 1 volume bounces (Cycles
                     counts the bounces after the first scattering event);
                     Voxlight is rendered at each of --path-samples, Cycles
                     at each of --samples, and both are measured against
                     Cycles' render at the most samples (the ground truth)

For scatter and path the surface term is off (gradient reference 1000, so
the medium is Cycles' Principled Volume everywhere) and the material's
ambient is 0. The light (--light):
  sun    one sun, Voxlight's strength 1; Cycles' 4 pi * diffuse times it
         (physical_model.md section 3)
  point  one point light 1 m from the phantom's centre, Voxlight's power
         1000 W (radiance 1); Cycles' power 16 pi^2 * diffuse * r^2 W, which
         gives the same irradiance at the centre (Voxlight's point lights have
         no fall-off, so the two agree only at the centre's distance)
  world  an HDRI-only World (a generated sky with a bright patch, no lamp),
         Voxlight's strength 1; Cycles' strength diffuse times it (Voxlight
         scatters diffuse * colour * E of the World's irradiance E); the sky
         itself is not compared (a transparent film)
  uniform  a World of one colour (radiance 0.5), no lamp, as world
The phantom (--phantom): ball (tests/blender/_util.py's noisy ball, 32^3),
blobs (the two-blobs phantom of the library's tests, 48^3, white), or ch2
(MRIcron's ch2better MRI, 181x217x181, the default transfer function).

blender -b --factory-startup --python bench/blender_volume_compare.py -- [--shading off|scatter|path]
        [--light sun|point|world] [--phantom ball|blobs|ch2] [--size 128] [--samples 1,4,16,64,256]
        [--path-samples 1,4,16,64] [--bounces 4] [--resolution 0] [--opacity 0.2]
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
    ap.add_argument("--shading", choices=("off", "scatter", "path"), default="off")
    ap.add_argument("--light", choices=("sun", "point", "world", "uniform"), default="sun")
    ap.add_argument("--phantom", choices=("ball", "blobs", "ch2"), default="ball")
    ap.add_argument("--size", type=int, default=128)
    ap.add_argument("--samples", default="1,4,16,64,256")
    ap.add_argument("--path-samples", default="1,4,16,64")
    ap.add_argument("--bounces", type=int, default=4)
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


def _blobs_file(n=48):
    """The library's two-blobs phantom (csrc/volume/phantom.c): Gaussians of
    sigma 0.2 at x = -0.45 and +0.45 of a [-1, 1] cube, 2 mm voxels."""
    g = (np.arange(n) + 0.5) / n * 2.0 - 1.0
    x, y, z = np.meshgrid(g, g, g, indexing="ij")
    v = sum(np.exp(-((x - b * 0.45) ** 2 + y * y + z * z) / (2 * 0.04)) for b in (-1, 1))
    aff = np.diag([2.0, 2.0, 2.0, 1.0])
    aff[:3, 3] = -(n - 1)
    return u.write_nifti(os.path.join(u.TMP, "blobs.nii.gz"), (100.0 * v).astype(np.float32), aff)


def _phantom(ob_name):
    if ob_name == "ball":
        return u.ball_file()
    if ob_name == "blobs":
        return _blobs_file()
    return u.CH2


def _sky_world(scene):
    """An HDRI-only World: a 64x32 equirectangular sky (blue above, dark
    below) with a bright warm patch low in the +X sky."""
    w, h = 64, 32
    v = (np.arange(h) + 0.5) / h
    sky = np.zeros((h, w, 4), np.float32)
    sky[..., 0] = (0.15 + 0.25 * v)[:, None]
    sky[..., 1] = (0.2 + 0.35 * v)[:, None]
    sky[..., 2] = (0.3 + 0.6 * v)[:, None]
    sky[: h // 2, :, :3] *= 0.3  # the ground
    sky[18:22, 28:36, :3] = (8.0, 6.0, 4.0)  # around +X, 10-30 degrees up
    sky[..., 3] = 1.0
    img = bpy.data.images.new("sky", w, h, float_buffer=True)
    img.pixels.foreach_set(sky.ravel())
    img.pack()
    tree = scene.world.node_tree
    env = tree.nodes.new("ShaderNodeTexEnvironment")
    env.image = img
    bg = tree.nodes["Background"]
    tree.links.new(env.outputs["Color"], bg.inputs["Color"])
    bg.inputs["Strength"].default_value = 1.0
    return bg


def _light(scene, kind, ob):
    """The scene's light as Voxlight reads it; returns a function that sets
    it to what Cycles needs for the same irradiance (section 3)."""
    diffuse = ob.voxlight.diffuse
    # the Blender tests' scenes leave the World's light off; a World-lit
    # scene turns it on (its default for users)
    scene.voxlight.use_world_light = kind in ("world", "uniform")
    if kind == "uniform":
        bg = scene.world.node_tree.nodes["Background"]
        bg.inputs["Color"].default_value = (0.5, 0.5, 0.5, 1.0)
        bg.inputs["Strength"].default_value = 1.0
        scene.render.film_transparent = True
        return lambda: setattr(bg.inputs["Strength"], "default_value", diffuse)
    if kind == "world":
        bg = _sky_world(scene)
        # the sky itself is not compared, only the light it gives the volume
        scene.render.film_transparent = True
        return lambda: setattr(bg.inputs["Strength"], "default_value", diffuse)
    if kind == "sun":
        lamp = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
        lamp.rotation_euler = (math.radians(50), 0.0, math.radians(30))
        lamp.data.angle = 0.0
        lamp.data.energy = 1.0  # Voxlight: L = 1
        scene.collection.objects.link(lamp)
        return lambda: setattr(lamp.data, "energy", 4 * math.pi * diffuse)
    lamp = bpy.data.objects.new("Point", bpy.data.lights.new("Point", "POINT"))
    r = 1.0
    centre = ob.matrix_world.translation
    lamp.location = (centre.x + r * 0.6, centre.y - r * 0.48, centre.z + r * 0.64)
    lamp.data.shadow_soft_size = 0.0
    lamp.data.energy = 1000.0  # Voxlight: L = P / 1000 W = 1
    scene.collection.objects.link(lamp)
    return lambda: setattr(lamp.data, "energy", 16 * math.pi ** 2 * diffuse * r * r)


def _table(title, rows, truth, truth_name):
    print(title)
    print("| samples | s | RMSE vs %s | PSNR (dB) |" % truth_name)
    print("|---|---|---|---|")
    for s, t, img in rows:
        r = _rmse(img, truth)
        print("| %d | %.2f | %.4f | %.1f |" % (s, t, r, _psnr(r)))


def _path_summary(ours, cycles, truth, at=64):
    """The issue's two targets: the time Voxlight takes to reach Cycles' own
    error at `at` samples, against Cycles' time for it; and the converged
    difference."""
    mine = [(s, t, _rmse(img, truth)) for s, t, img in ours]
    theirs = {s: (t, _rmse(img, truth)) for s, t, img in cycles}
    if at in theirs:
        t_c, e_c = theirs[at]
        hit = [(s, t) for s, t, e in mine if e <= e_c]
        if hit:
            s, t = hit[0]
            print("Cycles' own error at %d samples: %.4f in %.2f s; Voxlight reaches it at %d samples in "
                  "%.2f s: %.1fx less time" % (at, e_c, t_c, s, t, t_c / max(t, 1e-9)))
        else:
            print("Cycles' own error at %d samples: %.4f in %.2f s; Voxlight does not reach it (best %.4f)"
                  % (at, e_c, t_c, min(e for _, _, e in mine)))
    s, t, e = mine[-1]
    print("converged difference: Voxlight at %d samples against Cycles at %d: RMSE %.4f" % (s, cycles[-1][0], e))


def main():
    a = _args()
    vx = u.install_addon()
    scene = u.black_cycles_scene(a.size)
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    ob = u.import_volume(_phantom(a.phantom))
    ob.voxlight.jitter = False
    ob.voxlight.opacity_scale = a.opacity
    u.add_camera((0.0, -2.0, 0.0))
    for_cycles = None
    if a.shading == "off":
        ob.voxlight.shading = False
        scene.cycles.max_bounces = 0
    else:
        ob.voxlight.shading = True
        ob.voxlight.shading_model = a.shading
        ob.voxlight.gradient_ref = 1000.0
        ob.voxlight.ambient = 0.0
        for_cycles = _light(scene, a.light, ob)
        bounces = 1 if a.shading == "scatter" else a.bounces
        ob.voxlight.path_bounces = bounces
        scene.cycles.max_bounces = scene.cycles.volume_bounces = bounces - 1
    ours = []
    path_counts = [int(s) for s in a.path_samples.split(",")] if a.shading == "path" else [1]
    for n in path_counts:
        ob.voxlight.path_samples = n
        img, t = _render(scene, a.size, "voxlight_%d" % n)
        ours.append((n, t, img))
    # the library's own image (scene-linear, what F12 composites) through the scripting API
    library = vx.render_volume(ob)[..., :3]
    bpy.ops.voxlight.convert_to_blender_volume(resolution=a.resolution)
    ob.hide_render = True
    if for_cycles:
        for_cycles()
    counts = [int(s) for s in a.samples.split(",")]
    cycles = []
    for s in counts:
        scene.cycles.samples = s
        img, t = _render(scene, a.size, "cycles_%d" % s)
        cycles.append((s, t, img))
    truth = cycles[-1][2]
    print("\n%s, shading %s, light %s, %dx%d, grid resolution %s, opacity scale %g, Blender %s"
          % (a.phantom, a.shading, a.light if a.shading != "off" else "none", a.size, a.size,
             a.resolution or "one cell per voxel", a.opacity, bpy.app.version_string))
    if a.shading == "path":
        print("bounces: Voxlight %d collisions a path, Cycles %d volume bounces" % (a.bounces, a.bounces - 1))
    _table("Voxlight F12:", ours, truth, "Cycles %d" % counts[-1])
    _table("Cycles:", cycles, truth, "Cycles %d" % counts[-1])
    if a.shading == "path":
        _path_summary(ours, cycles, truth)
    print("mean value: Voxlight F12 (linear) %.4f, the library's own image %.4f, Cycles %d samples %.4f"
          % (ours[-1][2].mean(), library.mean(), counts[-1], truth.mean()))


main()
