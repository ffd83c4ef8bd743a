"""The volume's shadow on a floor in EEVEE's F12, with two lights (a Sun and
a point light), against Cycles' (exact per light: a light group each).

EEVEE has no per-light passes. Subtracting its direct-light passes times
the shadow left their ~1 % rounding in the umbra as concentric stripes, and
put the strongest light's shadow on every light's light
(docs/scene_shadows.md, "EEVEE"). Measured here, on the floor outside the
volume, with S = floor brightness with Cast Shadows on / off:

* stripes: in the umbra, the RMS of EEVEE's image minus its blur over its
  mean (with the subtraction, about 3 times Cycles' sample noise);
* the shadow's place and depth: mean |S_eevee - S_cycles| over the shadow.

The scene is tools/shadow_compare/render.py's (ch2better over a grey floor,
the factory scene's 1000 W point light), smaller.

blender -b --factory-startup --python-exit-code 1 --python tests/blender/test_eevee_shadow_matches_cycles.py
"""

import os
import sys

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import _util as u  # noqa: E402
from _util import test  # noqa: E402

vx = u.install_addon()
W, H = 192, 144
EEVEE = "BLENDER_EEVEE_NEXT" if (4, 2, 0) <= bpy.app.version < (5, 0, 0) else "BLENDER_EEVEE"


def _scene():
    scene = u.reset_scene()
    scene.render.film_transparent = False
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.render.resolution_x, scene.render.resolution_y = W, H
    scene.cycles.samples = 32
    scene.cycles.use_denoising = False  # Debian's Cycles has no OIDN
    scene.cycles.device = "CPU"
    if hasattr(scene.eevee, "taa_render_samples"):
        scene.eevee.taa_render_samples = 16
    floor = u.add_plane((6.0, 6.0), (0.0, 0.0, -1.0), name="Floor", color=(0.6, 0.6, 0.6))
    bsdf = floor.data.materials[0].node_tree.nodes["Principled BSDF"]
    if "Emission Strength" in bsdf.inputs:
        bsdf.inputs["Emission Strength"].default_value = 0.0
    bpy.context.scene.cursor.location = (0.0, 0.0, 0.0)
    ob = u.import_volume(u.CH2)
    ob.voxlight.jitter = False
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy = 3.0
    sun.rotation_euler = (0.4, 0.3, 0.0)
    scene.collection.objects.link(sun)
    pl = bpy.data.objects.new("Light", bpy.data.lights.new("Light", "POINT"))
    pl.data.energy = 1000.0
    pl.location = (4.0762, 1.0055, 5.9039)
    scene.collection.objects.link(pl)
    u.add_camera((0.0, -5.0, 2.0))
    bpy.context.view_layer.update()
    return scene, ob


def _f12(scene, name):
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.filepath = os.path.join(u.TMP, "eevee_vs_cycles_%s.exr" % name)
    bpy.ops.render.render(write_still=True)
    return u.load_png(scene.render.filepath)[..., :3].mean(-1).astype(np.float64)


def _blur(img, sigma=2.0):
    """Separable Gaussian blur, edges extended (numpy only: not every
    Blender's Python has scipy)."""
    r = int(3 * sigma)
    k = np.exp(-0.5 * (np.arange(-r, r + 1) / sigma) ** 2)
    k /= k.sum()
    out = np.pad(img, r, mode="edge")
    out = np.apply_along_axis(lambda v: np.convolve(v, k, mode="valid"), 0, out)
    return np.apply_along_axis(lambda v: np.convolve(v, k, mode="valid"), 1, out)


def _erode(mask, n):
    m = mask.copy()
    for _ in range(n):
        m[1:-1, 1:-1] &= m[:-2, 1:-1] & m[2:, 1:-1] & m[1:-1, :-2] & m[1:-1, 2:]
        m[0, :] = m[-1, :] = m[:, 0] = m[:, -1] = False
    return m


@u.test_oldest_and_newest
def eevee_shadow_of_two_lights_is_smooth_and_matches_cycles():
    scene, ob = _scene()
    images = {}
    for engine in ("CYCLES", EEVEE):
        scene.render.engine = engine
        for cast in (True, False):
            ob.voxlight.cast_shadows = cast
            images[engine, cast] = _f12(scene, "%s_%d" % (engine, cast))
    dg = bpy.context.evaluated_depsgraph_get()
    alpha = vx.offline.render(scene, dg, scene.camera, W, H)[0][..., 3]
    s = {e: np.where(images[e, False] > 0.02,
                     images[e, True] / np.maximum(images[e, False], 1e-6), 1.0)
         for e in ("CYCLES", EEVEE)}
    floor = _erode((alpha <= 0) & (images["CYCLES", False] > 0.02), 3)
    shadow = floor & ((s["CYCLES"] < 0.98) | (s[EEVEE] < 0.98))
    umbra = shadow & (s["CYCLES"] < 0.3) & (s[EEVEE] < 0.3)
    assert shadow.sum() > 1000 and umbra.sum() > 300, (shadow.sum(), umbra.sum())
    diff = np.abs(s["CYCLES"] - s[EEVEE])[shadow]
    stripes = {}
    for e in ("CYCLES", EEVEE):
        on = images[e, True]
        hp = on - _blur(on)
        stripes[e] = np.sqrt((hp[umbra] ** 2).mean()) / on[umbra].mean()
    print("floor shadow %d px, umbra %d px: |S_eevee - S_cycles| mean %.4f p95 %.4f; "
          "umbra high-pass RMS / mean: EEVEE %.3f, Cycles %.3f"
          % (shadow.sum(), umbra.sum(), diff.mean(), np.percentile(diff, 95),
             stripes[EEVEE], stripes["CYCLES"]), flush=True)
    # The umbra's roughness in Cycles is the volume's own detail plus 32
    # samples' noise; EEVEE's must stay near it (the stripes tripled it).
    assert stripes[EEVEE] < 1.5 * stripes["CYCLES"], stripes
    assert diff.mean() < 0.06, diff.mean()


if __name__ == "__main__":
    u.run("test_eevee_shadow_matches_cycles")
