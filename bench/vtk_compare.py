#!/usr/bin/python3
"""vtk_compare.py - Voxlight against VTK's GPU ray caster, per covered pixel.

Every (volume, transfer function) pair is rendered on the same frame by
three renderers: Voxlight (plugin/core/native.py, central gradients, the step
given), VTK's vtkOpenGLGPUVolumeRayCastMapper (bench/vtk_peer.py's Peer:
VTK's defaults except what must match) and the float64 CPU reference of
bench/ref_render.py. Same camera (Voxlight's default at azimuth 30,
elevation 15, handed to VTK as matrices), same voxels and placement, same
256-entry table over the same window, same step, material and headlight.

Reported per pair and renderer: median warm frame time (Voxlight and VTK
frames interleaved, so load slows both alike), covered pixels (alpha of the
renderer's own image at least 0.5/255, i.e. visible in an 8-bit image),
time per covered pixel, and RMSE/PSNR of premultiplied RGBA against the
reference. "box" is the share of pixels whose ray meets the volume's box:
the framing, the same for both since the camera is.

Transfer functions (alpha = opacity per voxel of path, window = the
volume's value range):
  ramp  white, opacity 0 at 25% to 1 at 75% of the range (opaque surface);
  mri   Voxlight's MRI preset (semi-transparent).

Run under X (VTK's GLX llvmpipe):
  xvfb-run -a -s "-screen 0 1024x768x24" /usr/bin/python3 bench/vtk_compare.py \\
      --size 512 --out bench/vtk_compare.csv --md bench/out/vtk_compare.md
"""
import argparse
import csv
import hashlib
import json
import math
import os
import statistics
import sys
import time
import types

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
if "voxlight" not in sys.modules:  # plugin/ without bpy (as bench/frame_time.py)
    pkg = types.ModuleType("voxlight")
    pkg.__path__ = [os.path.join(ROOT, "plugin")]
    sys.modules["voxlight"] = pkg
os.environ.setdefault("VOXLIGHT_LIB", os.path.join(ROOT, "build", "libvoxlight.so"))
from voxlight.core import native  # noqa: E402

import ref_render  # noqa: E402
import vtk_peer  # noqa: E402

# Both ship in Debian's mricron-data (bookworm and trixie), which build.sh
# installs: a human T1 (ch2better, 0.5 mm) and a rhesus macaque T1 brain
# template (INIA19, 0.5 mm, float32): other anatomy, other scanner, float data.
VOLUMES = {
    "ch2better": "/usr/share/mricron/templates/ch2better.nii.gz",
    "inia19": "/usr/share/mricron/templates/inia19-t1-brain.nii.gz",
}
MATERIAL = (0.3, 0.7, 0.3, 24.0)  # the library's default (csrc/frame.c)
COVERED_ALPHA = 0.5 / 255
COLUMNS = ["volume", "tf", "size", "step", "renderer", "ms_median", "box_frac", "covered_frac",
           "us_per_covered_px", "rmse", "psnr_db", "speedup_per_covered_px", "reference"]


def ramp_table():
    x = np.arange(256) / 255.0
    return np.stack([np.ones_like(x)] * 3 + [np.clip((x - 0.25) / 0.5, 0, 1)], axis=1)


TABLES = {"ramp": ramp_table, "mri": vtk_peer.mri_table}


def rmse_psnr(img, ref):
    d = img.astype(np.float64) - ref
    rmse = float(np.sqrt(np.mean(d * d)))
    return rmse, (20 * math.log10(1 / rmse) if rmse > 0 else 200.0)


def reference_image(cache_dir, name, data, dims, model, view, proj, size, table, window, step, ref_step):
    """ref_render's image, cached by everything that defines it."""
    h = hashlib.sha1()
    for a in (model, view, proj, table, np.array(window, float), np.array([size, step, ref_step], float),
              np.array(dims, float), np.array(MATERIAL)):
        h.update(np.ascontiguousarray(a, dtype=np.float64).tobytes())
    h.update(np.ascontiguousarray(data).tobytes()[:1 << 20])
    path = os.path.join(cache_dir, "vtkcmp_ref_%s_%s.npz" % (name, h.hexdigest()[:16]))
    if os.path.exists(path):
        z = np.load(path)
        return z["img"], z["box"], 0.0
    t = time.perf_counter()
    img, box = ref_render.render(data, dims, model, view, proj, size, size, table, window, MATERIAL, ref_step)
    secs = time.perf_counter() - t
    os.makedirs(cache_dir, exist_ok=True)
    np.savez_compressed(path, img=img.astype(np.float32), box=box)
    return img.astype(np.float32), box, secs


def measure_pair(lib, name, path, tf, a, cache_dir, log):
    vol = native.Volume.load(path, lib=lib)
    r = native.Renderer(lib=lib)
    try:
        r.set_volume(vol)
        info = vol.info
        dims = info["dims"]
        window = (info["value_min"], info["value_max"])
        model = np.asarray(info["affine"], dtype=np.float64)
        table = TABLES[tf]()
        view, proj = r.default_camera(width=a.size, height=a.size, azimuth=30.0, elevation=15.0)
        view, proj = np.asarray(view, np.float64), np.asarray(proj, np.float64)
        params = native.make_params(width=a.size, height=a.size, view=view, proj=proj, filter=a.filter,
                                    sample_distance=1.0, step=a.step, tf_rgba=table, window=window,
                                    material=MATERIAL, shading=True, lib=lib)
        dims_read, data = vtk_peer.read_nifti(path)
        if tuple(dims_read) != tuple(dims):
            sys.exit("vtk_compare: %s: dims %s, Voxlight read %s" % (path, dims_read, dims))
        ref, box, ref_secs = reference_image(cache_dir, name + "_" + tf, data, dims, model, view, proj, a.size,
                                             table, window, a.step, a.ref_step)
        if ref_secs:
            log("vtk_compare: %s/%s reference (step %g) in %.1f s" % (name, tf, a.ref_step, ref_secs))

        # The work of a caster without empty-space skipping that stops at
        # VTK's 1 - 1/255 (VTK's loop), against the samples Voxlight reports.
        t = time.perf_counter()
        noskip, visible = (int(c.sum()) for c in ref_render.march_samples(
            data, dims, model, view, proj, a.size, a.size, table, window, a.step, 1 - 1 / 255.0))
        log("vtk_compare: %s/%s samples without skipping counted in %.1f s" % (name, tf, time.perf_counter() - t))

        img_data, spacing = vtk_peer.image_data({"volume": path, "dims": list(dims)}, model)
        voxel = float(np.mean(spacing))
        if np.ptp(spacing) > 1e-6 * voxel:
            log("vtk_compare: warning: %s has anisotropic spacing %s; VTK's step uses the mean" % (name, spacing))
        color, opacity = vtk_peer.transfer_function({"tf_rgba": table.ravel().tolist(), "window": list(window)})
        peer = vtk_peer.Peer(img_data, voxel, color, opacity, MATERIAL, a.size, a.size, view, proj)
        peer.set_step(a.step)

        ours = r.render(params, want_depth=False)[0]  # warm-up: programs, grids, tables
        peer.frame()
        t_ours, t_vtk = [], []
        for _ in range(a.frames):  # interleaved: load on the machine slows both alike
            t = time.perf_counter()
            ours = r.render(params, want_depth=False)[0]
            t_ours.append((time.perf_counter() - t) * 1e3)
            t = time.perf_counter()
            peer.frame()
            t_vtk.append((time.perf_counter() - t) * 1e3)
        theirs = peer.image()
        st = r.stats()  # of Voxlight's last frame: how much work skipping and termination left
        vstats = {k: st[k] for k in ("samples", "sample_bound", "rays", "effective_step", "bricks_total",
                                     "bricks_occupied")}
        near, far = peer.clipping_range()
        rows, n_px = [], float(a.size * a.size)
        for renderer, img, times in (("voxlight", ours, t_ours), ("vtk", theirs, t_vtk)):
            covered = int(np.count_nonzero(img[..., 3] >= COVERED_ALPHA))
            ms = statistics.median(times)
            rmse, psnr = rmse_psnr(img, ref)
            rows.append(dict(volume=name, tf=tf, size=a.size, step="%g" % a.step, renderer=renderer,
                             ms_median="%.2f" % ms, box_frac="%.4f" % (box.mean()),
                             covered_frac="%.4f" % (covered / n_px),
                             us_per_covered_px="%.4f" % (1e3 * ms / max(covered, 1)),
                             rmse="%.6f" % rmse, psnr_db="%.2f" % psnr,
                             reference="ref_render float64 step %g" % a.ref_step,
                             frames_ms=[round(t, 2) for t in times]))
        speed = float(rows[1]["us_per_covered_px"]) / float(rows[0]["us_per_covered_px"])
        rows[0]["speedup_per_covered_px"] = "%.2f" % speed
        rows[1]["speedup_per_covered_px"] = "1"
        ref_cov = float(np.count_nonzero(ref[..., 3] >= COVERED_ALPHA)) / n_px
        extra = dict(gl_renderer=peer.gl_renderer, vtk_version=vtk_peer.vtk.vtkVersion.GetVTKVersion(),
                     voxlight_backend=r.info()["backend_name"], camera_view_max_abs_diff=peer.camera_diff[0],
                     camera_proj_max_rel_diff=peer.camera_diff[1], clipping_range=[near, far],
                     reference_covered_frac=ref_cov, window=list(window), dims=list(dims), voxel_mm=voxel,
                     vtk_vs_voxlight_rmse=rmse_psnr(theirs, ours.astype(np.float64))[0], voxlight_stats=vstats,
                     samples_without_skipping=noskip, visible_samples=visible)
        if a.images:
            np.savez_compressed(os.path.join(cache_dir, "vtkcmp_%s_%s_%d.npz" % (name, tf, a.size)),
                                voxlight=ours, vtk=theirs, ref=ref)
        return rows, extra
    finally:
        r.close()
        vol.close()


VTK_SETTINGS = """\
VTK's settings (bench/vtk_peer.py, class Peer). The mapper is
vtkGPUVolumeRayCastMapper (the factory gives vtkOpenGLGPUVolumeRayCastMapper),
composite blending. What differs from VTK's defaults, and why it must:

| setting | VTK default | here | why |
|---|---|---|---|
| AutoAdjustSampleDistances | on | off | on, VTK picks its own step from the render window's desired update rate: the step must be ours |
| SampleDistance | 1.0 (world units) | step x voxel spacing | same samples per ray (0.25 mm at step 0.5 on both volumes' 0.5 mm voxels) |
| InterpolationType | nearest | linear | both sample the trilinear field |
| Shade, Ambient/Diffuse/Specular/SpecularPower | off, 0.1/0.7/0.2/10 | on, 0.3/0.7/0.3/24 | the library's default material |
| ScalarOpacityUnitDistance | 1.0 (world units) | voxel spacing | table opacity is per voxel of path on both |
| camera | ResetCamera framing | our view and projection matrices | same frame (VTK's matrices are read back and compared) |
| colour and opacity functions | none | our 256-entry table, one node per entry, over the same window | same classification |
| MultiSamples | 8 | 0 | one ray per pixel, as ours (MSAA would only smooth the box's edges) |
| background | opaque black | black, alpha 0 | read back premultiplied RGBA like ours |

Left at VTK's defaults: jittering off, ImageSampleDistance 1 (full
resolution), LockSampleDistanceToInputSpacing off, one white headlight (made
explicitly, the same as VTK's automatic one), two-sided lighting on, no
gradient opacity, early ray termination at opacity 1 - 1/255, float or 8-bit
volume texture as the data comes. Voxlight runs its defaults too (jittered
start, empty-space skipping, early termination at 0.99) with the central
filter (d = 1), the gradient VTK uses.
"""


def markdown(rows, meta, command):
    first = next(iter(meta.values()))
    out = ["## Against VTK per covered pixel, two transfer functions, two volumes\n",
           "- Command: `%s`" % command,
           "- VTK %s on GL renderer \"%s\"; Voxlight on %s" % (first["vtk_version"], first["gl_renderer"],
                                                              first["voxlight_backend"]),
           "- Frame: %sx%s, Voxlight's default camera at azimuth 30, elevation 15, step %s voxel, median of the "
           "timed frames after one warm-up, Voxlight and VTK frames interleaved" % (rows[0]["size"], rows[0]["size"],
                                                                                  rows[0]["step"]),
           "- Volumes (Debian package mricron-data): ch2better (human T1, 301x370x316, uint8) and "
           "inia19-t1-brain (rhesus macaque T1 template, 168x206x128, float32)",
           "- Transfer functions over the volume's value range: **ramp** white, opacity 0 at 25% to 1 at 75% "
           "(opaque); **mri** Voxlight's MRI preset (semi-transparent)",
           "- Reference: %s (bench/ref_render.py: the library's equations in float64 on the trilinear field, "
           "no jitter, no early termination)" % rows[0]["reference"],
           "- covered: pixels with alpha >= 0.5/255 in each renderer's own image; box: pixels whose ray meets "
           "the volume's box; speed-up = VTK's time per covered pixel over Voxlight's\n",
           "| volume | TF | box | covered (voxlight / VTK) | voxlight ms | VTK ms | voxlight µs/px | VTK µs/px "
           "| speed-up per covered px | voxlight RMSE | VTK RMSE |",
           "|---|---|---|---|---|---|---|---|---|---|---|"]
    for i in range(0, len(rows), 2):
        o, v = rows[i], rows[i + 1]
        out.append("| %s | %s | %.1f%% | %.1f%% / %.1f%% | %s | %s | %.3f | %.3f | %s× | %s (%s dB) | %s (%s dB) |" % (
            o["volume"], o["tf"], 100 * float(o["box_frac"]), 100 * float(o["covered_frac"]),
            100 * float(v["covered_frac"]), o["ms_median"], v["ms_median"], float(o["us_per_covered_px"]),
            float(v["us_per_covered_px"]), o["speedup_per_covered_px"], o["rmse"], o["psnr_db"], v["rmse"],
            v["psnr_db"]))
    out.append("")
    for key, m in meta.items():
        out.append("%s frame times (ms): voxlight %s; VTK %s. VTK against Voxlight's image: RMSE %.5f. Camera "
                   "check: view max |diff| %.2g, projection max relative diff %.2g.\n"
                   % (key, ", ".join("%.1f" % t for t in m["frames_ms"]["voxlight"]),
                      ", ".join("%.1f" % t for t in m["frames_ms"]["vtk"]), m["vtk_vs_voxlight_rmse"],
                      m["camera_view_max_abs_diff"], m["camera_proj_max_rel_diff"]))
    out.append("Where the time goes: samples per frame of Voxlight (its own count, after empty-space skipping "
               "and early termination at 0.99) and of a caster without skipping that stops at 1 - 1/255, "
               "VTK's loop (counted on the reference's field at the same step), and each one's time per "
               "sample from those counts. Visible samples: those of the no-skip loop with opacity > 0, the "
               "least any caster must classify and shade.\n")
    out.append("| volume | TF | visible samples | voxlight samples | no-skip samples | fewer samples "
               "| voxlight ns/sample | VTK ns/sample (no-skip count) | cheaper per sample |")
    out.append("|---|---|---|---|---|---|---|---|---|")
    for i in range(0, len(rows), 2):
        o, v = rows[i], rows[i + 1]
        m = meta.get("%s/%s" % (o["volume"], o["tf"]), {})
        ns, nn = m.get("voxlight_stats", {}).get("samples"), m.get("samples_without_skipping")
        if ns and nn:
            ours, theirs = 1e6 * float(o["ms_median"]) / ns, 1e6 * float(v["ms_median"]) / nn
            out.append("| %s | %s | %.3g | %.3g | %.3g | %.1f× | %.0f | %.0f | %.2f× |" % (
                o["volume"], o["tf"], m.get("visible_samples", float("nan")), ns, nn, nn / ns, ours, theirs,
                theirs / ours))
    out.append("")
    out.append("The speed-up per covered pixel is about the product of the last column and \"fewer samples\": "
               "what empty-space skipping and early termination leave out, and what a sample costs. Where a "
               "transfer function leaves thick tissue semi-transparent, rays cross all of it, skipping saves "
               "only the empty margins, and the lead rests on the cost of a shaded sample.\n")
    out.append(VTK_SETTINGS)
    return "\n".join(out) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--size", type=int, default=512)
    ap.add_argument("--step", type=float, default=0.5, help="ray step in voxels, both renderers")
    ap.add_argument("--filter", default="central",
                    help="Voxlight's gradient filter (VTK takes central differences; the error column says what another costs)")
    ap.add_argument("--ref-step", type=float, default=0.125, help="the reference's step in voxels")
    ap.add_argument("--frames", type=int, default=5, help="timed frames per renderer (median)")
    ap.add_argument("--volumes", default=",".join(VOLUMES), help="comma-separated: " + ", ".join(VOLUMES))
    ap.add_argument("--tfs", default="ramp,mri")
    ap.add_argument("--out", default="bench/vtk_compare.csv", help="CSV (rewritten)")
    ap.add_argument("--md", help="markdown section to write (build.sh appends it to the benchmark page)")
    ap.add_argument("--command", help="the command to name in the markdown (default: this one)")
    ap.add_argument("--json", help="sidecar: frame times, VTK and GL versions, camera check")
    ap.add_argument("--cache-dir", default="bench/out", help="reference images are cached here")
    ap.add_argument("--images", action="store_true", help="also save the three images per pair")
    ap.add_argument("--replot", action="store_true", help="only rewrite --md from --out and --json")
    a = ap.parse_args()
    if a.size < 8 or a.frames < 1 or not a.step > 0 or not a.ref_step > 0:
        sys.exit("vtk_compare: --size >= 8, --frames >= 1, steps > 0")

    if a.replot:  # the markdown again from a finished run's CSV and JSON sidecar
        if not (a.md and a.json):
            sys.exit("vtk_compare: --replot needs --out, --json and --md")
        rows = list(csv.DictReader(open(a.out)))
        with open(a.md, "w") as f:
            f.write(markdown(rows, json.load(open(a.json)), a.command or "bench/vtk_compare.py"))
        return

    def log(msg):
        print(msg, file=sys.stderr, flush=True)

    lib = native.load_library()
    rows, meta = [], {}
    for name in a.volumes.split(","):
        if name not in VOLUMES:
            sys.exit("vtk_compare: unknown volume %r (%s)" % (name, ", ".join(VOLUMES)))
        if not os.path.exists(VOLUMES[name]):
            sys.exit("vtk_compare: %s is missing: install Debian's mricron-data (./build.sh does)" % VOLUMES[name])
        for tf in a.tfs.split(","):
            if tf not in TABLES:
                sys.exit("vtk_compare: unknown transfer function %r" % tf)
            pair, extra = measure_pair(lib, name, VOLUMES[name], tf, a, a.cache_dir, log)
            rows += pair
            meta["%s/%s" % (name, tf)] = dict(extra, frames_ms={p["renderer"]: p.pop("frames_ms") for p in pair})
            o, v = pair
            log("vtk_compare: %s/%s %dx%d step %g: voxlight %s ms, covered %s, %s us/px, rmse %s | "
                "vtk %s ms, covered %s, %s us/px, rmse %s | %sx per covered pixel"
                % (name, tf, a.size, a.size, a.step, o["ms_median"], o["covered_frac"], o["us_per_covered_px"],
                   o["rmse"], v["ms_median"], v["covered_frac"], v["us_per_covered_px"], v["rmse"],
                   o["speedup_per_covered_px"]))
    with open(a.out, "w", newline="") as f:
        wr = csv.DictWriter(f, COLUMNS, lineterminator="\n")
        wr.writeheader()
        wr.writerows(rows)
    if a.md:
        with open(a.md, "w") as f:
            f.write(markdown(rows, meta, a.command or " ".join(["bench/vtk_compare.py"] + sys.argv[1:])))
    if a.json:
        with open(a.json, "w") as f:
            json.dump(meta, f, indent=1)


if __name__ == "__main__":
    main()
