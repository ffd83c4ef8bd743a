"""F12 leaves the scene's own render exactly as it is wherever the volume
shows nothing: a volume hidden inside the factory startup's Cube, a label
map whose ids no lookup entry names, a volume out of view, in every engine,
the first F12 of a session as much as any later one. Compared pixel for
pixel (colour and alpha) with the render of the same scene with the volume
hidden from renders.

blender -b --factory-startup --python-exit-code 1 --python tests/blender/test_f12_untouched.py
"""

import os
import sys

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import _util as u  # noqa: E402
from _util import test  # noqa: E402

vx = u.install_addon()

# EEVEE's identifier in each Blender the tests run in.
EEVEE = "BLENDER_EEVEE_NEXT" if (4, 2, 0) <= bpy.app.version < (5, 0, 0) else "BLENDER_EEVEE"
ENGINES = ("CYCLES", EEVEE, "BLENDER_WORKBENCH")


def _small_and_quick(scene, width=64, height=36):
    scene.render.resolution_x, scene.render.resolution_y = width, height
    scene.render.resolution_percentage = 100
    scene.render.image_settings.file_format = "PNG"
    scene.render.image_settings.color_mode = "RGBA"
    scene.render.image_settings.color_depth = "16"
    scene.cycles.samples = 4
    scene.cycles.use_denoising = False  # Debian's Cycles has no OIDN
    scene.cycles.device = "CPU"
    if hasattr(scene.eevee, "taa_render_samples"):
        scene.eevee.taa_render_samples = 4


def _forget_images():
    """As in a new session: none of the add-on's compositing images yet."""
    for name in (vx.compositor.IMAGE_NAME,) + vx.compositor.PASSES:
        img = bpy.data.images.get(name)
        if img is not None:
            bpy.data.images.remove(img)


def _f12(scene, name):
    scene.render.filepath = os.path.join(u.TMP, name + ".png")
    bpy.ops.render.render(write_still=True)
    return u.load_png(scene.render.filepath)


def _without(scene, obs, name):
    """The render of the scene with `obs` hidden from renders."""
    for ob in obs:
        ob.hide_render = True
    try:
        return _f12(scene, name)
    finally:
        for ob in obs:
            ob.hide_render = False


def _same(a, b, what, mask=None):
    diff = np.abs(a - b) if mask is None else np.abs(a - b)[mask]
    assert diff.size and diff.max() == 0.0, "%s: %d pixels differ, by up to %g" % (
        what, int((diff.reshape(-1, 4) if mask is None else diff).max(axis=-1).astype(bool).sum()),
        diff.max())


@test
def factory_scene_volume_inside_the_cube_renders_the_lit_cube():
    """Run first: the scene is still the factory startup's (Cube, Camera,
    Light). The volume lands at the 3D cursor, inside the Cube, so meshes
    hide all of it: every engine must give its own render of the lit Cube,
    with Cast Shadows on and off."""
    scene = bpy.context.scene
    assert {"Cube", "Camera", "Light"} <= set(bpy.data.objects.keys()), list(bpy.data.objects.keys())
    _small_and_quick(scene)
    _forget_images()
    # kept where it is: the import would hide the untouched startup Cube
    vol = u.import_volume(u.CH2 if os.path.isfile(u.CH2) else u.ball_file(), hide_startup_cube=False)
    cube = bpy.data.objects["Cube"]
    for engine in ENGINES:
        scene.render.engine = engine
        tag = engine.lower()
        plain = _without(scene, [vol], "factory_plain_" + tag)
        h, w = plain.shape[:2]
        centre = plain[h // 2 - 3:h // 2 + 3, w // 2 - 3:w // 2 + 3]
        assert centre[..., :3].mean() > 0.1, (engine, "the Cube is not lit", centre[..., :3].mean())
        for cast in (True, False):
            vol.voxlight.cast_shadows = cast
            img = _f12(scene, "factory_%s_cast%d" % (tag, cast))
            assert img[..., :3].max() > 1.0 / 255, (engine, "a black frame")
            _same(img, plain, "%s, Cast Shadows %s" % (engine, cast))
    bpy.data.objects.remove(vol)
    bpy.data.objects.remove(cube)


def _lit_scene():
    """A lit grey floor and a grey world seen by a perspective camera: every
    pixel has colour, so a pass that paints anywhere shows."""
    scene = u.reset_scene()
    _small_and_quick(scene, 48, 48)
    scene.render.engine = "CYCLES"
    scene.render.film_transparent = False
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    if scene.world.node_tree is not None:
        scene.world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.2, 0.25, 0.3, 1)
    scene.world.color = (0.2, 0.25, 0.3)
    u.add_plane((20.0, 20.0), (0.0, 0.0, -0.6), name="Floor", color=(0.5, 0.5, 0.5))
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy = 3.0
    sun.rotation_euler = (0.3, 0.2, 0.0)
    scene.collection.objects.link(sun)
    u.add_camera((0.0, -4.0, 1.0))
    return scene


def _box_mask(scene, ob, w, h, pad=2):
    """True outside the volume box's screen footprint (its corners'
    bounding rectangle, `pad` pixels wider), row 0 = bottom."""
    dg = bpy.context.evaluated_depsgraph_get()
    view, proj = vx.offline.camera_matrices(scene.camera, dg, w, h, scene)
    model = np.array(ob.matrix_world, np.float64) @ \
        np.array(ob.voxlight.voxel_to_local, np.float64).reshape(4, 4).T
    corners = vx.core.volume_space.world_corners(model, tuple(ob.voxlight.dims))
    clip = np.c_[corners, np.ones(8)] @ (proj @ view).T
    ndc = clip[:, :2] / clip[:, 3:4]
    x = (ndc[:, 0] * 0.5 + 0.5) * w
    y = (ndc[:, 1] * 0.5 + 0.5) * h
    mask = np.ones((h, w), bool)
    x0, x1 = max(int(np.floor(x.min())) - pad, 0), min(int(np.ceil(x.max())) + pad, w)
    y0, y1 = max(int(np.floor(y.min())) - pad, 0), min(int(np.ceil(y.max())) + pad, h)
    mask[y0:y1, x0:x1] = False
    assert mask.any() and not mask.all(), (x0, x1, y0, y1)
    return mask


def _label_file(named):
    """A 24^3 uint8 label image (ids 1..5 in slabs, 0 around them) and a
    lookup file beside it naming the ids in `named` only."""
    n = 24
    data = np.zeros((n, n, n), np.uint8)
    data[4:20, 4:20, 4:20] = 1 + (np.arange(4, 20) * 5 // n)[:, None, None]
    tag = "_".join(str(i) for i in named) or "none"
    path = os.path.join(u.TMP, "seg_%s.nii.gz" % tag)
    aff = np.diag([4.0, 4.0, 4.0, 1.0])
    aff[:3, 3] = -(n - 1) / 2.0 * 4.0
    u.write_nifti(path, data, aff)
    with open(path[:-len(".nii.gz")] + "_labels.txt", "w") as f:
        for i in named:
            f.write("%d region_%d\n" % (i, i))
    return path


@test
def a_label_map_with_unnamed_ids_leaves_the_scene_alone_outside_its_box():
    for named in ((200, 201), (2,)):  # none of its ids named; one of five
        scene = _lit_scene()
        _forget_images()
        ob = u.import_volume(_label_file(named), import_as="NEW")
        assert ob.voxlight_labels.enabled, "imported as labels, as asked"
        plain = _without(scene, [ob], "labels_plain")
        img = _f12(scene, "labels_%d" % len(named))
        _same(img, plain, "label map naming %s, outside its box" % (named,),
              _box_mask(scene, ob, img.shape[1], img.shape[0]))
        if len(named) == 2:  # nothing of it is named, so nothing of it shows
            _same(img, plain, "label map with no named id")


@test
def the_first_f12_equals_the_second():
    """A volume hidden behind a wall, then one in plain view, then one out
    of view: each first F12 of an unchanged scene equals the next, and
    where the volume shows nothing, the scene without it."""
    scene = _lit_scene()
    ob = u.import_volume(u.ball_file())
    ob.voxlight.jitter = False
    wall = u.add_plane((3.0, 3.0), (0.0, -1.5, 0.5), rotation=(np.pi / 2, 0.0, 0.0), name="Wall")
    cases = (("behind_wall", (0.0, 0.0, 0.0), True),
             ("in_view", (0.0, 0.0, 0.0), False),
             ("out_of_view", (0.0, -20.0, 0.0), False))
    for tag, where, walled in cases:
        ob.location = where
        wall.hide_render = not walled
        if tag == "behind_wall":
            _forget_images()  # the session's very first F12
        first = _f12(scene, tag + "_1")
        second = _f12(scene, tag + "_2")
        _same(first, second, tag + ": first and second F12")
        if tag != "in_view":
            _same(first, _without(scene, [ob], tag + "_plain"), tag + ": the scene without the volume")
        else:
            mask = _box_mask(scene, ob, first.shape[1], first.shape[0])
            assert np.abs(first - _without(scene, [ob], "in_view_plain"))[~mask].max() > 0.05, \
                "the volume shows"


@test
def an_intensity_volume_beside_a_folder_wide_labels_txt_renders_as_intensity():
    """The reproducer's case: a uint8 ball with hundreds of values and a
    3-label labels.txt for another image in its folder. Detect takes it as
    an intensity volume, the first F12 shows the ball over the lit scene,
    and the panel's switch makes it a label map and back, in place."""
    folder = os.path.join(u.TMP, "with_labels_txt")
    os.makedirs(folder, exist_ok=True)
    n = 48
    c = (n - 1) / 2.0
    x, y, z = np.meshgrid(*[np.arange(n) - c] * 3, indexing="ij")
    r = np.sqrt(x * x + y * y + z * z)
    data = (np.clip(255 * (1 - r / 22), 0, 255) * (r < 22)).astype(np.uint8)
    aff = np.diag([2.0, 2.0, 2.0, 1.0])
    aff[:3, 3] = -c * 2.0
    path = u.write_nifti(os.path.join(folder, "sphere.nii.gz"), data, aff)
    with open(os.path.join(folder, "labels.txt"), "w") as f:
        f.write("1 left_ball\n2 right_ball\n3 floor_slab\n")
    scene = _lit_scene()
    _forget_images()
    ob = u.import_volume(path)
    ob.voxlight.jitter = False
    assert not ob.voxlight_labels.enabled, "a folder-wide table naming 3 of its values made it labels"
    img = _f12(scene, "sphere_first")
    plain = _without(scene, [ob], "sphere_plain")
    mask = _box_mask(scene, ob, img.shape[1], img.shape[0])
    _same(img, plain, "outside the sphere's box", mask)
    assert np.abs(img - plain)[~mask].max() > 0.05, "the sphere shows"
    bpy.context.view_layer.objects.active = ob
    assert bpy.ops.voxlight.use_as_labels(labels=True) == {"FINISHED"}
    s = ob.voxlight_labels
    assert s.enabled and [lab.label_id for lab in s.labels] == [1, 2, 3]
    assert os.path.basename(s.lookup_file) == "labels.txt"
    assert bpy.ops.voxlight.use_as_labels(labels=False) == {"FINISHED"}
    assert not s.enabled
    _same(_f12(scene, "sphere_again"), img, "intensity again: the first render")


def _animation(scene, name):
    """Renders frames frame_start..frame_end as an animation (the render
    job changes frames itself) and returns them as arrays."""
    scene.render.filepath = os.path.join(u.TMP, name + "_####")
    bpy.ops.render.render(animation=True)
    return [u.load_png(os.path.join(u.TMP, "%s_%04d.png" % (name, f)))
            for f in range(scene.frame_start, scene.frame_end + 1)]


@test
def an_animation_whose_camera_passes_through_behind_and_away_never_gets_a_damaged_frame():
    """The camera flies at the volume, through it, past it (the volume
    behind it) and turns away. Where the volume is out of view, a frame
    equals the scene without it; inside it, the frame shows the volume over
    the scene, never a black or broken frame."""
    scene = _lit_scene()
    ob = u.import_volume(u.ball_file())
    ob.voxlight.jitter = False
    cam = scene.camera
    half = 0.5 * max(ob.dimensions)
    shots = (("in_view", (0.0, -4.0, 0.3), (np.pi / 2, 0.0, 0.0)),
             ("inside", (0.0, 0.0, 0.0), (np.pi / 2, 0.0, 0.0)),
             ("behind", (0.0, 1.5 * half + 1.0, 0.3), (np.pi / 2, 0.0, 0.0)),
             ("away", (0.0, -4.0, 0.3), (np.pi / 2, 0.0, np.pi)))
    scene.frame_start, scene.frame_end = 1, len(shots)
    edit = bpy.context.preferences.edit  # jumps, not flights between the shots
    edit.keyframe_new_interpolation_type = "CONSTANT"
    for f, (_tag, loc, rot) in enumerate(shots, start=1):
        cam.location, cam.rotation_euler = loc, rot
        cam.keyframe_insert("location", frame=f)
        cam.keyframe_insert("rotation_euler", frame=f)
    _forget_images()
    frames = _animation(scene, "fly")
    for ob_ in (ob,):
        ob_.hide_render = True
    try:
        plain = _animation(scene, "fly_plain")
    finally:
        ob.hide_render = False
    for (tag, _l, _r), img, ref in zip(shots, frames, plain):
        assert np.isfinite(img).all() and img[..., :3].max() > 1.0 / 255, (tag, "a black or broken frame")
        if tag in ("behind", "away"):
            _same(img, ref, tag + ": the scene without the volume")
        else:
            assert np.abs(img - ref).max() > 0.05, (tag, "the volume shows")
            assert (img[..., 3] == 1.0).all(), (tag, "holes in the frame's alpha")


u.run("test_f12_untouched")
