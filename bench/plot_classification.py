"""plot_classification.py - the classification axis of the benchmark: on a
thin opacity spike (workload spike64, voxlight-bench), image error against
frame time for post-, pre- and pre-integrated classification across ray
steps. Called by plot.py, which keeps these rows out of the filter panels.

The claim it tests: pre-integration reaches a given error at a much
larger step, hence in less time. The text below the table is computed from
the rows, never written by hand.
"""
import os

import matplotlib.pyplot as plt

MODES = [("post", "post-classification", "tab:blue"),
         ("pre", "pre-classification", "tab:orange"),
         ("preint", "pre-integrated", "tab:green")]


def figure(rows, png):
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    for mode, name, colour in MODES:
        pts = sorted((r for r in rows if r["classify"] == mode), key=lambda r: r["ms_median"])
        if not pts:
            continue
        ax.plot([r["ms_median"] for r in pts], [r["rmse"] for r in pts], "-o", color=colour, label=name)
        for r in pts:
            ax.annotate("%g" % r["step"], (r["ms_median"], r["rmse"]), textcoords="offset points",
                        xytext=(4, 4), fontsize=7, color=colour)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.grid(True, which="both", alpha=0.3)
    ax.set_xlabel("frame time, median (ms)")
    ax.set_ylabel("image RMSE vs analytic reference")
    ax.set_title("thin opacity spike (spike64, %s, %s); labels = step in voxels"
                 % (rows[0]["backend"], rows[0]["size"]), fontsize=9)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(png, dpi=110)
    plt.close(fig)


def _cheapest_at(rows, mode, rmse):
    ok = [r for r in rows if r["classify"] == mode and r["rmse"] <= rmse]
    return min(ok, key=lambda r: r["ms_median"]) if ok else None


def section(rows, png, md_path):
    """Markdown: the figure, the table and what the numbers say."""
    md = ["## Classification on a high-frequency transfer function\n",
          "The sphere phantom (64^3) with a thin Gaussian opacity spike (sigma 2% of the window), shading "
          "off, against the analytic reference renderer; every mode at every step, in one run.\n",
          "![classification: time against error](%s)\n" % os.path.relpath(png, os.path.dirname(os.path.abspath(md_path)))]
    trs = []
    for mode, name, _ in MODES:
        for r in sorted((r for r in rows if r["classify"] == mode), key=lambda r: -r["step"]):
            trs.append([name, "%g" % r["step"], "%.2f" % r["ms_median"], "%.5f" % r["rmse"], "%.2f" % r["psnr_db"]])
    md.append("| mode | step | ms | RMSE | PSNR dB |\n|---|---|---|---|---|")
    md.extend("| " + " | ".join(t) + " |" for t in trs)
    md.append("")
    post = [r for r in rows if r["classify"] == "post"]
    pre_int = [r for r in rows if r["classify"] == "preint"]
    if post and pre_int:
        best_post = min(post, key=lambda r: r["rmse"])
        coarse = max(pre_int, key=lambda r: r["step"])
        match = _cheapest_at(pre_int, "preint", best_post["rmse"])
        post_at = _cheapest_at(post, "post", coarse["rmse"])
        md.append("- Pre-integration at its coarsest step (%g) has RMSE %.5f in %.1f ms; post-classification "
                  "needs %s." % (coarse["step"], coarse["rmse"], coarse["ms_median"],
                                 "step %g and %.1f ms for that error (%.1fx the time)"
                                 % (post_at["step"], post_at["ms_median"], post_at["ms_median"] / coarse["ms_median"])
                                 if post_at else "a finer step than any measured to reach it"))
        if match:
            md.append("- Post-classification's best error (%.5f, step %g, %.1f ms) is reached by pre-integration "
                      "at step %g in %.1f ms (%.1fx faster)." % (best_post["rmse"], best_post["step"],
                                                                 best_post["ms_median"], match["step"],
                                                                 match["ms_median"],
                                                                 best_post["ms_median"] / match["ms_median"]))
    pre = [r for r in rows if r["classify"] == "pre"]
    if pre:
        best_pre = min(pre, key=lambda r: r["rmse"])
        md.append("- Pre-classification stops improving at RMSE %.5f: interpolating classified voxels cannot "
                  "recover a spike narrower than a voxel's value step, whatever the ray step." % best_pre["rmse"])
    return "\n".join(md) + "\n"
