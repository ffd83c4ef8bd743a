"""Renders ch2better over a floor (a Sun, optionally POINT=1 the factory scene's point light)
in Cycles and EEVEE with Cast Shadows on and off, and saves the linear images as .npy in OUT_DIR
(analyse.py OUT_DIR compares the floor shadows). See docs/scene_shadows.md, "EEVEE"."""
import math, os, sys
import bpy
import numpy as np
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tests", "blender"))
import _util as u
vx = u.install_addon()
W, H = int(os.environ.get("RW", 480)), int(os.environ.get("RH", 360))
OUT = os.environ.get("OUT_DIR", "/tmp/voxlight-shadow-compare")
os.makedirs(OUT, exist_ok=True)

def scene_setup():
    scene = u.reset_scene()
    scene.render.film_transparent = False
    scene.view_settings.view_transform = os.environ.get("VT", "Standard")
    scene.render.resolution_x, scene.render.resolution_y = W, H
    floor = u.add_plane((6.0, 6.0), (0.0, 0.0, -1.0), name="Floor", color=(0.6, 0.6, 0.6))
    floor.data.materials[0].node_tree.nodes["Principled BSDF"].inputs["Emission Strength"].default_value = 0.0
    if os.environ.get("NOSPEC"): floor.data.materials[0].node_tree.nodes["Principled BSDF"].inputs["Specular"].default_value = 0.0
    bpy.context.scene.cursor.location = (0.0, 0.0, 0.0)
    ob = u.import_volume(u.CH2)
    ob.voxlight.opacity_scale = float(os.environ.get("OPS", "1"))
    ob.voxlight.jitter = bool(int(os.environ.get("JITTER", "0")))
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy = 3.0
    sun.rotation_euler = tuple(float(x) for x in os.environ.get("SUNROT", "0.4,0.3,0").split(","))
    scene.collection.objects.link(sun)
    if os.environ.get("POINT"):
        pl = bpy.data.objects.new("Light", bpy.data.lights.new("Light", "POINT"))
        pl.data.energy = 1000.0
        pl.data.use_shadow = not os.environ.get("NOSHADOW")
        pl.location = (4.0762, 1.0055, 5.9039)
        scene.collection.objects.link(pl)
    cam = u.add_camera((0.0, -5.0, 2.0))
    bpy.context.view_layer.update()
    return scene, ob

def f12(scene, name):
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.filepath = os.path.join(OUT, name + ".exr")
    bpy.ops.render.render(write_still=True)
    return u.load_png(scene.render.filepath)

scene, ob = scene_setup()
res = {}
for eng in os.environ.get("ENGINES", "CYCLES,BLENDER_EEVEE").split(","):
    scene.render.engine = eng
    scene.cycles.samples = 32
    scene.cycles.use_denoising = False
    scene.eevee.taa_render_samples = int(os.environ.get("ESAMP", "16"))
    for cast in (True, False):
        ob.voxlight.cast_shadows = cast
        img = f12(scene, "%s_%s" % (eng, "on" if cast else "off"))
        res[(eng, cast)] = img
dg = bpy.context.evaluated_depsgraph_get()
vol = vx.offline.render(scene, dg, scene.camera, W, H)[0]
np.save(os.path.join(OUT, "vol_alpha.npy"), vol[..., 3])
for k, v in res.items():
    np.save(os.path.join(OUT, "%s_%s.npy" % (k[0], k[1])), v)
print("DONE")
