#!/usr/bin/env python3
"""tools/relayout.py [--dry-run] - csrc/ by pipeline stage.

Moves every csrc/*.{c,h,cpp} into its stage folder (git mv; a file git does
not track yet is moved and said so), following MOVES below, and rewrites what
names the old paths, so that `make` builds the same library:

  Makefile  sources by wildcard over csrc/*/ (objects stay flat in
            build/obj/, found through vpath: object names, HELPER_CORE and
            FUZZ_LIB_C keep working), one -I per folder after csrc/include
            (so `#include "error.h"` needs no folder), every literal
            csrc/NAME becomes csrc/FOLDER/NAME;
  text      every csrc/NAME in the repository's other text files (comments,
            docs, tests, tools) becomes csrc/FOLDER/NAME.

It refuses to run (exit 1, nothing changed) when a file in csrc/ is not in
MOVES (add a line, then run it again), when two files would share a name
(objects are flat and -I is per folder), or outside a git work tree. Files
outside the Makefile that pass -Icsrc to a compiler are listed for a look.
Run it from anywhere; it works on the tree it sits in. Afterwards:
  make -j2 && tools/check_includes.py && ./build.sh test
"""
import argparse
import os
import re
import subprocess
import sys

# file -> stage folder under csrc/, bottom of the layers first (the order of
# tools/check_includes.py's LAYERS, reversed). csrc/include/ stays.
# Names not in the tree today are there so that files other work adds land
# in a plausible place; a missing file is skipped.
FOLDERS = {
    # errors, math, names of enumerations
    "core": """error.c error.h hash.h mat4.c mat4.h names.c names.h""",
    # CPU volumes: limits, scaling, normalised storage; generated phantoms;
    # the brick min-max grid and occupancy math (CPU only)
    "volume": """volume.c volume.h phantom.c phantom.h phantom_large.c phantom_large.h bricks.c bricks.h""",
    # every loader, the dispatch, the reader helpers' protocol and the
    # in-process readers the helpers run; image output
    "io": """volume_load.c loaders.h nifti.c nifti.h nrrd.c metaimage.c loader_util.c loader_util.h
             dicom_detect.c reader_stream.h reader_spawn.c reader_spawn.h remote_readers.c
             helper_main.c helper_main.h image_stack.cpp vdb.cpp dicom.cpp image_write.c image_write.h
             json.c json.h zarr.h zarr_store.c zarr_chunk.c zarr_read.c zarr_detect.c
             vdb_write.cpp vdb_write.h""",
    # the GL context and its backends, the function table, the GL thread,
    # programs and shader source, texture units and bindings, the GL memory
    # accountant
    "gl": """context.c context.h backend_egl.c backend_osmesa.c gl_funcs.c gl_funcs.h gl_thread.c gl_thread.h
             gl_util.c gl_util.h shader_source.c shader_source.h gl_bindings.h gl_bindings.c
             gpu.h budget.c budget.h holdings.c holdings.h""",
    # render parameters resolved against the volume, transfer-function
    # tables: plain values every GL-side stage reads (no GL)
    "frame": """frame.c frame.h frame_lighting.c transfer.c transfer.h frame_cut.c frame_cut.h""",
    # how the volume is held on the GL side: the storage interface and its
    # modes, paging on the CPU, compression, LOD levels
    "storage": """storage.c storage.h storage_dense.c storage_bricked.c storage_sparse.c storage_compressed.c
                  storage_pool.c storage_pool.h storage_derived.c storage_derived.h
                  paging.c paging.h paged.c paged.h compress.c compress.h compressed_pool.c lod.c lod.h""",
    # empty-space skipping: min-max grid, occupancy, distance map
    "skip": """skipping.c skipping.h minmax.c minmax.h""",
    # classification: transfer functions, the classified volume,
    # pre-integration
    "classify": """classification.c classification.h preint.c preint.h classified_grid.c""",
    # derived volumes for filtering: gradients, B-spline coefficients, the
    # shared kernels, the gradient probe
    "gradients": """precompute.c precompute.h paged_gradients.c gradients.h bspline.c bspline.h
                    paged_bspline.c bspline_bricks.c bspline_bricks.h kernels.c kernels.h""",
    # one frame: parameters, the renderer object, the reference renderer
    "render": """render.c render.h renderer.c renderer.h renderer_internal.h reference.c reference.h reference_light.c
                 probe.c slices.c slices.h slice_plane.c""",
    # lighting: the illumination volumes (shadows, occlusion)
    "light": """illumination.c illumination.h""",
    # cutaways: clip planes' and crop box's uniforms, cutter meshes peeled per pixel
    "cut": """cutaway.c cutaway.h""",
    # the command-line tool (an executable, not in the library)
    "cli": """cli.c cli_cut.c cli_cut.h""",
    # the reader helper executables' own main()s
    "helpers": """helper_oiio.c helper_dicom.c helper_zarr.c helper_write_vdb.c""",
}
MOVES = {name: folder for folder, names in FOLDERS.items() for name in names.split()}

SOURCE_EXT = (".c", ".h", ".cpp")
TEXT_EXT = (".c", ".h", ".cpp", ".py", ".sh", ".md", ".txt", ".mk", ".toml", ".cfg", ".json", ".glsl", ".comp", ".vert", ".frag")
# never rewritten: this script's table, and the checker's own examples
KEEP = {"tools/relayout.py", "tests/cli/test_check_includes.py"}

CSRC_DIRS_BLOCK = """\
# csrc/ holds one folder per pipeline stage (docs/architecture.md); the
# layer order is checked by tools/check_includes.py. Sources are found by
# wildcard over the folders, objects stay flat in $(BUILD)/obj/ (file names
# are unique across csrc/), and each folder is on the include path after
# csrc/include, so `#include "error.h"` names no folder.
CSRC_DIRS := $(filter-out csrc/include,$(patsubst %/,%,$(sort $(dir $(wildcard csrc/*/*.c csrc/*/*.cpp csrc/*/*.h)))))
CSRC_INC := $(addprefix -I,$(CSRC_DIRS))
vpath %.c $(CSRC_DIRS)
vpath %.cpp $(CSRC_DIRS)
"""


def git(root, *args, check=True):
    return subprocess.run(["git", *args], cwd=root, capture_output=True, text=True, check=check)


def rewrite_paths(text, moves):
    """csrc/NAME -> csrc/FOLDER/NAME for every moved NAME (not a longer name,
    not one already in a folder)."""
    names = sorted(moves, key=len, reverse=True)
    pattern = re.compile(r"(?<![\w/.-])csrc/(" + "|".join(re.escape(n) for n in names) + r")(?!\w|\.\w)")
    text = pattern.sub(lambda m: f"csrc/{moves[m.group(1)]}/{m.group(1)}", text)
    # globs over the flat folder
    text = text.replace("csrc/helper_*.c", "csrc/*/helper_*.c")
    return text


def rewrite_makefile(text, moves):
    problems = []
    text = rewrite_paths(text, moves)
    for ext in ("c", "h", "cpp"):
        text = text.replace(f"csrc/*.{ext}", f"csrc/*/*.{ext}")
    # csrc/*/*.h already holds csrc/include/*.h
    text = text.replace("csrc/*/*.h csrc/include/*.h", "csrc/*/*.h")
    # substitution references over csrc/: flat object names
    text = re.sub(r"\$\((\w+):csrc/%\.(c|cpp)=((?:\$\(\w+\)|[^)%$])*)%\.o\)",
                  r"$(patsubst %.\2,\3%.o,$(notdir $(\1)))", text)
    # pattern rules: the source is found through vpath
    text, n = re.subn(r"^(\S+:\s*)csrc/%\.(c|cpp)\b", r"\1%.\2", text, flags=re.M)
    if n == 0:
        problems.append("no pattern rule 'X/%.o: csrc/%.c' found")
    # -Icsrc (not -Icsrc/include): one -I per folder
    text, n = re.subn(r"-Icsrc(?=\s|$)", "$(CSRC_INC)", text, flags=re.M)
    if n == 0:
        problems.append("no -Icsrc flag found")
    m = re.search(r"^CFLAGS\s*:?=", text, flags=re.M)
    if not m:
        problems.append("no CFLAGS line found")
    else:
        text = text[:m.start()] + CSRC_DIRS_BLOCK + text[m.start():]
    leftover = [line for line in text.splitlines()
                if re.search(r"csrc/(?:%|[^/\s)$,]+\.(?:c|h|cpp)(?![\w/]))", line)
                and not line.lstrip().startswith("#")]
    if leftover:
        problems.append("lines still naming flat csrc/ paths:\n    " + "\n    ".join(leftover))
    return text, problems


def main(argv=None):
    ap = argparse.ArgumentParser(description="csrc/ by pipeline stage (item 3)")
    ap.add_argument("--dry-run", action="store_true", help="print the plan, change nothing")
    args = ap.parse_args(argv)
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    csrc = os.path.join(root, "csrc")
    if git(root, "rev-parse", "--is-inside-work-tree", check=False).returncode != 0:
        print(f"relayout: {root} is not a git work tree", file=sys.stderr)
        return 1

    flat = sorted(f for f in os.listdir(csrc) if f.endswith(SOURCE_EXT) and os.path.isfile(os.path.join(csrc, f)))
    if not flat:
        print("relayout: csrc/ has no flat sources left: nothing to move")
        return 0
    unknown = [f for f in flat if f not in MOVES]
    if unknown:
        print("relayout: REFUSED, nothing changed: these csrc/ files are not in the table "
              "(FOLDERS in tools/relayout.py):", file=sys.stderr)
        for f in unknown:
            print(f"    csrc/{f}", file=sys.stderr)
        print("Add each name to its stage folder's list (core volume io gl frame storage skip classify gradients "
              "render cli helpers), then run tools/relayout.py again.", file=sys.stderr)
        return 1
    # names must stay unique: flat objects, one -I per folder
    existing = {}
    for dirpath, _, files in os.walk(csrc):
        for f in files:
            if f.endswith(SOURCE_EXT) and dirpath != csrc:
                existing.setdefault(f, []).append(os.path.relpath(os.path.join(dirpath, f), root))
    clashes = [f"csrc/{f} and {', '.join(existing[f])}" for f in flat if f in existing]
    if clashes:
        print("relayout: REFUSED, nothing changed: names would not be unique:\n    " + "\n    ".join(clashes),
              file=sys.stderr)
        return 1

    moves = {f: MOVES[f] for f in flat}
    tracked = set(git(root, "ls-files", "csrc").stdout.split())
    print(f"relayout: {len(moves)} files into {len(set(moves.values()))} folders")
    for folder in FOLDERS:
        names = [f for f in flat if moves[f] == folder]
        if names:
            print(f"  csrc/{folder}/: {' '.join(names)}")
    if args.dry_run:
        return 0

    makefile = os.path.join(root, "Makefile")
    with open(makefile) as fh:
        mk_text, problems = rewrite_makefile(fh.read(), moves)
    if problems:
        print("relayout: REFUSED, nothing changed: the Makefile is not what this script knows:\n  "
              + "\n  ".join(problems), file=sys.stderr)
        return 1

    untracked = []
    for f, folder in moves.items():
        os.makedirs(os.path.join(csrc, folder), exist_ok=True)
        src, dst = f"csrc/{f}", f"csrc/{folder}/{f}"
        if src in tracked:
            git(root, "mv", src, dst)
        else:
            os.rename(os.path.join(root, src), os.path.join(root, dst))
            untracked.append(dst)
    with open(makefile, "w") as fh:
        fh.write(mk_text)

    listed = git(root, "ls-files", "-co", "--exclude-standard").stdout.splitlines()
    rewritten, iflag_users = [], []
    for rel in listed:
        if rel in KEEP or rel == "Makefile" or rel.startswith("tests/crashers/"):
            continue
        path = os.path.join(root, rel)
        if not rel.endswith(TEXT_EXT) or not os.path.isfile(path) or os.path.islink(path):
            continue
        try:
            with open(path, encoding="utf-8") as fh:
                text = fh.read()
        except UnicodeDecodeError:
            continue
        new = rewrite_paths(text, moves)
        if new != text:
            with open(path, "w", encoding="utf-8") as fh:
                fh.write(new)
            rewritten.append(rel)
        if re.search(r"-Icsrc(?=\s|\"|'|$)", new, flags=re.M):
            iflag_users.append(rel)

    print(f"relayout: moved {len(moves)} files; Makefile rewritten; csrc/ paths updated in {len(rewritten)} files:")
    for rel in rewritten:
        print(f"    {rel}")
    if untracked:
        print("relayout: not tracked by git, moved without it (git add them):\n    " + "\n    ".join(untracked))
    if iflag_users:
        print("relayout: these pass -Icsrc to a compiler; internal headers now need -Icsrc/FOLDER "
              "(or the Makefile's CSRC_INC):\n    " + "\n    ".join(iflag_users))
    print("relayout: next: make -j2 && tools/check_includes.py && ./build.sh test")
    return 0


if __name__ == "__main__":
    sys.exit(main())
