#!/usr/bin/env python3
"""What the artist sees in the first 2 s after a change: error of the
viewport's image against the final one over time, on ch2better, for a
filter change, a preset change, a light move and a camera orbit; the
compositing before (nearest texels: blocks) against today's (depth-aware
bilinear, plugin/core/upsample.py, the maths of viewport._FRAG), and, for
comparison, keeping the last full image until the new one is ready.

It models the add-on (plugin/viewport.py) with the library directly:
  * the preview: a fast frame (doubled step) at the scale the policy gives
    a 0.05 s budget (PREVIEW_SECONDS, resolution_policy), at most 0.35;
  * refine steps: refine_scales (half then full when the half is sharper
    than the preview and the full frame takes >= 0.3 s, HALF_STEP_WORTH_S),
    started at once for a filter or preset change (the view is still) and
    after Refine After (0.3 s) for a light move or an orbit;
  * each step's time is its library time, measured once per step here
    (quietly: each frame rendered twice, the second timed), then the
    timeline is simulated: until the preview is ready the previous final
    image stays on screen (both curves alike).
Error: RMS over RGB of the image composited over Blender's viewport grey,
against the final image, over the pixels either covers, in 8-bit levels.

  python3 bench/preview_error.py --size 800x600 --plot docs/preview_error.png
"""

import argparse
import math
import os
import sys
import time
import types

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
if "voxlight" not in sys.modules:
    pkg = types.ModuleType("voxlight")
    pkg.__path__ = [os.path.join(ROOT, "plugin")]
    sys.modules["voxlight"] = pkg
os.environ.setdefault("VOXLIGHT_LIB", os.path.join(ROOT, "build", "libvoxlight.so"))
from voxlight.core import native, resolution_policy, upsample  # noqa: E402

VOLUME = "/usr/share/mricron/templates/ch2better.nii.gz"
GREY = 0.23
PREVIEW_SECONDS, MAX_PREVIEW, SETTLE, HALF_WORTH = 0.05, 0.35, 0.3, 0.3

BASE = dict(filter="central", preset="mri", azimuth=30.0, elevation=15.0, step=0.5,
            lights=(((0.5, -1.0, 0.6, 0.0), (1.0, 1.0, 1.0), 1.0),))
CHANGES = [  # (name, what changes, refine waits for Refine After)
    ("filter", dict(filter="sobel8"), False),
    ("preset", dict(preset="bone"), False),
    ("light", dict(lights=(((-0.8, -0.6, 0.4, 0.0), (1.0, 1.0, 1.0), 1.0),)), True),
    ("orbit", dict(azimuth=50.0), True),
]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--volume", default=VOLUME)
    ap.add_argument("--size", default="800x600")
    ap.add_argument("--plot", default="")
    args = ap.parse_args()
    W, H = map(int, args.size.split("x"))
    lib = native.load_library()
    vol = native.Volume.load(args.volume, lib=lib)
    r = native.Renderer(lib=lib)
    r.set_volume(vol)

    def cam(kw):
        p = native.make_params(width=W, height=H, lib=lib, **kw)
        return r.default_camera(p)

    def frame(kw, view, proj, scale, fast):
        w, h = max(1, round(W * scale)), max(1, round(H * scale))
        k = dict(kw)
        k.pop("azimuth"), k.pop("elevation")
        k["step"] = kw["step"] * (2.0 if fast else 1.0)
        p = native.make_params(width=w, height=h, view=view, proj=proj, jitter=False, lib=lib, **k)
        r.render(p)
        t = time.perf_counter()
        rgba, d = r.render(p)
        return rgba, d, time.perf_counter() - t, proj

    def shown(img, mode):
        rgba, d, _, proj = img
        h, w = rgba.shape[:2]
        hit = np.where(np.isfinite(d), 0.5, 1.0)  # no scene: only hit/no hit matters
        ones = np.ones((h, w), np.float32)
        out, _ = upsample.composite(rgba, hit, ones, np.ones((H, W), np.float32), proj,
                                    0.0, 1e30, 1.0, mode)
        return out

    def err(a, b):
        m = (a[..., 3] > 0.002) | (b[..., 3] > 0.002)
        d = upsample.over(a, GREY) - upsample.over(b, GREY)
        return 255.0 * math.sqrt(float(np.mean(d[m] ** 2)))

    times = np.round(np.arange(0.0, 2.0001, 0.05), 3)
    curves = {}
    for name, change, waits in CHANGES:
        a = dict(BASE)
        b = dict(BASE, **change)
        va, pa = cam(a)
        vb, pb = cam(b)
        final_a = frame(a, va, pa, 1.0, False)
        final_b = frame(b, vb, pb, 1.0, False)
        probe = frame(b, vb, pb, 0.25, True)
        spp = probe[2] / (W * H * 0.25 ** 2)
        scale = min(MAX_PREVIEW, max(resolution_policy.MIN_SCALE,
                                     math.sqrt(PREVIEW_SECONDS / (spp * W * H))))
        prev = frame(b, vb, pb, scale, True)
        steps = resolution_policy.refine_scales(scale, 1.0)
        if len(steps) > 1 and final_b[2] < HALF_WORTH:
            steps = steps[-1:]
        t0 = prev[2]
        start = SETTLE if waits else t0
        timeline = [(0.0, "old", final_a), (t0, "preview", prev)]
        t = start
        for s in steps:
            img = final_b if s == 1.0 else frame(b, vb, pb, s, False)
            t += img[2]
            timeline.append((t, "full" if s == 1.0 else "half", img))
        final = final_b[0]
        rows = {}
        for mode in upsample.FILTERS + ("hold",):
            cache = {}
            ys = []
            for tt in times:
                _, kind, img = [e for e in timeline if e[0] <= tt][-1]
                if kind == "full":
                    ys.append(0.0)
                    continue
                key = kind if mode != "hold" else ("old" if kind != "full" else kind)
                if key not in cache:
                    im = final_a[0] if key == "old" else shown(img, mode if mode != "hold" else upsample.BILATERAL)
                    cache[key] = err(im, final)
                ys.append(cache[key])
            rows[mode] = ys
        curves[name] = (rows, timeline, scale)
        print("%s: preview scale %.3f (%.3f s), steps %s, shown at %s" % (
            name, scale, t0, steps, ", ".join("%s %.2f s" % (k, tt) for tt, k, _ in timeline)), flush=True)

    print("\nRMS error against the final image (8-bit levels) at t seconds after the change:")
    marks = [0.0, 0.1, 0.2, 0.3, 0.5, 0.75, 1.0, 1.5, 2.0]
    print("| change | compositing | " + " | ".join("%.2f s" % m for m in marks) + " |")
    print("|---|---|" + "---|" * len(marks))
    for name, (rows, _, _) in curves.items():
        for mode, label in ((upsample.NEAREST, "before: nearest (blocks)"),
                            (upsample.BILATERAL, "now: depth-aware bilinear"),
                            ("hold", "keep last full image")):
            ys = [rows[mode][list(times).index(m)] for m in marks]
            print("| %s | %s | %s |" % (name, label, " | ".join("%.1f" % y for y in ys)))
        below = all(n <= o + 1e-9 for n, o in zip(rows[upsample.BILATERAL], rows[upsample.NEAREST]))
        print("|  | now <= before at all %d points: %s |" % (len(times), below))
    if args.plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, axes = plt.subplots(1, len(curves), figsize=(4 * len(curves), 3.2), sharey=True)
        for ax, (name, (rows, _, scale)) in zip(axes, curves.items()):
            ax.step(times, rows[upsample.NEAREST], where="post", label="before (nearest)")
            ax.step(times, rows[upsample.BILATERAL], where="post", label="now (bilinear, depth-aware)")
            ax.step(times, rows["hold"], where="post", ls=":", label="keep last full")
            ax.set_title("%s (preview scale %.2f)" % (name, scale))
            ax.set_xlabel("s after the change")
        axes[0].set_ylabel("RMS error (8-bit levels)")
        axes[0].legend(fontsize=7)
        fig.tight_layout()
        fig.savefig(args.plot, dpi=80)
    r.close()
    vol.close()


if __name__ == "__main__":
    main()
