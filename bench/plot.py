#!/usr/bin/python3
"""plot.py - the benchmark figure and tables from voxlight-bench's CSV.

    /usr/bin/python3 bench/plot.py bench/results.csv --png docs/benchmark.png \
        --md docs/benchmark.md --command "./build.sh bench"

One panel per workload (a row per backend): frame time against image RMSE,
a colour per filter, our Pareto front marked, VTK's point where it ran. The
markdown holds the command, the machine, the tables and a "which filter when"
section computed from the numbers, never written by hand.
"""
import argparse
import csv
import glob
import json
import math
import os
import subprocess
import sys

import matplotlib

matplotlib.use("Agg")  # headless: CI and xvfb-less machines
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib import ticker  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import plot_classification  # noqa: E402

WORKLOADS = ["ml64", "ml41", "noisy64", "ch2better"]
FILTERS = ["central", "forward3", "sobel8", "sobel14", "sobel26", "precomputed", "cubic"]
STEP_MARKERS = {1.0: "s", 0.5: "o", 0.25: "^"}  # marker shape = ray step in voxels
NEAR_BEST = 1.10  # "good enough" = within 10 % of the best RMSE on a workload

# What the VTK peer matches and what it cannot; bench/vtk_peer.py is the code.
VTK_NOTES = """\
How the peer is matched (bench/vtk_peer.py), and checked where it can be:

- **Camera**: vtkCamera position, focal direction and view-up come from our
  view matrix, the vertical view angle and clipping range from our projection;
  VTK's own matrices are read back and compared (differences below).
- **Volume**: the same NIfTI voxels, placed by our voxel->world affine
  (origin, spacing, direction of vtkImageData); linear interpolation.
- **Transfer function**: our 256-entry preset table, one vtkColorTransferFunction
  and vtkPiecewiseFunction node per entry over the same window, so both sides
  interpolate the same piecewise-linear function. Opacity is per voxel of path
  on both sides (ScalarOpacityUnitDistance = one voxel spacing) and corrected
  for the step as 1-(1-a)^step.
- **Step**: SampleDistance = our step x voxel spacing, automatic adjustment off.
- **Shading**: Phong with the same ambient/diffuse/specular/power, one white
  headlight, two-sided lighting; central-difference gradients (one voxel).

What cannot be matched:

- **Headlight geometry**: VTK lights in data space from the eye position, with
  light and view directions fixed per ray at its entry point; ours is a
  directional light along the view axis. They differ by up to half the field
  of view at the image edge.
- **Ray start and box**: VTK's box ends at the outer voxel centres, ours half a
  voxel further out, and the sample positions along a ray differ, so the two
  sample the same field at different points.
- **Jitter**: VTK runs without jitter; our timed frame uses our deterministic
  per-pixel start jitter (the reference does not).
- **Early termination**: VTK stops at opacity 1-1/255, we at 0.99.
- **Tables**: VTK resamples both functions into its own lookup textures and
  applies opacity correction there; we correct per sample.
- **Gradient details**: VTK's central differences are taken in texture space
  and scaled by spacing; ours in voxel space through the normal matrix. Where
  |g| = 0 VTK shades with a zero normal (ambient light only), we
  leave the sample unlit.
- **Output**: VTK's image is read from an RGBA8 framebuffer (quantised to
  1/255); ours is float.
"""


def load(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    for r in rows:
        for k in ("ms_median", "rmse", "psnr_db", "ang_mean_deg", "ang_p95_deg", "step", "sample_distance"):
            r[k] = float(r[k]) if r.get(k) not in (None, "") else None
    return rows


def pareto(rows):
    """Configurations no other is both faster and more accurate than."""
    front, best = [], float("inf")
    for r in sorted(rows, key=lambda r: (r["ms_median"], r["rmse"])):
        if r["rmse"] < best:
            front.append(r)
            best = r["rmse"]
    return front


def label(r):
    sd = "" if r["sample_distance"] is None else " d=%g" % r["sample_distance"]
    return "%s%s step=%g%s" % (r["filter"], sd, r["step"], " reuse" if r["reuse_gradients"] == "1" else "")


def gradient_label(r):
    """Angular error depends on the filter and its sampleDistance only."""
    return r["filter"] + ("" if r["sample_distance"] is None else " d=%g" % r["sample_distance"])


def machine():
    cpu = "unknown"
    try:
        with open("/proc/cpuinfo") as f:
            cpu = next(l.split(":", 1)[1].strip() for l in f if l.startswith("model name"))
    except (OSError, StopIteration):
        pass
    return len(os.sched_getaffinity(0)), cpu  # what nproc reports


def git_rev():
    try:
        return subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True,
                              check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def groups(rows):
    """(backend, workload) -> our rows, in a stable order."""
    ours = [r for r in rows if r["renderer"] == "voxlight"]
    backends = sorted({r["backend"] for r in ours}, key=lambda b: (b != "osmesa", b))
    workloads = [w for w in WORKLOADS if any(r["workload"] == w for r in ours)]
    workloads += sorted({r["workload"] for r in ours} - set(workloads))
    return backends, workloads, {(b, w): [r for r in ours if r["backend"] == b and r["workload"] == w]
                                 for b in backends for w in workloads}


def peer_backend(backends):
    """VTK runs on llvmpipe: its point belongs with our llvmpipe (OSMesa) row."""
    return "osmesa" if "osmesa" in backends else backends[0]


def log_ticks(axis, lims):
    """Readable ticks on a log axis that may span less than a decade: the
    coarsest set of 'nice' mantissas that puts at least three ticks in view."""
    lo, hi = lims
    ticks = []
    finest = [x / 10 for x in range(10, 100)]
    for subs in ((1,), (1, 2, 5), (1, 2, 3, 5), (1, 1.5, 2, 3, 4, 5, 7), (1, 1.2, 1.5, 2, 2.5, 3, 4, 5, 6, 7, 8, 9),
                 finest[::5], finest):
        ticks = [m * 10 ** e for e in range(int(math.floor(math.log10(lo))), int(math.ceil(math.log10(hi))) + 1)
                 for m in subs if lo <= m * 10 ** e <= hi]
        if len(ticks) >= 3:
            break
    ticks = ticks[::max(1, len(ticks) // 5)]  # the finest set can be dense
    axis.set_major_locator(ticker.FixedLocator(ticks))
    axis.set_major_formatter(ticker.FuncFormatter(lambda v, _: "%g" % float("%.3g" % v)))
    axis.set_minor_formatter(ticker.NullFormatter())


def plot(rows, png):
    backends, workloads, g = groups(rows)
    vtk = [r for r in rows if r["renderer"] == "vtk"]
    colors = dict(zip(FILTERS, plt.get_cmap("tab10").colors))
    # Two panels a row (readable at page width), a block of rows per backend.
    cols = min(2, len(workloads))
    per = -(-len(workloads) // cols)
    fig, axes = plt.subplots(per * len(backends), cols, figsize=(6.2 * cols, 4.4 * per * len(backends) + 0.9),
                             squeeze=False)
    for i, b in enumerate(backends):
        for j, w in enumerate(workloads):
            ax, pts = axes[i * per + j // cols][j % cols], g[(b, w)]
            if not pts:  # this backend did not run this workload
                ax.set_visible(False)
                continue
            for f in FILTERS + sorted({r["filter"] for r in pts} - set(FILTERS)):
                for st in sorted({r["step"] for r in pts}, reverse=True):
                    m = STEP_MARKERS.get(st, "D")
                    fr = [r for r in pts if r["filter"] == f and r["step"] == st]
                    if fr:
                        ax.scatter([r["ms_median"] for r in fr], [r["rmse"] for r in fr], s=24, alpha=0.8,
                                   marker=m, color=colors.get(f, "grey"), label=f)
            front = pareto(pts)
            ax.step([r["ms_median"] for r in front], [r["rmse"] for r in front], where="post", color="black",
                    lw=1, zorder=1)
            ax.scatter([r["ms_median"] for r in front], [r["rmse"] for r in front], s=70, facecolors="none",
                       edgecolors="black", lw=1, label="Pareto front", zorder=3)
            if b == peer_backend(backends):
                for r in (r for r in vtk if r["workload"] == w):
                    ax.scatter([r["ms_median"]], [r["rmse"]], marker="*", s=180, color="crimson",
                               edgecolors="black", zorder=4, label="VTK GPU ray caster (%s)" % r["backend"])
            ax.set_xscale("log")
            ax.set_yscale("log")
            log_ticks(ax.xaxis, ax.get_xlim())
            log_ticks(ax.yaxis, ax.get_ylim())
            ax.grid(True, which="both", alpha=0.3)
            size = pts[0]["size"] if pts else ""
            ax.set_title("%s  (%s, %s)" % (w, b, size), fontsize=10)
            ax.set_xlabel("frame time, median (ms)")
            if j % cols == 0:
                ax.set_ylabel("image RMSE vs reference")
    # Legend built by hand: colour = filter, shape = step, so neither reads as the other.
    handles, labels = {}, []
    for st in sorted({r["step"] for r in rows if r["renderer"] == "voxlight"}, reverse=True):
        handles["step %g" % st] = plt.Line2D([], [], ls="", marker=STEP_MARKERS.get(st, "D"), color="grey")
        labels.append("step %g" % st)
    for f in FILTERS:
        if any(r["filter"] == f and r["renderer"] == "voxlight" for r in rows):
            handles[f] = plt.Line2D([], [], ls="", marker="o", color=colors[f])
            labels.append(f)
    for ax in axes.flat:
        for h, l in zip(*ax.get_legend_handles_labels()):
            if l not in handles and l not in FILTERS:
                handles[l] = h
                labels.append(l)
    fig.legend([handles[l] for l in labels], labels, loc="lower center", ncol=min(len(labels), 6), fontsize=9,
               frameon=False)
    fig.tight_layout(rect=(0, 0.9 / fig.get_figheight(), 1, 1))
    fig.savefig(png, dpi=110)


def table(header, rows):
    out = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    out += ["| " + " | ".join(str(c) for c in r) + " |" for r in rows]
    return "\n".join(out) + "\n"


def recommend(backend, workloads, g):
    """Picks per workload from the numbers: lowest error, fastest, and the
    cheapest configuration within NEAR_BEST of the lowest error."""
    picks, lines = {}, []
    for w in workloads:
        pts = g[(backend, w)]
        if not pts:
            continue
        best = min(pts, key=lambda r: r["rmse"])
        fast = min(pts, key=lambda r: r["ms_median"])
        good = min((r for r in pts if r["rmse"] <= NEAR_BEST * best["rmse"]), key=lambda r: r["ms_median"])
        ang = [r for r in pts if r["ang_mean_deg"] is not None]
        sharp = min(ang, key=lambda r: r["ang_mean_deg"]) if ang else None
        picks[w] = dict(best=best, fast=fast, good=good, sharp=sharp)
    rows = []
    for w, p in picks.items():
        rows.append([w, "%s (%.4f, %.1f ms)" % (label(p["best"]), p["best"]["rmse"], p["best"]["ms_median"]),
                     "%s (%.4f, %.1f ms)" % (label(p["good"]), p["good"]["rmse"], p["good"]["ms_median"]),
                     "%s (%.4f, %.1f ms)" % (label(p["fast"]), p["fast"]["rmse"], p["fast"]["ms_median"]),
                     "%s (%.2f°)" % (gradient_label(p["sharp"]), p["sharp"]["ang_mean_deg"]) if p["sharp"] else "n/a"])
    lines.append(table(["workload", "lowest RMSE", "cheapest within %d%% of it" % round(100 * (NEAR_BEST - 1)),
                        "fastest", "lowest mean angular error"], rows))
    # Summaries: which filter wins where, grouped so the text follows the data.
    for key, what in (("best", "gives the lowest image error"), ("good", "is the cheapest near-best choice"),
                      ("sharp", "gives the most accurate normals")):
        by = {}
        for w, p in picks.items():
            if p[key]:
                by.setdefault(p[key]["filter"], []).append(w)
        if by:
            lines.append("- " + "; ".join("**%s** %s on %s" % (f, what, ", ".join(ws)) for f, ws in by.items()) + ".")
    for w, p in picks.items():
        ref = p["best"]["reference"]
        self_ref = [f for f in FILTERS if f in ref.split()]
        if self_ref:
            lines.append("- Caveat for %s: its reference is \"%s\", so %s's error there is partly agreement "
                         "with itself; the phantoms, measured against analytic truth, are the fair test."
                         % (w, ref, self_ref[0]))
    return "\n".join(lines) + "\n"


def markdown(rows, csv_path, png, md_path, command, scene_dir, commit=None):
    backends, workloads, g = groups(rows)
    ncpu, cpu = machine()
    vtk = [r for r in rows if r["renderer"] == "vtk"]
    info = {}
    for path in sorted(glob.glob(os.path.join(scene_dir, "vtk_*.json"))):
        with open(path) as f:
            info[os.path.basename(path)[4:-5]] = json.load(f)
    md = ["# Benchmark: frame time against image error\n",
          "Generated by `bench/plot.py` from `%s`; do not edit by hand.\n" % csv_path,
          "- Command: `%s`" % command,
          "- Commit: `%s`" % (commit or git_rev()),
          "- Machine: %s CPUs, %s" % (ncpu, cpu),
          "- Backends: %s (voxlight)%s" % (", ".join(backends),
                                           "; VTK on " + ", ".join(sorted({r["backend"] for r in vtk})) if vtk else ""),
          ]
    for w, i in info.items():
        md.append("- VTK %s peer (%s): VTK %s, GL renderer \"%s\"" % (w, i["backend"], i["vtk_version"],
                                                                       i["gl_renderer"]))
    sizes = sorted({(r["size"], r["frames"]) for r in rows if r["renderer"] == "voxlight"})
    md.append("- Image size and timed frames (median taken, after one warm-up): %s\n" %
              ", ".join("%s x %s" % s for s in sizes))
    md.append("![time against error](%s)\n" % os.path.relpath(png, os.path.dirname(os.path.abspath(md_path))))
    md.append("Error is the RMSE of premultiplied RGBA against the workload's reference: the analytic "
              "reference renderer for the phantoms, the finest own setting (see the reference column) for "
              "ch2better. Black rings: our Pareto front; red star: VTK.\n")

    for b in backends:
        md.append("## Backend %s\n" % b)
        md.append("### Pareto-best configurations per filter\n")
        md.append("Per workload and filter, the configurations on that filter's own front; "
                  "\"front\" marks those on the front of all filters.\n")
        for w in workloads:
            pts = g[(b, w)]
            if not pts:
                continue
            front = {id(r) for r in pareto(pts)}
            trs = []
            for f in FILTERS:
                for r in pareto([r for r in pts if r["filter"] == f]):
                    trs.append([f, "" if r["sample_distance"] is None else "%g" % r["sample_distance"],
                                "%g" % r["step"], r["reuse_gradients"], "%.2f" % r["ms_median"],
                                r["fetches_per_sample"], "%.5f" % r["rmse"], "%.2f" % r["psnr_db"],
                                "front" if id(r) in front else ""])
            md.append("**%s** (reference: %s)\n" % (w, pts[0]["reference"]))
            md.append(table(["filter", "d", "step", "reuse", "ms", "fetches/sample", "RMSE", "PSNR dB", ""], trs))

        ang_w = [w for w in workloads if any(r["ang_mean_deg"] is not None for r in g[(b, w)])]
        if ang_w:
            md.append("### Angular error of the gradient (degrees, mean / p95)\n")
            md.append("Measured through the shader at points on the 0.5 iso-surface against the analytic "
                      "gradient; d is the filter's sampleDistance in voxels.\n")
            for w in ang_w:
                pts = g[(b, w)]
                sds = sorted({r["sample_distance"] for r in pts if r["sample_distance"] is not None})
                trs = []
                for f in FILTERS:
                    fr = [r for r in pts if r["filter"] == f and r["ang_mean_deg"] is not None]
                    if not fr:
                        continue
                    cell = {r["sample_distance"]: "%.2f / %.2f" % (r["ang_mean_deg"], r["ang_p95_deg"]) for r in fr}
                    if None in cell:  # filters without a sampleDistance
                        trs.append([f] + [cell[None]] + [""] * (len(sds) - 1))
                    else:
                        trs.append([f] + [cell.get(sd, "") for sd in sds])
                md.append("**%s**\n" % w)
                md.append(table(["filter"] + ["d = %g" % sd for sd in sds], trs))

        md.append("### Which filter when\n")
        md.append("Computed from the table above (RMSE, ms).\n")
        md.append(recommend(b, workloads, g))

    if vtk:
        pb = peer_backend(backends)
        md.append("## Side by side: VTK's GPU ray caster\n")
        trs = []
        for v in vtk:
            mine = [r for r in g.get((pb, v["workload"]), []) if r["filter"] == v["filter"]
                    and r["step"] == v["step"] and r["reuse_gradients"] == "0" and r["sample_distance"] == 1.0]
            if not mine:
                continue
            m = mine[0]
            cheaper = [r for r in g[(pb, v["workload"])] if r["rmse"] <= v["rmse"]]
            alt = min(cheaper, key=lambda r: r["ms_median"]) if cheaper else None
            trs.append([v["workload"], v["size"], "%g" % v["step"], "%.2f" % m["ms_median"], "%.2f" % v["ms_median"],
                        "%.2f" % (m["ms_median"] / v["ms_median"]), "%.5f (%.2f dB)" % (m["rmse"], m["psnr_db"]),
                        "%.5f (%.2f dB)" % (v["rmse"], v["psnr_db"]),
                        "%s, %.2f ms" % (label(alt), alt["ms_median"]) if alt else "none"])
        md.append("Same frame on both: %s filter, d = 1, step as shown; voxlight on %s, VTK on %s. "
                  "Time ratio = our median frame time over VTK's (below 1: we are faster).\n"
                  % (vtk[0]["filter"], pb, vtk[0]["backend"]))
        md.append(table(["workload", "size", "step", "voxlight ms", "VTK ms", "voxlight / VTK", "voxlight RMSE",
                         "VTK RMSE", "our fastest config at VTK's error or better"], trs))
        for w, i in info.items():
            md.append("%s, VTK frame times: %s. Camera check: view matrix max |diff| %.2g, projection max "
                      "relative diff %.2g, clipping range kept at %.1f..%.1f.\n"
                      % (w, "; ".join("step %g: %s ms (warm-up %s)" % (r["step"], ", ".join("%.1f" % t for t in
                                      r["frames_ms"]), r["warmup_ms"]) for r in i["runs"]),
                         i["camera_view_max_abs_diff"], i["camera_proj_max_rel_diff"], *i["clipping_range"]))
            for r in i["runs"]:
                if "vtk_vs_voxlight" in r:
                    md.append("Images at step %g: VTK against voxlight's own frame differ by RMSE %.5f "
                              "(%.2f dB), less than either differs from the reference.\n"
                              % (r["step"], r["vtk_vs_voxlight"]["rmse"], r["vtk_vs_voxlight"]["psnr_db"])
                              if r["vtk_vs_voxlight"]["rmse"] < min(r["vtk_vs_ref"]["rmse"],
                                                                    r["voxlight_vs_ref"]["rmse"]) else
                              "Images at step %g: VTK against voxlight's own frame differ by RMSE %.5f (%.2f dB).\n"
                              % (r["step"], r["vtk_vs_voxlight"]["rmse"], r["vtk_vs_voxlight"]["psnr_db"]))
        md.append(VTK_NOTES)
    return "\n".join(md) + "\n"


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description="benchmark figure and tables")
    ap.add_argument("csv")
    ap.add_argument("--png", default="docs/benchmark.png")
    ap.add_argument("--md", default="docs/benchmark.md")
    ap.add_argument("--command", help="the command that produced the CSV (default: this one)")
    ap.add_argument("--scene-dir", default="bench/out", help="where vtk_peer.py left vtk_<workload>.json")
    ap.add_argument("--commit", help="the commit the CSV was measured at (default: HEAD)")
    a = ap.parse_args()
    data = load(a.csv)
    # The classification study has its own figure: its axis is the mode, not the filter.
    spike = [r for r in data if r["workload"] == "spike64" and r["renderer"] == "voxlight"]
    data = [r for r in data if r["workload"] != "spike64"]
    if not any(r["renderer"] == "voxlight" for r in data):
        sys.exit("plot: no voxlight rows in %s" % a.csv)
    plot(data, a.png)
    with open(a.md, "w") as f:
        f.write(markdown(data, a.csv, a.png, a.md, a.command or " ".join(["bench/plot.py"] + sys.argv[1:]), a.scene_dir,
                         a.commit))
        if spike:
            cpng = os.path.splitext(a.png)[0] + "_classification.png"
            plot_classification.figure(spike, cpng)
            f.write("\n" + plot_classification.section(spike, cpng, a.md))
    print("plot: wrote %s and %s" % (a.png, a.md), file=sys.stderr)
