"""GUI Blender under Xvfb: the viewport shows a streamed volume
at once, coarser where its bricks are still loading, and keeps refining it
by itself (the add-on's timers, no redraw from the test) until nothing is
pending.

xvfb-run -a -s "-screen 0 1280x1024x24" blender --factory-startup \
    --enable-event-simulate --python-exit-code 1 --python tests/blender/test_gui_streaming.py
"""

import os
import shutil
import subprocess
import sys
import tempfile
import time

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import _gui  # noqa: E402
import _util as u  # noqa: E402

RUN = _gui.Run("test_gui_streaming", limit_s=560)
capture = _gui.Capture()
FOLDER = tempfile.mkdtemp(prefix="voxlight-gui-stream-")


def steps():
    vx = u.install_addon()
    vp = vx.viewport
    capture.install()
    scene = u.reset_scene()
    scene.voxlight.viewport_resolution = 0.25  # llvmpipe: keep each pass short
    scene.voxlight.settle_time = 0.3
    win, area, space = _gui.view3d()
    space.overlay.show_overlays = False
    _gui.front_view(space)
    # a sparse volume of 512 MiB, streamed: the loader needs a while for its bricks
    path = os.path.join(FOLDER, "sparse.nii")
    subprocess.run(["/usr/bin/python3", os.path.join(u.ROOT, "tests", "make_stream_data.py"), "sparse", path,
                    "--dims", "1024,1024,512"], check=True, timeout=300)
    prefs = bpy.context.preferences.addons[u.MODULE].preferences
    prefs.streaming = "on"
    ob = u.import_volume(path, unit_scale=2.0 / 1024)
    ob.voxlight.jitter = False
    entry = vx.core.runtime.find_entry(path)
    RUN.check("imported_streamed", entry is not None and entry.info["streamed"])
    area.tag_redraw()  # the first draw; from here on only the add-on redraws
    yield 0.5
    seen = []  # (pending, coarsest level) of each full image shown, in order
    end = time.monotonic() + 300.0
    while time.monotonic() < end:
        st = next((s for (_r, name), s in vp._states.items() if name == ob.name), None)
        img = st.full if st is not None else None
        if img is not None and (not seen or seen[-1][2] is not img):
            seen.append((img.pending, img.level, img))
            if img.pending == 0:
                break
        yield 0.25
    passes = [(p, lvl) for p, lvl, _img in seen]
    RUN.check("first_full_frame_did_not_wait", passes and passes[0][0] > 0, "passes %s" % passes)
    RUN.check("refined_by_itself_until_nothing_pending", len(passes) > 1 and passes[-1] == (0, 0),
              "passes %s" % passes)
    for _ in capture.settled(vx, area):
        yield _
    with_volume = capture.img
    ob.hide_set(True)
    for _ in capture.settled(vx, area):
        yield _
    without = capture.img
    shown = float((abs(with_volume[..., :3] - without[..., :3]).max(axis=-1) > 0.02).mean()) \
        if with_volume is not None and without is not None else 0.0
    RUN.check("final_frame_shows_the_volume", shown > 0.001, "%.4f of the pixels differ" % shown)
    RUN.check("no_viewport_error", vp.last_error == "", vp.last_error)
    vx.core.runtime.release_all()
    shutil.rmtree(FOLDER, ignore_errors=True)


RUN.start(steps())
