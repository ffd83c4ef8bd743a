"""The demo for `./build.sh demo`:

    blender -b --factory-startup --python tools/blender_demo.py -- OUT.png

Headless Blender loads the add-on from this checkout (plugin/ with the
library in build/), imports the ch2better brain MRI, puts a mesh beside it,
lights it with a sun and renders OUT.png with the scene camera (Cycles on
the CPU for the mesh, Voxlight for the volume, composited by the add-on).
"""

import importlib.util
import math
import os
import sys

import bpy

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BRAIN = "/usr/share/mricron/templates/ch2better.nii.gz"


def load_addon():
    """Import plugin/ as the package `voxlight` and register it. The library
    comes from $VOXLIGHT_LIB or build/libvoxlight.so."""
    os.environ.setdefault("VOXLIGHT_LIB", os.path.join(ROOT, "build", "libvoxlight.so"))
    spec = importlib.util.spec_from_file_location(
        "voxlight", os.path.join(ROOT, "plugin", "__init__.py"),
        submodule_search_locations=[os.path.join(ROOT, "plugin")])
    mod = importlib.util.module_from_spec(spec)
    sys.modules["voxlight"] = mod
    spec.loader.exec_module(mod)
    mod.register()
    ok, msg = mod.library_status()
    if not ok:
        raise SystemExit("voxlight demo: %s" % msg)
    return mod


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    out = os.path.abspath(argv[0] if argv else "demo.png")
    load_addon()
    for ob in list(bpy.data.objects):
        bpy.data.objects.remove(ob)
    scene = bpy.context.scene
    scene.cursor.location = (0.0, 0.0, 0.0)

    bpy.ops.voxlight.import_volume(filepath=BRAIN)  # 1 mm = 0.01 units: ~1.7 units long
    brain = bpy.context.view_layer.objects.active
    brain.voxlight.preset = "mri"
    # The brain shadows the floor and the sphere (on by default):
    # each light's direct light in the render times the volume's
    # transmittance, through Cycles light groups and the compositor.
    brain.voxlight.cast_shadows = True

    # A mesh beside the brain (and a floor) so the compositing is visible.
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.45, location=(1.35, 0.2, -0.3))
    sphere = bpy.context.active_object
    bpy.ops.object.shade_smooth()
    mat = bpy.data.materials.new("Demo Sphere")
    mat.use_nodes = True
    mat.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (0.8, 0.25, 0.1, 1)
    sphere.data.materials.append(mat)
    bpy.ops.mesh.primitive_plane_add(size=8.0, location=(0.0, 0.0, -0.8))

    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy = 3.0
    sun.rotation_euler = (math.radians(40), math.radians(20), math.radians(30))
    scene.collection.objects.link(sun)

    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    cam.location = (1.2, -4.2, 1.4)
    cam.rotation_euler = (math.radians(75), 0.0, math.radians(15))
    scene.collection.objects.link(cam)
    scene.camera = cam

    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = 16
    scene.cycles.use_denoising = False  # Debian's Cycles has no OIDN
    scene.render.resolution_x, scene.render.resolution_y = 640, 480
    scene.render.resolution_percentage = 100
    scene.view_settings.view_transform = "Standard"
    scene.render.image_settings.file_format = "PNG"
    scene.render.filepath = out
    bpy.ops.render.render(write_still=True)
    print("voxlight demo: wrote %s" % out)


main()
