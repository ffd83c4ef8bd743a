#!/usr/bin/python3
"""vtk_peer.py - VTK's GPU ray caster on the same frame as voxlight-bench.

Reads bench/out/scene_<workload>.json (written by voxlight-bench), renders the
same volume with vtkOpenGLGPUVolumeRayCastMapper, times the median of
--frames renders (render + read back) after a warm-up, measures the image
against ref_<workload>.f32 and appends one CSV row with renderer=vtk per
step (--steps; default the scene's step).

Run it under X on llvmpipe:  xvfb-run -a /usr/bin/python3 bench/vtk_peer.py \
    bench/out/scene_ch2better.json --out bench/results.csv

What is matched (the camera is checked, see the "match" line on stderr): camera (view
and projection rebuilt from our matrices and compared back), volume placement
(our voxel->world affine), the 256-entry transfer function over the same
window, opacity per voxel of path, sample distance = step x voxel spacing,
Phong material, a headlight, trilinear interpolation, central-difference
gradients, no jitter. What cannot be matched is listed in bench/plot.py
(VTK_NOTES), which docs/benchmark.md reproduces.
"""
import argparse
import csv
import gzip
import json
import math
import os
import statistics
import struct
import sys
import time

import numpy as np
import vtk
from vtk.util import numpy_support

CSV_COLUMNS = ("workload,filter,sample_distance,step,reuse_gradients,classify,backend,renderer,ms_median,"
               "fetches_per_sample,ang_mean_deg,ang_p95_deg,rmse,psnr_db,max_abs,size,frames,samples,"
               "reference").split(",")

# NIfTI-1 datatype codes -> numpy dtypes (the ones real scans use).
NIFTI_DTYPES = {2: "u1", 4: "i2", 8: "i4", 16: "f4", 64: "f8", 256: "i1", 512: "u2", 768: "u4"}


def read_nifti(path):
    """Minimal NIfTI-1 reader (nibabel is not in Debian's base set): returns
    the voxel array in file order (x fastest) with scl_slope/inter applied.
    Placement comes from the scene's affine, not from this header."""
    raw = gzip.open(path).read() if path.endswith(".gz") else open(path, "rb").read()
    end = "<" if struct.unpack("<i", raw[:4])[0] == 348 else ">"
    dim = struct.unpack(end + "8h", raw[40:56])
    dtype = np.dtype(end + NIFTI_DTYPES[struct.unpack(end + "h", raw[70:72])[0]])
    offset = int(struct.unpack(end + "f", raw[108:112])[0])
    slope, inter = struct.unpack(end + "2f", raw[112:120])
    dims = dim[1:4]
    n = dims[0] * dims[1] * dims[2]
    data = np.frombuffer(raw, dtype=dtype, count=n, offset=offset)
    if slope not in (0.0, 1.0) or inter != 0.0:
        data = data.astype(np.float32) * slope + inter
    return dims, data


def mri_table():
    """Mirror of vxl_preset_table(VXL_PRESET_MRI) in csrc/frame/transfer.c, which is
    not exported from libvoxlight. Used only when the scene JSON carries no
    "tf_rgba"; keep the two in step."""
    x = np.arange(256) / 255.0
    t = np.clip((x - 0.15) / (0.45 - 0.15), 0, 1)
    return np.stack([0.8 + 0.2 * x, 0.65 + 0.3 * x, 0.55 + 0.4 * x, 0.25 * t * t * (3 - 2 * t)], axis=1)


def transfer_function(scene):
    if "tf_rgba" in scene:
        table = np.asarray(scene["tf_rgba"], dtype=float).reshape(-1, 4)
    elif scene["preset"] == "mri":
        table = mri_table()
    else:
        sys.exit("vtk_peer: preset %r has no mirror here; add tf_rgba to the scene JSON" % scene["preset"])
    lo, hi = scene["window"] if "window" in scene else (scene["value_min"], scene["value_max"])
    # One node per table entry at the data value our shader maps onto that
    # entry's centre: both sides then interpolate the same piecewise-linear
    # function (VTK resamples it into its own texture, a small difference).
    color, opacity = vtk.vtkColorTransferFunction(), vtk.vtkPiecewiseFunction()
    color.SetColorSpaceToRGB()
    for i, (r, g, b, a) in enumerate(table):
        v = lo + (hi - lo) * i / (len(table) - 1)
        color.AddRGBPoint(v, r, g, b)
        opacity.AddPoint(v, a)
    return color, opacity


def image_data(scene, affine):
    dims, data = read_nifti(scene["volume"])
    if list(dims) != list(scene["dims"]):
        sys.exit("vtk_peer: %s has dims %s, scene says %s" % (scene["volume"], dims, scene["dims"]))
    lin = affine[:3, :3]
    spacing = np.linalg.norm(lin, axis=0)
    img = vtk.vtkImageData()
    img.SetDimensions(*dims)
    img.SetSpacing(*spacing)
    img.SetOrigin(*affine[:3, 3])
    direction = lin / spacing
    if not np.allclose(direction, np.eye(3)):
        img.SetDirectionMatrix(*direction.ravel())  # rotation/flip of the grid (shear is lost)
    img.GetPointData().SetScalars(numpy_support.numpy_to_vtk(data, deep=True))
    return img, spacing


def set_camera(cam, view, proj, width, height):
    """vtkCamera from our OpenGL matrices: eye, look direction and up from the
    view matrix, vertical field of view and clipping range from proj."""
    rot, trans = view[:3, :3], view[:3, 3]
    eye = -rot.T @ trans
    forward, up = -rot[2], rot[1]
    near = proj[2, 3] / (proj[2, 2] - 1)
    far = proj[2, 3] / (proj[2, 2] + 1)
    if abs(proj[0, 2]) > 1e-6 or abs(proj[1, 2]) > 1e-6 or abs(proj[3, 3]) > 1e-6:
        sys.exit("vtk_peer: only symmetric perspective projections are supported")
    cam.SetPosition(*eye)
    cam.SetFocalPoint(*(eye + forward * 0.5 * (near + far)))
    cam.SetViewUp(*up)
    cam.SetViewAngle(math.degrees(2 * math.atan(1 / proj[1, 1])))
    cam.SetClippingRange(near, far)
    # Read back what VTK will use and compare: the match must be checked.
    got_v = np.array([[cam.GetModelViewTransformMatrix().GetElement(i, j) for j in range(4)] for i in range(4)])
    pm = cam.GetProjectionTransformMatrix(width / height, -1, 1)
    got_p = np.array([[pm.GetElement(i, j) for j in range(4)] for i in range(4)])
    return np.abs(got_v - view).max(), np.abs(got_p - proj).max() / np.abs(proj).max()


def gl_renderer(win):
    for line in win.ReportCapabilities().splitlines():
        if "OpenGL renderer string" in line:
            return line.split(":", 1)[1].strip()
    return "unknown"


def errors(img, ref):
    d = np.abs(img.astype(np.float64) - ref)
    rmse = float(np.sqrt(np.mean(d * d)))
    return rmse, (20 * math.log10(1 / rmse) if rmse > 0 else 200.0), float(d.max())


def reference_label(csv_path, workload):
    """The reference the bench used for this workload, so the rows agree."""
    try:
        with open(csv_path) as f:
            for row in csv.DictReader(f):
                if row["workload"] == workload and row["renderer"] == "voxlight":
                    return row["reference"]
    except (OSError, KeyError):
        pass
    return "ref_%s.f32" % workload


def write_png(path, pic):
    """Premultiplied float RGBA (row 0 = bottom) -> straight-alpha 8-bit PNG."""
    a = pic[..., 3:]
    straight = np.where(a > 0, pic[..., :3] / np.maximum(a, 1e-6), 0)
    u8 = np.clip(np.concatenate([straight, a], axis=2) * 255 + 0.5, 0, 255).astype(np.uint8)
    out = vtk.vtkImageData()
    out.SetDimensions(pic.shape[1], pic.shape[0], 1)  # vtkImageData row 0 = bottom, as the writer expects
    out.GetPointData().SetScalars(numpy_support.numpy_to_vtk(u8.reshape(-1, 4), deep=True))
    writer = vtk.vtkPNGWriter()
    writer.SetInputData(out)
    writer.SetFileName(path)
    writer.Write()


class Peer:
    """VTK's GPU ray caster set up for one frame: VTK's defaults except what
    must match ours (the settings table in docs/benchmark.md): the sample distance
    (automatic adjustment off), trilinear interpolation, opacity per voxel
    of path, shading with our material, the camera. The light is VTK's
    default headlight; jittering off and image sample distance 1 are VTK's
    defaults, set here so a change of default cannot slip in."""

    def __init__(self, img, voxel, color, opacity, material, w, h, view, proj):
        ambient, diffuse, specular, shininess = material
        prop = vtk.vtkVolumeProperty()
        prop.SetColor(color)
        prop.SetScalarOpacity(opacity)
        prop.SetScalarOpacityUnitDistance(voxel)  # table alpha = opacity per voxel of path
        prop.SetInterpolationTypeToLinear()  # VTK's default is nearest
        prop.ShadeOn()
        prop.SetAmbient(ambient)
        prop.SetDiffuse(diffuse)
        prop.SetSpecular(specular)
        prop.SetSpecularPower(shininess)

        mapper = vtk.vtkGPUVolumeRayCastMapper()  # the factory gives vtkOpenGLGPUVolumeRayCastMapper
        mapper.SetInputData(img)
        mapper.SetBlendModeToComposite()
        mapper.AutoAdjustSampleDistancesOff()  # otherwise VTK changes the step to meet a frame rate
        mapper.LockSampleDistanceToInputSpacingOff()
        mapper.SetImageSampleDistance(1.0)
        mapper.UseJitteringOff()  # VTK's default; our bench frame is jittered, the reference is not (see docs)

        volume = vtk.vtkVolume()
        volume.SetMapper(mapper)
        volume.SetProperty(prop)

        ren = vtk.vtkRenderer()
        ren.SetBackground(0, 0, 0)
        ren.SetBackgroundAlpha(0)  # black transparent: the read-back is premultiplied like ours
        ren.AutomaticLightCreationOff()
        light = vtk.vtkLight()
        light.SetLightTypeToHeadlight()  # white, intensity 1, from the eye: what VTK creates by default
        ren.AddLight(light)
        ren.TwoSidedLightingOn()
        ren.AddVolume(volume)

        win = vtk.vtkRenderWindow()
        win.SetOffScreenRendering(1)
        win.SetAlphaBitPlanes(1)
        win.SetMultiSamples(0)
        win.SetSize(w, h)
        win.AddRenderer(ren)
        self.camera_diff = set_camera(ren.GetActiveCamera(), view, proj, w, h)
        win.Render()  # creates the GL context (and uploads the volume) so the renderer string can be read
        self.gl_renderer = gl_renderer(win)
        self.backend = ("llvmpipe-glx" if "llvmpipe" in self.gl_renderer
                        else self.gl_renderer.split()[0].lower() + "-glx")
        self.win, self.ren, self.mapper, self.prop, self.w, self.h = win, ren, mapper, prop, w, h
        self.buf = vtk.vtkFloatArray()
        self.voxel = voxel

    def frame(self):
        self.win.Render()
        self.win.GetRGBAPixelData(0, 0, self.w - 1, self.h - 1, 0, self.buf)  # back buffer, row 0 = bottom

    def image(self):
        """The last frame as premultiplied float RGBA (h, w, 4), row 0 = bottom.
        RGBA8 framebuffer over black with alpha 0: rgb is already
        premultiplied; clamp away float read-back noise."""
        return np.clip(numpy_support.vtk_to_numpy(self.buf).reshape(self.h, self.w, 4), 0, 1).astype(np.float32)

    def set_step(self, step):
        self.mapper.SetSampleDistance(step * self.voxel)

    def clipping_range(self):
        return self.ren.GetActiveCamera().GetClippingRange()


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("scene")
    ap.add_argument("--out", required=True, help="CSV to append rows to")
    ap.add_argument("--frames", type=int, default=5)
    ap.add_argument("--steps", help="comma-separated ray steps in voxels (default: the scene's step)")
    ap.add_argument("--png", help="VTK image at the scene's step (default scene_dir/vtk_<workload>.png)")
    a = ap.parse_args()
    if a.frames < 5:
        sys.exit("vtk_peer: --frames must be at least 5")

    scene = json.load(open(a.scene))
    if not scene.get("volume"):
        sys.exit("vtk_peer: %s has no volume file (phantoms are generated inside libvoxlight)" % a.scene)
    sdir = os.path.dirname(os.path.abspath(a.scene))
    name, w, h = scene["workload"], scene["width"], scene["height"]
    col = lambda key: np.array(scene[key], dtype=float).reshape(4, 4).T  # column-major lists
    affine, view, proj = col("affine"), col("view"), col("proj")
    ref = np.fromfile(os.path.join(sdir, scene["reference_image"]), dtype=np.float32).reshape(h, w, 4)
    ours = np.fromfile(os.path.join(sdir, scene["voxlight_image"]), dtype=np.float32).reshape(h, w, 4)
    steps = [float(s) for s in a.steps.split(",")] if a.steps else [scene["step_voxels"]]

    img, spacing = image_data(scene, affine)
    # Our step and opacity unit are voxel-space lengths; VTK's are world
    # lengths. They agree for isotropic voxels (ch2better: 0.5 mm).
    voxel = float(np.mean(spacing))
    if np.ptp(spacing) > 1e-6 * voxel:
        print("vtk_peer: warning: anisotropic spacing %s, using the mean" % spacing, file=sys.stderr)
    color, opacity = transfer_function(scene)

    peer = Peer(img, voxel, color, opacity, scene["material"], w, h, view, proj)
    dv, dp = peer.camera_diff
    renderer, backend, frame = peer.gl_renderer, peer.backend, peer.frame
    reference = reference_label(a.out, name)

    runs, rows = [], []
    for step in steps:
        peer.set_step(step)
        t0 = time.perf_counter()
        frame()  # warm-up: shader variant, tables for this sample distance
        warm_ms = (time.perf_counter() - t0) * 1e3
        times = []
        for _ in range(a.frames):
            t0 = time.perf_counter()
            frame()
            times.append((time.perf_counter() - t0) * 1e3)
        ms = statistics.median(times)
        pic = peer.image()
        rmse, psnr, maxabs = errors(pic, ref)
        run = dict(step=step, sample_distance_world=step * voxel, ms_median=ms, frames_ms=[round(t, 2) for t in times],
                   warmup_ms=round(warm_ms, 1), vtk_vs_ref=dict(rmse=rmse, psnr_db=psnr))
        if step == scene["step_voxels"]:  # our saved image is for the scene's step only
            write_png(a.png or os.path.join(sdir, "vtk_%s.png" % name), pic)
            o_rmse, o_psnr, _ = errors(ours, ref)
            vs_rmse, vs_psnr, _ = errors(pic, ours)
            run.update(voxlight_vs_ref=dict(rmse=o_rmse, psnr_db=o_psnr),
                       vtk_vs_voxlight=dict(rmse=vs_rmse, psnr_db=vs_psnr))
        runs.append(run)
        row = dict.fromkeys(CSV_COLUMNS, "")
        row.update(workload=name, filter="central", sample_distance=1, step="%g" % step, reuse_gradients=0,
                   classify="post", backend=backend, renderer="vtk", ms_median="%.2f" % ms,
                   fetches_per_sample=7, rmse="%.6f" % rmse, psnr_db="%.2f" % psnr, max_abs="%.5f" % maxabs,
                   size="%dx%d" % (w, h), frames=a.frames, reference=reference)
        rows.append(row)
        print("vtk_peer: %s %dx%d step %g on %s: %.2f ms median of %d (warm-up %.0f ms), rmse %.5f (%.2f dB)"
              % (name, w, h, step, renderer, ms, a.frames, warm_ms, rmse, psnr), file=sys.stderr)
        if "vtk_vs_voxlight" in run:
            print("vtk_peer:   voxlight's image at this step: rmse %.5f (%.2f dB); vtk vs voxlight %.5f (%.2f dB)"
                  % (o_rmse, o_psnr, vs_rmse, vs_psnr), file=sys.stderr)

    new = not os.path.exists(a.out) or os.path.getsize(a.out) == 0
    with open(a.out, "a", newline="") as f:
        wr = csv.DictWriter(f, CSV_COLUMNS, lineterminator="\n")
        if new:
            wr.writeheader()
        wr.writerows(rows)

    near, far = peer.clipping_range()  # after rendering: VTK must not have reset it
    print("vtk_peer: match: view max|diff| %.2g, proj max rel diff %.2g, clip %.1f..%.1f" % (dv, dp, near, far),
          file=sys.stderr)
    # Sidecar for the docs: what ran, and how well the camera was matched.
    info = dict(vtk_version=vtk.vtkVersion.GetVTKVersion(), gl_renderer=renderer, backend=backend,
                size=[w, h], opacity_unit_distance=voxel, camera_view_max_abs_diff=dv,
                camera_proj_max_rel_diff=dp, clipping_range=[near, far], runs=runs)
    with open(os.path.join(sdir, "vtk_%s.json" % name), "w") as f:
        json.dump(info, f, indent=1)


if __name__ == "__main__":
    main()
