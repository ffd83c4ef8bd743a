"""How smooth label surfaces look: the shading's second differences along
image rows and columns over the inside of label surfaces (docs/labels.md
"Smoothness"). Voxel stairs show as a jump in shading at every step; a
smooth surface's shading changes slowly from pixel to pixel.

    python3 bench/label_smoothness.py [--voxlight build/voxlight] [--out DIR] [RUN=EXTRA_ARGS ...]

renders (1) a ball of radius 10 labelled on a 48^3 grid and (2) AAL on
ch2better (mricron-data, /usr/share/mricron/templates), every label white
so the image is the shading alone, with each RUN's extra arguments, e.g.
smooth="--label-surface smooth" voxels="--label-surface voxels"; a RUN
named with a path's `@` (before@/tmp/before/build/voxlight=) uses that
binary. Prints, per scene and run, the mean and the 99th percentile of
|L[i-1] - 2 L[i] + L[i+1]| (L: luminance 0..1) over pixels whose 2
neighbours each side along that axis are fully covered, and where the
ball is concerned only within 0.85 of its radius on screen."""

import argparse
import os
import subprocess
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "tests", "python"))
sys.path.insert(0, os.path.dirname(__file__))
from nifti_write import write_nifti  # noqa: E402


def read_png(path):
    """RGBA uint8 (h, w, 4): PIL when there is one, else bench/png_read.py."""
    try:
        from PIL import Image
        return np.asarray(Image.open(path).convert("RGBA"))
    except ImportError:
        import png_read
        img = png_read.read(path)
        return img.reshape(img.shape[0], -1, 4)

TEMPLATES = "/usr/share/mricron/templates"


def white_table(path, ids):
    with open(path, "w") as f:
        f.write("# Color table file\n")
        for i in ids:
            f.write("%d L%d 255 255 255 255\n" % (i, i))


def ball(out):
    n, r = 48, 10.0
    g = np.indices((n, n, n)).astype(float) - (n - 1) / 2
    lab = ((g ** 2).sum(0) <= r * r).astype(np.uint8) * 7
    path = os.path.join(out, "ball.nii")
    write_nifti(path, lab, np.diag([1.0, 1.0, 1.0, 1.0]))
    white_table(os.path.join(out, "ball.ctbl"), [7])
    return path, path, os.path.join(out, "ball.ctbl")


def aal(out):
    table = os.path.join(out, "aal_white.ctbl")
    white_table(table, range(1, 117))
    return os.path.join(TEMPLATES, "ch2better.nii.gz"), os.path.join(TEMPLATES, "aal.nii.gz"), table


def second_differences(rgba, inside):
    lum = rgba[..., :3].astype(float) @ np.array([0.2126, 0.7152, 0.0722]) / 255.0
    full = (rgba[..., 3] == 255) & inside
    vals = []
    for axis in (0, 1):
        l, f = np.moveaxis(lum, axis, 0), np.moveaxis(full, axis, 0)
        d2 = np.abs(l[:-2] - 2 * l[1:-1] + l[2:])
        ok = f[:-4] & f[1:-3] & f[2:-2] & f[3:-1] & f[4:]
        vals.append(d2[1:-1][ok])
    v = np.concatenate(vals)
    return v.mean(), np.percentile(v, 99), v.size


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--voxlight", default="build/voxlight")
    ap.add_argument("--out", default="/tmp/label_smoothness")
    ap.add_argument("--size", type=int, default=384)
    ap.add_argument("runs", nargs="+", help="NAME=EXTRA ARGS or NAME@BINARY=EXTRA ARGS")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    scenes = {"ball": (ball(a.out), ["--azimuth", "30", "--elevation", "25"]),
              "aal": (aal(a.out), ["--azimuth", "60", "--elevation", "20"])}
    for scene, ((vol, labels, table), view) in scenes.items():
        for run in a.runs:
            name, _, extra = run.partition("=")
            name, _, binary = name.partition("@")
            png = os.path.join(a.out, "%s_%s.png" % (scene, name))
            cmd = [binary or a.voxlight, "render", vol, "-o", png, "--size", "%dx%d" % (a.size, a.size),
                   "--no-jitter", "--labels", labels, "--label-lut", table] + view + extra.split()
            subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
            img = read_png(png)
            h, w = img.shape[:2]
            inside = np.ones((h, w), bool)
            if scene == "ball":  # the ball's rim is seen edge-on: only its face
                cover = img[..., 3] > 127
                jj, ii = np.nonzero(cover)
                cy, cx = jj.mean(), ii.mean()
                rad = np.sqrt(cover.sum() / np.pi)
                yy, xx = np.indices((h, w))
                inside = (yy - cy) ** 2 + (xx - cx) ** 2 <= (0.85 * rad) ** 2
            mean, p99, n = second_differences(img, inside)
            print("%-5s %-8s mean |d2 L| %.5f  99th pct %.4f  (%d pixel triples)  %s" %
                  (scene, name, mean, p99, n, " ".join(cmd)))


if __name__ == "__main__":
    main()
