"""Median share of each step in the handler, per kind of draw, from VOXLIGHT_PROFILE lines."""
import re, sys, statistics as S
def parse(path):
    out = []
    for line in open(path):
        if not line.startswith("voxlight profile:") or "handler" not in line:
            continue
        m = re.search(r"handler ([\d.]+) s( \[moving\])? (.*?) \| blender scene ([\d.]+) overlays", line)
        if not m:
            continue
        total = float(m.group(1)); steps = dict()
        toks = m.group(3).split()
        for k, v in zip(toks[::2], toks[1::2]):
            steps[k] = float(v)
        if total < 0.01:
            continue  # volume hidden: nothing to do
        kind = "preview (view change)" if "rendered" in line else ("still, new refined image" if "result" in steps else "still, cached image")
        out.append((kind, total, float(m.group(4)), steps))
    return out
groups = {"depth: gl_sync (Blender's GL)": ["gl_sync"],
          "depth: read+numpy+crc": ["depth_alloc", "glreadpixels", "depth_numpy", "depth_numpy_crc", "depth_read"],
          "scene depth maths": ["scene_depth"], "params": ["params"], "digest": ["digest"],
          "library render": ["render"], "textures+fragment depth": ["color_texture", "fragment_depth", "depth_texture", "depth_check", "result"],
          "other": ["setup", "entry", "lights", "frame_setup", "policy", "update", "gpu_draw", "bookkeeping"]}
for path in sys.argv[1:]:
    rows = parse(path)
    print("==", path)
    for kind in ("preview (view change)", "still, new refined image", "still, cached image"):
        rs = [r for r in rows if r[0] == kind]
        if not rs:
            continue
        print("  %s: %d draws, median handler %.3f s, median Blender scene before it %.3f s" % (
            kind, len(rs), S.median(r[1] for r in rs), S.median(r[2] for r in rs)))
        parts = []
        for g, keys in groups.items():
            share = S.median(sum(r[3].get(k, 0.0) for k in keys) / r[1] for r in rs)
            parts.append("%s %.0f%%" % (g, 100 * share))
        print("    median share of handler: " + ", ".join(parts))
