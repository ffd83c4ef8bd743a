"""In Blender: the scene's lights cast shadows through the volume
in F12 renders (blender -b), the lighting settings (shading model,
occlusion, anisotropy, shadow quality) are animatable and reach the
library, new volumes default to shadowed, files from before keep Phong,
and a dragged light coarsens only the illumination volume.

The phantom: two opaque blobs side by side, the camera on -Y seeing one on
the left and one on the right. A Sun on the right puts the left blob in the
shadow of the right one.

blender -b --factory-startup --python-exit-code 1 --python tests/blender/test_shadow.py
"""

import os
import sys

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import _util as u  # noqa: E402
from _util import test  # noqa: E402

vx = u.install_addon()
W, H = 128, 64
# 96 voxels along its length: more than Shadow Quality Low's 64 cells (the
# library caps the illumination volume at the data's own resolution).
N = (96, 48, 48)
CENTRES = ((27.5, 23.5, 23.5), (67.5, 23.5, 23.5))  # voxel centres of the blobs
RADIUS = 14.0


def _blobs_file():
    i, j, k = np.meshgrid(*[np.arange(n) for n in N], indexing="ij")
    vol = np.zeros(N, np.float32)
    for c in CENTRES:
        vol[(i - c[0]) ** 2 + (j - c[1]) ** 2 + (k - c[2]) ** 2 < RADIUS ** 2] = 100.0
    aff = np.eye(4)
    aff[:3, 3] = [-(n - 1) / 2.0 for n in N]  # 1 mm voxels centred on the scanner origin
    return u.write_nifti(os.path.join(u.TMP, "two_blobs.nii.gz"), vol, aff)


def _scene():
    """Two blobs at the origin, camera on -Y. F12 renders the (empty) scene
    with one Cycles sample on a transparent film, in the Standard view: a
    pixel is the volume's colour and coverage."""
    scene = u.reset_scene()
    scene.render.engine = "CYCLES"
    scene.cycles.samples = 1
    scene.cycles.use_denoising = False  # Debian's Cycles has no OIDN
    scene.render.film_transparent = True
    scene.view_settings.view_transform = "Standard"
    scene.render.resolution_x, scene.render.resolution_y = W, H
    ob = u.import_volume(_blobs_file())
    p = ob.voxlight
    p.jitter = False
    p.opacity_scale = 8.0  # opaque blobs: a blob's shadow is deep
    p.ambient = 0.15  # and dark
    # No highlights: their half vectors follow each blob's direction to the
    # eye, which differs left and right; diffuse light alone is symmetric.
    p.specular = 0.0
    cam = u.add_camera((0.0, -2.0, 0.0))
    # Orthographic: both blobs are seen from the same side, so without
    # shadows a Sun along the line through them lights them alike.
    cam.data.type = "ORTHO"
    cam.data.ortho_scale = 1.1
    return scene, ob


def _blob_centres(ob):
    """World centres of the blobs (the importer may turn the file's axes)."""
    model = vx.params.model_matrix(ob)
    return [(model @ np.array([*c, 1.0]))[:3] for c in CENTRES]


def _sun(scene, ob, side):
    """A Sun shining along the line through the blobs, from the side of the
    blob that is on the right in the image (side = 1) or on the left (-1).
    A sun shines along its local -Z, so its +Z points at the light."""
    from mathutils import Vector
    sun = bpy.data.objects.get("Sun") or bpy.data.objects.new(
        "Sun", bpy.data.lights.new("Sun", "SUN"))
    if sun.name not in scene.collection.objects:
        scene.collection.objects.link(sun)
    sun.data.energy = 2.0
    sun.data.angle = 0.0
    a, b = _blob_centres(ob)
    left_to_right = Vector(b - a) if _blob_pixels(scene, ob, sort=False)[0][0] < \
        _blob_pixels(scene, ob, sort=False)[1][0] else Vector(a - b)
    sun.rotation_mode = "QUATERNION"
    sun.rotation_quaternion = (left_to_right * side).to_track_quat("Z", "Y")
    bpy.context.view_layer.update()
    return sun


def _f12(scene, name):
    scene.render.filepath = os.path.join(u.TMP, name + ".png")
    bpy.ops.render.render(write_still=True)
    return u.load_png(scene.render.filepath)


def _blob_pixels(scene, ob, sort=True):
    """Image (x, y) of each blob's centre, the left one first (sort), from
    the camera."""
    dg = bpy.context.evaluated_depsgraph_get()
    view, proj = vx.offline.camera_matrices(scene.camera, dg, W, H, scene)
    out = []
    for c in _blob_centres(ob):
        clip = proj @ view @ np.array([*c, 1.0])
        ndc = clip[:3] / clip[3]
        out.append(((ndc[0] + 1) * W / 2, (ndc[1] + 1) * H / 2))
    assert abs(out[0][0] - out[1][0]) > 2 * _radius_px(scene, ob), out  # side by side
    return sorted(out) if sort else out


def _radius_px(scene, ob):
    """A blob's radius in the image (orthographic camera), plus a margin:
    the disc measured holds the whole blob, its lit rim included."""
    world = RADIUS * float(np.linalg.norm(vx.params.model_matrix(ob)[:3, 0]))
    return 1.15 * world * W / scene.camera.data.ortho_scale


def _blob_light(img, centre, r):
    """(mean linear premultiplied brightness, mean coverage) of a blob's
    disc in the pixels of an RGBA PNG (sRGB, straight alpha; row 0 =
    bottom)."""
    ys, xs = np.mgrid[0:H, 0:W]
    disc = (xs + 0.5 - centre[0]) ** 2 + (ys + 0.5 - centre[1]) ** 2 < r * r
    c = np.clip(img[disc], 0.0, 1.0)
    lin = np.where(c[:, :3] <= 0.04045, c[:, :3] / 12.92, ((c[:, :3] + 0.055) / 1.055) ** 2.4)
    return float((lin * c[:, 3:]).mean()), float(c[:, 3].mean())


def _balance(scene, ob, name):
    """Brightness of the left blob over that of the right one in an F12 render."""
    img = _f12(scene, name)
    left, right = _blob_pixels(scene, ob)
    r = _radius_px(scene, ob)
    (a, cover_a), (b, cover_b) = _blob_light(img, left, r), _blob_light(img, right, r)
    assert cover_a > 0.4 and cover_b > 0.4, (name, cover_a, cover_b)  # both blobs show
    assert b > 0.0, name
    return a / b


@test
def moving_the_sun_swaps_the_shadowed_blob_in_f12():
    """Shadowed: the blob away from the Sun is darker, and moving the Sun to
    the other side swaps them. Phong (no shadows) lights them alike: the
    shadows are what changes the balance."""
    scene, ob = _scene()
    p = ob.voxlight
    assert p.shading_model == "shadowed"  # the default of a new volume
    p.occlusion_strength = 0.0  # shadows only
    sun = _sun(scene, ob, 1)
    p.shading_model = "phong"
    phong_from_right = _balance(scene, ob, "phong_right")
    p.shading_model = "shadowed"
    from_right = _balance(scene, ob, "shadowed_right")
    sun = _sun(scene, ob, -1)
    from_left = _balance(scene, ob, "shadowed_left")
    p.shading_model = "phong"
    phong_from_left = _balance(scene, ob, "phong_left")
    print("balance left/right: phong %.3f %.3f, shadowed %.3f %.3f"
          % (phong_from_right, phong_from_left, from_right, from_left), flush=True)
    # Without shadows, each blob is lit alike on its sunny side.
    assert 0.9 < phong_from_right < 1.1 and 0.9 < phong_from_left < 1.1
    # Sun on the right: the left blob is in the right one's shadow, and the other way round.
    assert from_right < 0.7 * phong_from_right, (from_right, phong_from_right)
    assert from_left > 1.43 * phong_from_left, (from_left, phong_from_left)
    assert from_right < 1.0 < from_left  # the darker blob is the one away from the Sun
    assert sun.name == "Sun"


@test
def animated_lighting_settings_reach_f12():
    """Keyframed shading model and occlusion are read per frame by F12
    (blender -b): frame 1 Phong, frame 2 shadowed."""
    scene, ob = _scene()
    p = ob.voxlight
    _sun(scene, ob, 1)
    p.occlusion_strength = 0.0
    p.shading_model = "phong"
    p.keyframe_insert("shading_model", frame=1)
    p.keyframe_insert("occlusion_strength", frame=1)
    p.shading_model = "shadowed"
    p.occlusion_strength = 0.8
    p.keyframe_insert("shading_model", frame=2)
    p.keyframe_insert("occlusion_strength", frame=2)
    balance = []
    for frame in (1, 2):
        scene.frame_set(frame)
        assert p.shading_model == ("phong", "shadowed")[frame - 1]
        balance.append(_balance(scene, ob, "animated_%d" % frame))
    assert balance[1] < 0.7 * balance[0], balance  # frame 2 shadows the left blob


@test
def every_lighting_setting_changes_the_render():
    scene, ob = _scene()
    p = ob.voxlight
    # See-through blobs: inside them the gradient vanishes, where Scatter's
    # phase function differs from Shadowed.
    p.opacity_scale = 0.3
    p.shadow_quality = "LOW"  # (Auto's size is the library's choice: compare Low and High)
    _sun(scene, ob, 1)
    # (The Sun shines across the view: the phase function of g and -g agree
    # at 90 degrees, so the anisotropies differ in size.)
    changes = [("shading_model", "phong"), ("shading_model", "shadowed"),
               ("occlusion_radius", 24.0), ("occlusion_strength", 1.0),
               ("shadow_quality", "HIGH"),
               ("shading_model", "scatter"), ("anisotropy", 0.8), ("anisotropy", 0.3)]
    prev = vx.render_volume(ob, resolution=(W, H))
    for name, value in changes:
        setattr(p, name, value)
        img = vx.render_volume(ob, resolution=(W, H))
        assert float(np.abs(img - prev).max()) > 1e-3, "%s=%r did not change the image" % (
            name, value)
        prev = img


@test
def defaults_choices_and_animatable():
    rna = bpy.types.Object.bl_rna.properties["voxlight"].fixed_type.properties
    assert rna["shading_model"].default == "shadowed"
    assert rna["occlusion_radius"].default == 4.0
    assert rna["occlusion_strength"].default == 0.5
    assert rna["anisotropy"].default == 0.0
    assert rna["shadow_quality"].default == "AUTO"
    # The models and their numbers are the library's (VXL_SHADING_*).
    lib = vx.core.native.load_library()
    items = [(i.identifier, i.value) for i in rna["shading_model"].enum_items]
    assert items == [(n, i) for i, n in enumerate(lib.names("shading_model"))], items
    assert [(i.identifier, i.value) for i in rna["shadow_quality"].enum_items] == \
        [("AUTO", 0), ("LOW", 64), ("MEDIUM", 128), ("HIGH", 256)]
    scene, ob = _scene()
    p = ob.voxlight
    for name in ("shading_model", "occlusion_radius", "occlusion_strength", "anisotropy",
                 "shadow_quality"):
        assert rna[name].is_animatable, name
        assert p.keyframe_insert(name, frame=1), name
    p.occlusion_radius = 9.0
    p.keyframe_insert("occlusion_radius", frame=10)
    scene.frame_set(10)
    kw = vx.params.look_kwargs(ob.evaluated_get(bpy.context.evaluated_depsgraph_get()).voxlight)
    assert kw["ambient_occlusion"] == 9.0 and kw["shading_model"] == "shadowed", kw
    assert kw["occlusion_strength"] == 0.5 and kw["illumination_size"] == 0, kw
    scene.frame_set(1)
    assert vx.params.look_kwargs(ob.voxlight)["ambient_occlusion"] == 4.0


@test
def files_from_before_shading_models_keep_phong():
    """A volume saved before shading models (tf_version 2, no stored model)
    opens as Phong, its look then; one saved now keeps its model."""
    scene, old = _scene()
    new = u.import_volume(_blobs_file())
    new.voxlight.shading_model = "scatter"
    old.voxlight.tf_version = 2
    old.voxlight.property_unset("shading_model")
    assert old.voxlight.get("shading_model") is None
    assert vx.params.look_kwargs(old.voxlight)["shading_model"] == "phong"  # before the upgrade
    old, new = u.reopen((old, new), "before_shadows.blend")
    assert old.voxlight.shading_model == "phong", old.voxlight.shading_model
    assert new.voxlight.shading_model == "scatter", new.voxlight.shading_model
    assert old.voxlight.tf_version == new.voxlight.tf_version == vx.tf.TF_VERSION
    # A volume imported now gets the new default.
    assert u.import_volume(_blobs_file()).voxlight.shading_model == "shadowed"


@test
def dragging_a_light_coarsens_only_the_illumination_volume():
    """The viewport's hook (params.while_lights_move): a light moved within
    the settle time gives frames the coarse illumination size, and the
    chosen one once it settles; nothing else in the params changes."""
    scene, ob = _scene()
    sun = _sun(scene, ob, 1)
    sun.data.angle = 0.05  # a shape to pass
    ob.voxlight.shadow_quality = "HIGH"
    dg = bpy.context.evaluated_depsgraph_get()
    view, proj = vx.offline.camera_matrices(scene.camera, dg, W, H, scene)

    def frame(now):
        lights = vx.params.scene_lights(scene, bpy.context.evaluated_depsgraph_get())
        lights, left = vx.params.while_lights_move(lights, now, 0.3)
        return vx.params.build(ob, W, H, view, proj, lights=lights), left

    first, _ = frame(100.0)
    still, left = frame(100.1)
    assert left is None and still.illumination_size == 256
    sun.rotation_quaternion.rotate(__import__("mathutils").Euler((0.0, 0.2, 0.0)))  # dragged
    bpy.context.view_layer.update()
    dragged, left = frame(100.2)
    assert left is not None and 0 < left <= 0.3
    assert dragged.illumination_size == vx.core.lighting.DRAG_ILLUMINATION_SIZE
    assert dragged.shading_model == still.shading_model and dragged.step == still.step
    settled, left = frame(100.6)
    assert left is None and settled.illumination_size == 256
    # The lights reach the params with their shapes.
    assert settled.light_count == 1 and bool(settled.light_shapes)


u.run("test_shadow")
