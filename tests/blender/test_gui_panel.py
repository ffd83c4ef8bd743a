"""GUI Blender under Xvfb: the Voxlight object panel at the Properties
editor's default width.

xvfb-run -a -s "-screen 0 1280x1024x24" blender --factory-startup \
    --python-exit-code 1 --python tests/blender/test_gui_panel.py

  * every label of the panel and its sub-panels fits the property-split
    label column at the default width on a 1920-pixel-wide screen (text
    measured with blf at the UI's font size), so nothing is cut to
    "Gradient Fi...";
  * the Statistics header shows the full-resolution frame once the viewport
    has refined, without anything but the add-on redrawing the editor;
  * screenshots of the editor (the panel's top and bottom) are written to
    VOXLIGHT_SCREENSHOT_DIR (default the test's temporary folder) for a
    person to look at.

The steps run from a timer once the window exists; the script exits itself
(a timer's exception would not reach --python-exit-code).
"""

import os
import sys

import blf
import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import _gui  # noqa: E402
import _util as u  # noqa: E402

RUN = _gui.Run("test_gui_panel", limit_s=300)
check = RUN.check
finish = RUN.finish

# uiLayout's property split gives the label column this share of the width
# (UI_ITEM_PROP_SEP_DIVIDE); labels keep a margin from the values.
SPLIT = 0.4
LABEL_MARGIN_PX = 8




def area_of(win, kind):
    return next(a for a in win.screen.areas if a.type == kind)


class _Recorder:
    """Stands in for a UILayout and records the labels the property split
    puts in its label column: (property, text shown)."""

    def __init__(self, labels):
        self.__dict__["labels"] = labels

    def __getattr__(self, name):
        def call(*args, **kw):
            if name == "prop" and len(args) >= 2:
                data, ident = args[0], args[1]
                text = kw.get("text")
                prop = data.bl_rna.properties[ident]
                if text is None:
                    text = prop.name
                if text:
                    # A checkbox's text sits in the value column beside the box.
                    box = prop.type == "BOOLEAN" and not getattr(prop, "is_array", False)
                    self.labels.append((ident, text, box))
            return _Recorder(self.labels)
        return call

    def __setattr__(self, name, value):
        pass


def panel_labels(ob):
    labels = []

    class Ctx:
        object = ob
        region = None
        preferences = bpy.context.preferences
        scene = bpy.context.scene
    failed = []
    # Every Voxlight panel of the Properties editor, drawn for the volume.
    for name in sorted(n for n in dir(bpy.types) if n.startswith("VOXLIGHT_PT_")):
        panel = getattr(bpy.types, name)
        if getattr(panel, "bl_space_type", "") != "PROPERTIES":
            continue
        try:
            getattr(panel, "draw")(type("P", (), {"layout": _Recorder(labels)})(), Ctx)
        except Exception as e:  # a draw that needs more context than the stand-in has
            failed.append("%s: %s" % (name, e))
    return labels, failed


def import_option_labels():
    """(ident, text, is checkbox) of every import option the file
    browser's side bar shows (the operator's visible properties)."""
    rna = bpy.ops.voxlight.import_volume.get_rna_type()
    out = []
    for prop in rna.properties:
        if prop.identifier == "rna_type" or prop.is_hidden or not prop.name:
            continue
        out.append((prop.identifier, prop.name, prop.type == "BOOLEAN"))
    return out


def text_width(text):
    prefs = bpy.context.preferences
    pts = prefs.ui_styles[0].widget.points if hasattr(prefs.ui_styles[0].widget, "points") else 11
    blf.size(0, pts * prefs.view.ui_scale)
    return blf.dimensions(0, text)[0]


def steps():
    vx = u.install_addon()
    rt, vp = vx.core.runtime, vx.viewport
    scene = u.reset_scene()
    scene.voxlight.viewport_resolution = 0.5
    scene.voxlight.settle_time = 0.3
    win = bpy.context.window_manager.windows[0]
    v3d = area_of(win, "VIEW_3D")
    props = area_of(win, "PROPERTIES")
    space = v3d.spaces.active
    r3d = _gui.front_view(space)
    yield 0.5
    with bpy.context.temp_override(window=win, area=v3d):
        ob = u.import_volume(u.CH2)
    props.tag_redraw()  # the Object tab exists once the editor has seen the active object
    yield 0.3
    props.spaces.active.context = "DATA"
    v3d.tag_redraw()
    props.tag_redraw()
    yield 0.5

    # Only the viewport is redrawn from here on: the Statistics header must
    # come to show the refined frame by the add-on's own doing.
    last = -1
    for _ in range(60):
        v3d.tag_redraw()
        yield 0.5
        if not vp.busy() and rt.render_count == last and rt.render_count > 0:
            break
        last = rt.render_count
    yield 1.0
    entry = rt.find_entry(ob.voxlight.filepath)
    shown = [k for name, k in vx.panels.stats_drawn if name == ob.name]
    check("final_frame_rendered", entry is not None and entry.last_frame is not None
          and entry.last_frame["kind"] == "refined",
          "last frame: %s" % (entry.last_frame or {}).get("kind"))
    check("statistics_show_the_final_frame", shown and shown[-1] == "refined",
          "Statistics header drew: %s" % shown[-6:])

    # Labels against the label column at the editor's default width.
    # The editor's default width on a 1920-pixel-wide screen: the factory
    # layout's areas keep their share of the window (this Xvfb screen may be
    # narrower, where Blender's own labels are cut too).
    region = next(r for r in props.regions if r.type == "WINDOW")
    scale = bpy.context.preferences.view.ui_scale
    width = region.width * max(1.0, 1920.0 / win.width)
    content = width - 2 * 20 * scale  # panel margins and the keyframe-dot column
    room = SPLIT * content - LABEL_MARGIN_PX * scale
    # A checkbox's text shares the value column with the box (a UI unit).
    box_room = (1.0 - SPLIT) * content - (20 + LABEL_MARGIN_PX) * scale
    too_long = []
    labels, failed = panel_labels(ob)
    check("every_panel_drawn", not failed, failed)
    for ident, text, box in labels:
        w = text_width(text)
        if w > (box_room if box else room):
            too_long.append("%s %r %.0f px" % (ident, text, w))
    check("labels_fit_at_default_width", not too_long,
          "editor %d px wide (%d here), label column %.0f px, checkbox text %.0f px; too "
          "long: %s" % (width, region.width, room, box_room, too_long))
    # The import options in the file browser's side bar, measured against
    # the same columns (an assumption: the side bar's default width is not
    # measured here, the file browser is not opened).
    too_long = []
    for ident, text, box in import_option_labels():
        w = text_width(text)
        if w > (box_room if box else room):
            too_long.append("%s %r %.0f px" % (ident, text, w))
    check("import_options_fit", not too_long, "too long: %s" % too_long)

    out_dir = os.environ.get("VOXLIGHT_SCREENSHOT_DIR", u.TMP)
    os.makedirs(out_dir, exist_ok=True)
    shots = []
    for name, steps_down in (("panel_default_width_top.png", 14),
                             ("panel_default_width_bottom.png", 30)):
        shot = os.path.join(out_dir, name)
        with bpy.context.temp_override(window=win, area=props, region=region):
            for _ in range(steps_down):  # down to the Voxlight panel, below Blender's own
                bpy.ops.view2d.scroll_down()
        props.tag_redraw()
        yield 0.5
        with bpy.context.temp_override(window=win, area=props):
            res = bpy.ops.screen.screenshot_area(filepath=shot)
        shots.append(res == {"FINISHED"} and os.path.isfile(shot))
    check("screenshots_written", all(shots), out_dir)


RUN.start(steps())
