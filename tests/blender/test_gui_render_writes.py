"""GUI Blender under Xvfb: the render handlers write no data-block
attribute once the scene is ready, so an F12 never fails because a panel
was drawing.

An F12 in the GUI runs render_init, render_pre and frame_change_post on the
render job's thread, and Blender refuses attribute writes to data while
any Python panel or header draws on the main thread (one flag for the whole
process). In CI that made 1 run in 3 print "Writing to ID classes in this
context is not allowed" from our handlers. Which thread wins is chance, so
this test makes the refusal certain instead: it calls the handlers, the
whole render path, from inside a header's draw, where every attribute write
is refused. They must still lay the volume into the render image, after the
add-on's main-thread set-up (render_setup.py) had its tick.

xvfb-run -a -s "-screen 0 1280x1024x24" blender --factory-startup \
    --enable-event-simulate --python-exit-code 1 --python tests/blender/test_gui_render_writes.py
"""

import os
import sys
import traceback

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import _gui  # noqa: E402
import _util as u  # noqa: E402

RUN = _gui.Run("test_gui_render_writes", limit_s=400)
check = RUN.check
EEVEE = "BLENDER_EEVEE_NEXT" if (4, 2, 0) <= bpy.app.version < (5, 0, 0) else "BLENDER_EEVEE"


class InDraw:
    """Runs one function inside the 3D viewport header's draw (writes
    refused there) and keeps its result or traceback."""

    def __init__(self):
        self.fn = None
        self.result = None
        bpy.types.VIEW3D_HT_header.append(self._draw)

    def _draw(self, _header, context):
        fn, self.fn = self.fn, None
        if fn is None:
            return
        try:
            self.result = ("ok", fn(context))
        except Exception:
            self.result = ("error", traceback.format_exc())

    def run(self, fn):
        """A generator step: yields until the header drew fn."""
        self.fn, self.result = fn, None
        for _ in range(200):
            for win in bpy.context.window_manager.windows:
                for area in win.screen.areas:
                    area.tag_redraw()
            yield 0.05
            if self.result is not None:
                return


def _render_in_draw(vx, scene):
    def fn(context):
        rh = vx.render_hooks
        rh.last_error = ""
        rh.on_render_init(scene)
        rh.on_render_pre(scene)
        if rh._pending:  # what frame_change_post does with the render's depsgraph
            rh.render_frame(scene, context.evaluated_depsgraph_get())
        rh.on_render_end(scene)
        return rh.last_error
    return fn


def _coverage(name):
    img = bpy.data.images.get(name)
    if img is None:
        return -1.0
    px = np.empty(len(img.pixels), np.float32)
    img.pixels.foreach_get(px)
    return float((px.reshape(-1, 4)[:, 3] > 0.01).mean())


def steps():
    vx = u.install_addon()
    scene = u.reset_scene()
    ob = u.import_volume(u.CH2)
    u.add_plane((6.0, 6.0), (0.0, 0.0, -1.0), name="Floor", color=(0.6, 0.6, 0.6))
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.rotation_euler = (0.4, 0.3, 0.0)
    scene.collection.objects.link(sun)
    u.add_camera((0.0, -5.0, 2.0))
    scene.render.resolution_x, scene.render.resolution_y = 160, 120
    scene.render.resolution_percentage = 100
    draw = InDraw()

    # The premise: a header's draw refuses writes on this Blender.
    yield from draw.run(lambda c: setattr(scene.render, "resolution_x", 161))
    check("writes_are_refused_in_a_draw", draw.result is not None and draw.result[0] == "error"
          and "not allowed" in draw.result[1], str(draw.result)[-160:])

    cases = (
        ("eevee_shadows", dict(engine=EEVEE, shadows=True)),
        ("cycles_shadows", dict(engine="CYCLES", shadows=True)),
        ("cycles_no_shadows", dict(engine="CYCLES", shadows=False)),
        ("workbench_shadows", dict(engine="BLENDER_WORKBENCH", shadows=True)),
        ("separate_layer", dict(engine=EEVEE, shadows=True, separate=True)),
        ("resized", dict(engine="CYCLES", shadows=True, size=(200, 100))),
        ("render_off", dict(engine=EEVEE, shadows=True, enabled=False)),
        ("render_on_again", dict(engine=EEVEE, shadows=True)),
    )
    for name, c in cases:
        scene.render.engine = c["engine"]
        ob.voxlight.cast_shadows = c["shadows"]
        scene.voxlight.render_separate_layer = c.get("separate", False)
        scene.voxlight.render_enabled = c.get("enabled", True)
        scene.render.resolution_x, scene.render.resolution_y = c.get("size", (160, 120))
        yield 1.0  # the main thread's set-up (render_setup.py) has had its tick
        yield from draw.run(_render_in_draw(vx, scene))
        ok = draw.result is not None and draw.result[0] == "ok" and not draw.result[1]
        check("%s_renders_with_writes_refused" % name, ok, str(draw.result)[-400:])
        image = vx.compositor.PASS_COLOR if c.get("separate") else vx.compositor.IMAGE_NAME
        cover = _coverage(image)
        if c.get("enabled", True):
            check("%s_volume_in_the_image" % name, cover > 0.05, "%s covers %.3f" % (image, cover))
        else:
            over = vx.compat.compositor_tree(scene).nodes[vx.compositor.NODE_OVER]
            check("%s_alpha_over_muted_and_image_empty" % name, over.mute and cover == 0.0,
                  "muted %s, covers %.3f" % (over.mute, cover))
        if c["shadows"] and c.get("enabled", True) and not c.get("separate"):
            chain = [n.name for n in vx.compat.compositor_tree(scene).nodes
                     if n.name.startswith(vx.compositor.shadow_plan.NODE_PREFIX)]
            check("%s_shadow_chain_ready" % name, len(chain) >= 3, str(chain))


RUN.start(steps())
