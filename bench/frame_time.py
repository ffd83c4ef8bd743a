#!/usr/bin/env python3
"""Warm-frame time of the shaded ray caster on ch2better, as measured it.

ch2better at 512x512, default camera (azimuth 30, elevation 15), MRI preset,
through plugin/core/native.py; per configuration the median of --frames warm
frames. Each --shader-dir makes a renderer (A/B: give two) and their frames
are interleaved in one process, so a busy machine slows all alike: compare
the ratio columns (k/0: renderer k over renderer 0, same configuration), not
the milliseconds, unless the machine is quiet.

Every image is compared by PSNR (over premultiplied RGBA in [0, 1]) against a
reference set (--reference, .npy per configuration); --save-reference writes
that set from the first renderer (today's shaders). Usage:

  python3 bench/frame_time.py --save-reference --reference /tmp/ref    # once, on today's shaders
  python3 bench/frame_time.py --shader-dir /tmp/old_shaders --shader-dir shaders --reference /tmp/ref
"""

import argparse
import math
import os
import statistics
import sys
import time
import types

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
if "voxlight" not in sys.modules:  # plugin/ without bpy (as tests/python/conftest.py)
    pkg = types.ModuleType("voxlight")
    pkg.__path__ = [os.path.join(ROOT, "plugin")]
    sys.modules["voxlight"] = pkg
os.environ.setdefault("VOXLIGHT_LIB", os.path.join(ROOT, "build", "libvoxlight.so"))
from voxlight.core import native  # noqa: E402

VOLUME = "/usr/share/mricron/templates/ch2better.nii.gz"

# (name, filter, step, shading): the configurations the frame-time table compares.
CONFIGS = [
    ("central-s1-shaded", "central", 1.0, True),
    ("central-s1-unshaded", "central", 1.0, False),
    ("precomputed-s1-shaded", "precomputed", 1.0, True),
    ("central-s0.5-shaded", "central", 0.5, True),
    ("sobel8-s1-shaded", "sobel8", 1.0, True),
    ("sobel8-s0.5-shaded", "sobel8", 0.5, True),
    ("sobel26-s0.5-shaded", "sobel26", 0.5, True),
    ("cubic-s0.5-shaded", "cubic", 0.5, True),
]


def psnr(a, b):
    mse = float(np.mean((a.astype(np.float64) - b.astype(np.float64)) ** 2))
    return math.inf if mse == 0.0 else 10.0 * math.log10(1.0 / mse)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--volume", default=VOLUME)
    ap.add_argument("--size", type=int, default=512)
    ap.add_argument("--frames", type=int, default=5, help="warm frames per median")
    ap.add_argument("--shader-dir", action="append", default=[],
                    help="shader folder (repeat for A/B; none = the library's embedded shaders)")
    ap.add_argument("--only", default="", help="comma-separated configuration names or filters")
    ap.add_argument("--reference", default="", help="folder of reference images (.npy)")
    ap.add_argument("--save-reference", action="store_true",
                    help="write the first renderer's images into --reference")
    args = ap.parse_args()

    configs = CONFIGS
    if args.only:
        want = set(args.only.split(","))
        configs = [c for c in CONFIGS if c[0] in want or c[1] in want]
    dirs = args.shader_dir or [None]
    lib = native.load_library()
    vol = native.Volume.load(args.volume, lib=lib)
    renderers = []
    for d in dirs:
        r = native.Renderer(shader_dir=os.path.abspath(d) if d else None, lib=lib)
        r.set_volume(vol)
        renderers.append(r)
    if args.save_reference and args.reference:
        os.makedirs(args.reference, exist_ok=True)

    names = [os.path.basename(os.path.normpath(d)) if d else "embedded" for d in dirs]
    for k, (n, d) in enumerate(zip(names, dirs)):
        print("#%d %s: %s" % (k, n, d or "embedded shaders"))
    head = "%-24s" % "configuration" + "".join(" %13s %7s" % (n[:13], "PSNR") for n in names)
    if len(dirs) > 1:
        head += "  " + " ".join("%d/0" % i for i in range(1, len(dirs)))
    print(head)
    for name, filt, step, shaded in configs:
        params = native.make_params(width=args.size, height=args.size, filter=filt, step=step,
                                    shading=shaded, preset="mri", azimuth=30.0, elevation=15.0,
                                    lib=lib)
        times = [[] for _ in renderers]
        images = []
        for r in renderers:  # cold frame: compiles the variant, uploads what it needs
            images.append(r.render(params, want_depth=False)[0])
        for _ in range(args.frames):
            for k, r in enumerate(renderers):
                t = time.perf_counter()
                r.render(params, want_depth=False)
                times[k].append((time.perf_counter() - t) * 1e3)
        ref = None
        path = os.path.join(args.reference, name + ".npy") if args.reference else ""
        if args.save_reference and path:
            np.save(path, images[0])
        if path and os.path.exists(path):
            ref = np.load(path)
        med = [statistics.median(t) for t in times]
        line = "%-24s" % name
        for k in range(len(renderers)):
            q = psnr(images[k], ref) if ref is not None else float("nan")
            line += " %13.1f %7s" % (med[k], "inf" if math.isinf(q) else "%.1f" % q)
        if len(dirs) > 1:
            line += "  " + " ".join("%.3f" % (m / med[0]) for m in med[1:])
        print(line, flush=True)
    for r in renderers:
        r.close()
    vol.close()


if __name__ == "__main__":
    main()
