#!/usr/bin/env python3
"""tools/check_includes.py [--root DIR] [-I DIR ...] [--layers ORDER]

Fails (exit 1) on an include cycle under csrc/, so that dependencies keep
going one way: from the CLI down to core.

It reads every `#include "..."` line of csrc/**/*.{c,h,cpp} and resolves the
name the way the compiler does with the Makefile's flags: first the including
file's own folder, then each -I folder in order (taken from the Makefile's
CFLAGS through `make`, so a Makefile that lists its folders by wildcard is
read right). Headers outside csrc/ (build/gen/, the system) are not followed.
Then it checks:

  files    no cycle between files (a.h includes b.h includes a.h);
  modules  cycles between modules, a module being one stem's .c/.cpp/.h
           (x.h includes y.h while y.c includes x.h is a cycle of modules):
           listed as notes, failed only with --modules (there are none
           since the hub header renderer_internal.h was split by subsystem);
  folders  no cycle between csrc/ folders;
  layers   a folder includes only itself and folders below it in LAYERS;
           every folder is in LAYERS, and no two headers share a name (with
           one -I per folder the first on the path would win silently).

Files directly in csrc/ (today's flat layout) belong to no layer: for them
only the first two checks mean anything. Prints each cycle with its path
(every step names the including file and the line) and a last line
"N passed, M failed" (one per check) that ./build.sh test counts.
"""
import argparse
import os
import re
import subprocess
import sys
import tempfile

# The declared layer order of csrc/ folders, top first. A folder may include
# itself and any folder on a later line; folders on one line are peers and
# may not include each other. A new folder gets a line here and a box in
# docs/architecture.md.
LAYERS = [
    ["cli", "helpers"],               # executables: voxlight, voxlight-read-*
    ["render"],                       # frames, the renderer object, the API
    ["classify", "gradients", "skip", "light", "cut", "labels", "overlay", "colour", "channels"],  # derived volumes, cutaways, labels, overlays, a colour volume's colour, a multi-channel volume's channels: what the ray caster reads
    ["storage"],                      # dense/bricked/sparse/compressed
    ["gl", "io", "frame"],            # GL services; file readers; render parameters
    ["volume"],                       # CPU volumes, phantoms
    ["core"],                         # errors, math, names
    ["platform"],                     # the OS seams, one file per OS
    ["include"],                      # the public headers
]

SOURCE_EXT = (".c", ".h", ".cpp")
INCLUDE_RE = re.compile(r'^\s*#\s*include\s*"([^"]+)"')


def parse_layers(text):
    """'cli helpers > render > core' -> [['cli','helpers'],['render'],['core']]"""
    return [part.split() for part in text.split(">") if part.split()]


def makefile_include_dirs(root):
    """The -I folders of the Makefile's CFLAGS, in order, as make expands
    them (None when there is no Makefile or make cannot read it)."""
    if not os.path.isfile(os.path.join(root, "Makefile")):
        return None
    with tempfile.NamedTemporaryFile("w", suffix=".mk", delete=False) as extra:
        extra.write("print-check-includes-cflags:\n\t@echo $(CFLAGS)\n")
    try:
        env = dict(os.environ)
        env.pop("MAKEFLAGS", None)
        env.pop("MFLAGS", None)
        out = subprocess.run(
            ["make", "--no-print-directory", "-s", "-f", "Makefile", "-f", extra.name,
             "print-check-includes-cflags"],
            cwd=root, env=env, capture_output=True, text=True, timeout=60)
    except (OSError, subprocess.TimeoutExpired):
        return None
    finally:
        os.unlink(extra.name)
    if out.returncode != 0:
        return None
    tokens = out.stdout.split()
    dirs = []
    for i, tok in enumerate(tokens):
        if tok == "-I" and i + 1 < len(tokens):
            dirs.append(tokens[i + 1])
        elif tok.startswith("-I") and len(tok) > 2:
            dirs.append(tok[2:])
    return dirs


def find_sources(csrc):
    files = []
    for dirpath, dirnames, filenames in os.walk(csrc):
        dirnames.sort()
        for name in sorted(filenames):
            if name.endswith(SOURCE_EXT):
                files.append(os.path.join(dirpath, name))
    return files


def folder_of(rel):
    """'io/nifti.c' -> 'io'; 'nifti.c' (flat csrc/) -> None"""
    parts = rel.split(os.sep)
    return parts[0] if len(parts) > 1 else None


def module_of(rel):
    return os.path.splitext(rel)[0]


def find_cycles(edges):
    """Every strongly connected component with a cycle, each as one cycle
    (a list of nodes, first == last). edges: node -> {node: evidence}."""
    index, low, on_stack, stack, sccs = {}, {}, set(), [], []
    counter = [0]
    nodes = sorted(set(edges) | {b for a in edges for b in edges[a]})

    def strongconnect(start):
        # iterative Tarjan: the include graph of a big tree must not hit
        # Python's recursion limit
        work = [(start, iter(sorted(edges.get(start, {}))))]
        index[start] = low[start] = counter[0]
        counter[0] += 1
        stack.append(start)
        on_stack.add(start)
        while work:
            node, it = work[-1]
            advanced = False
            for nxt in it:
                if nxt not in index:
                    index[nxt] = low[nxt] = counter[0]
                    counter[0] += 1
                    stack.append(nxt)
                    on_stack.add(nxt)
                    work.append((nxt, iter(sorted(edges.get(nxt, {})))))
                    advanced = True
                    break
                if nxt in on_stack:
                    low[node] = min(low[node], index[nxt])
            if advanced:
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[node])
            if low[node] == index[node]:
                comp = []
                while True:
                    n = stack.pop()
                    on_stack.discard(n)
                    comp.append(n)
                    if n == node:
                        break
                sccs.append(comp)

    for n in nodes:
        if n not in index:
            strongconnect(n)

    cycles = []
    for comp in sccs:
        members = set(comp)
        first = min(comp)
        if len(comp) == 1 and first not in edges.get(first, {}):
            continue
        # shortest way back to `first` inside the component (breadth first)
        prev = {first: None}
        queue = [first]
        found = None
        while queue and found is None:
            nxt_queue = []
            for n in queue:
                for m in sorted(edges.get(n, {})):
                    if m == first:
                        found = n
                        break
                    if m in members and m not in prev:
                        prev[m] = n
                        nxt_queue.append(m)
                if found is not None:
                    break
            queue = nxt_queue
        path = [first]
        n = found
        while n is not None and n != first:
            path.append(n)
            n = prev[n]
        path.append(first)
        # path was built backwards from the last step
        cycle = [first] + list(reversed(path[1:-1])) + [first]
        cycles.append((cycle, sorted(comp)))
    return sorted(cycles)


def describe(cycle, members, edges, label):
    lines = ["  " + " -> ".join(label(n) for n in cycle)]
    for a, b in zip(cycle, cycle[1:]):
        lines.append("      " + edges[a][b])
    if len(members) > len(cycle) - 1:
        lines.append(f"    (the shortest cycle through {label(cycle[0])}; {len(members)} are tangled together: "
                     + " ".join(label(n) for n in members) + ")")
    return "\n".join(lines)


def main(argv=None):
    here = os.path.dirname(os.path.abspath(__file__))
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[1])
    ap.add_argument("--root", default=os.path.dirname(here),
                    help="the tree holding csrc/ and the Makefile (default: this repository)")
    ap.add_argument("-I", dest="include_dirs", action="append",
                    help="an include folder, relative to --root (repeat; default: the Makefile's CFLAGS)")
    ap.add_argument("--layers", help="the layer order, top first: 'cli helpers > render > ... > core'")
    ap.add_argument("--modules", action="store_true",
                    help="fail on module cycles too (default: list them as notes)")
    args = ap.parse_args(argv)

    root = os.path.abspath(args.root)
    csrc = os.path.join(root, "csrc")
    if not os.path.isdir(csrc):
        print(f"check_includes: no csrc/ under {root}")
        print("0 passed, 1 failed")
        return 1
    layers = parse_layers(args.layers) if args.layers else LAYERS
    rank = {folder: i for i, line in enumerate(layers) for folder in line}

    inc_dirs = args.include_dirs
    source_of_dirs = "-I"
    if inc_dirs is None:
        inc_dirs = makefile_include_dirs(root)
        source_of_dirs = "the Makefile's CFLAGS"
    if inc_dirs is None:
        # no Makefile: what it would say, one -I per folder after include/
        sub = sorted(d for d in os.listdir(csrc) if os.path.isdir(os.path.join(csrc, d)) and d != "include")
        inc_dirs = ["csrc/include", "csrc"] + [f"csrc/{d}" for d in sub]
        source_of_dirs = "csrc/include, csrc and each folder (no Makefile)"
    search = [os.path.normpath(os.path.join(root, d)) for d in inc_dirs]

    files = find_sources(csrc)
    rel = {f: os.path.relpath(f, csrc) for f in files}
    file_edges, module_edges, folder_edges = {}, {}, {}
    layer_errors = []
    n_includes = 0

    for f in files:
        with open(f, encoding="utf-8", errors="replace") as fh:
            lines = fh.readlines()
        for lineno, line in enumerate(lines, 1):
            m = INCLUDE_RE.match(line)
            if not m:
                continue
            name = m.group(1)
            target = None
            for d in [os.path.dirname(f)] + search:
                cand = os.path.normpath(os.path.join(d, name))
                if os.path.isfile(cand):
                    target = cand
                    break
            if target is None or os.path.relpath(target, csrc).startswith(".."):
                continue  # generated (build/gen) or outside csrc/
            n_includes += 1
            a, b = rel[f], os.path.relpath(target, csrc)
            where = f"csrc/{a}:{lineno}: #include \"{name}\" -> csrc/{b}"
            file_edges.setdefault(a, {}).setdefault(b, where)
            ma, mb = module_of(a), module_of(b)
            if ma != mb:
                module_edges.setdefault(ma, {}).setdefault(mb, where)
            fa, fb = folder_of(a), folder_of(b)
            if fa is not None and fb is not None and fa != fb:
                folder_edges.setdefault(fa, {}).setdefault(fb, where)
                if fa in rank and fb in rank and rank[fb] <= rank[fa]:
                    kind = "a peer" if rank[fb] == rank[fa] else "a folder above it"
                    layer_errors.append(f"  {fa} includes {kind} ({fb}): {where}")

    folders = sorted({folder_of(r) for r in rel.values()} - {None})
    for folder in folders:
        if folder not in rank:
            layer_errors.append(f"  csrc/{folder}/ is not in the layer order (LAYERS in tools/check_includes.py)")
    headers = {}
    for r in sorted(rel.values()):
        if r.endswith(".h"):
            headers.setdefault(os.path.basename(r), []).append(r)
    for base, paths in sorted(headers.items()):
        if len(paths) > 1:
            layer_errors.append(f"  two headers named {base}: " + ", ".join(f"csrc/{p}" for p in paths))

    checks = [
        ("files", file_edges, lambda n: f"csrc/{n}"),
        ("modules", module_edges, lambda n: f"csrc/{n}.*"),
        ("folders", folder_edges, lambda n: f"csrc/{n}/"),
    ]
    passed = failed = 0
    print(f"check_includes: {len(files)} files, {n_includes} includes inside csrc/, "
          f"{len(folders)} folders; include path from {source_of_dirs}: {' '.join(inc_dirs)}")
    for what, edges, label in checks:
        cycles = find_cycles(edges)
        if cycles and what == "modules" and not args.modules:
            # a hub header makes every module that includes it part of a
            # cycle (renderer_internal.h did until split
            # it): listed, not failed, unless --modules
            print(f"check_includes: note: {len(cycles)} cycle(s) between modules (not failed without --modules):")
            for c, members in cycles:
                print(describe(c, members, edges, label))
        elif cycles:
            failed += 1
            print(f"check_includes: FAIL: {len(cycles)} include cycle(s) between {what}:")
            for c, members in cycles:
                print(describe(c, members, edges, label))
        else:
            if what != "modules" or args.modules:
                passed += 1
            print(f"check_includes: no cycle between {what}")
    if layer_errors:
        failed += 1
        print(f"check_includes: FAIL: {len(layer_errors)} layer-order error(s) "
              f"(order, top first: {' > '.join(' '.join(line) for line in layers)}):")
        print("\n".join(layer_errors))
    elif folders:
        passed += 1
        print(f"check_includes: every folder includes only folders below it "
              f"({' > '.join(' '.join(line) for line in layers)})")
    else:
        passed += 1
        print("check_includes: flat csrc/, no folders to layer")
    print(f"{passed} passed, {failed} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
