"""tools/check_includes.py: ./build.sh test fails on an include
cycle between csrc/ files or folders, or on a folder including one above it
in the declared layer order. Each test writes a small csrc/ tree (with a
Makefile whose CFLAGS give the -I path, as the real one does) and runs the
checker on it from another working directory."""
import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
CHECK = ROOT / "tools" / "check_includes.py"


def write_tree(root, files, iflags):
    for rel, includes in files.items():
        p = root / "csrc" / rel
        p.parent.mkdir(parents=True, exist_ok=True)
        p.write_text("".join(f'#include "{h}"\n' for h in includes) + "int x;\n")
    (root / "Makefile").write_text(f"CFLAGS := -std=c11 {iflags} -I$(BUILD)/gen\nall:\n")


def run_check(root, *extra):
    out = subprocess.run([sys.executable, str(CHECK), "--root", str(root), *extra],
                         capture_output=True, text=True, cwd="/")
    return out.returncode, out.stdout + out.stderr


def test_the_real_tree_is_read_through_its_makefile():
    """Whether the real tree passes is build.sh's own suite; here: the -I
    path comes from the real Makefile, and every csrc/ file is read."""
    rc, out = run_check(ROOT)
    first, last = out.splitlines()[0], out.strip().splitlines()[-1]
    assert "include path from the Makefile's CFLAGS: csrc/include " in first, out
    n = sum(1 for p in (ROOT / "csrc").rglob("*") if p.suffix in (".c", ".h", ".cpp"))
    assert f"check_includes: {n} files," in first
    assert re.fullmatch(r"\d+ passed, \d+ failed", last)
    assert (rc == 0) == last.endswith(" 0 failed")


def test_a_flat_header_cycle_fails_with_its_path(tmp_path):
    write_tree(tmp_path, {
        "include/voxlight.h": [],
        "a.h": ["b.h"],
        "b.h": ["c.h"],
        "c.h": ["a.h", "voxlight.h"],
        "a.c": ["a.h"],
    }, "-Icsrc/include -Icsrc")
    rc, out = run_check(tmp_path)
    assert rc == 1, out
    assert "csrc/a.h -> csrc/b.h -> csrc/c.h -> csrc/a.h" in out
    assert 'csrc/c.h:1: #include "a.h" -> csrc/a.h' in out
    assert out.strip().splitlines()[-1].endswith("failed") and " 0 failed" not in out


def test_a_module_cycle_through_a_c_file_is_listed_and_fails_with_modules(tmp_path):
    # x.h needs y.h while y.c needs x.h: no header cycle, but the modules
    # x and y depend on each other
    write_tree(tmp_path, {"x.h": ["y.h"], "y.h": [], "y.c": ["y.h", "x.h"], "x.c": ["x.h"]},
               "-Icsrc/include -Icsrc")
    rc, out = run_check(tmp_path)
    assert rc == 0, out
    assert "no cycle between files" in out
    assert "note: 1 cycle(s) between modules" in out
    assert "csrc/x.* -> csrc/y.* -> csrc/x.*" in out
    rc, out = run_check(tmp_path, "--modules")
    assert rc == 1, out
    assert "FAIL: 1 include cycle(s) between modules" in out


def layered(extra=None):
    files = {
        "include/voxlight.h": [],
        "core/error.h": ["voxlight.h"],
        "core/error.c": ["error.h"],
        "volume/volume.h": ["error.h"],
        "volume/volume.c": ["volume.h"],
        "io/nifti.c": ["volume.h", "loader_util.h"],
        "io/loader_util.h": ["volume.h"],
        "render/frame.h": ["error.h"],
        "skip/bricks.h": ["error.h"],
        "cli/cli.c": ["voxlight.h"],
    }
    files.update(extra or {})
    return files


FOLDER_IFLAGS = ("-Icsrc/include -Icsrc/core -Icsrc/volume -Icsrc/io -Icsrc/render "
                 "-Icsrc/skip -Icsrc/cli")


def test_a_layered_tree_without_cycles_passes(tmp_path):
    write_tree(tmp_path, layered(), FOLDER_IFLAGS)
    rc, out = run_check(tmp_path)
    assert rc == 0, out
    assert "7 folders" in out
    assert out.strip().splitlines()[-1] == "3 passed, 0 failed"


def test_a_folder_cycle_fails_with_the_includes_that_make_it(tmp_path):
    # bricks.h (skip) includes frame.h (render), and render uses skip
    write_tree(tmp_path, layered({"skip/bricks.h": ["frame.h"], "render/render.c": ["frame.h", "bricks.h"]}),
               FOLDER_IFLAGS)
    rc, out = run_check(tmp_path)
    assert rc == 1, out
    assert "csrc/render/ -> csrc/skip/ -> csrc/render/" in out
    assert 'csrc/skip/bricks.h:1: #include "frame.h" -> csrc/render/frame.h' in out
    assert "skip includes a folder above it (render)" in out


def test_an_upward_include_without_a_cycle_breaks_the_layer_order(tmp_path):
    # (cli/ includes nothing of core/, so core -> cli closes no cycle)
    write_tree(tmp_path, layered({"cli/cli_usage.h": [], "core/error.c": ["error.h", "cli_usage.h"]}),
               FOLDER_IFLAGS)
    rc, out = run_check(tmp_path)
    assert rc == 1, out
    assert "no cycle between folders" in out
    assert "core includes a folder above it (cli)" in out


def test_an_unlisted_folder_and_a_shared_header_name_fail(tmp_path):
    write_tree(tmp_path, layered({"misc/util.c": ["error.h"], "io/error.h": []}),
               FOLDER_IFLAGS + " -Icsrc/misc")
    rc, out = run_check(tmp_path)
    assert rc == 1, out
    assert "csrc/misc/ is not in the layer order" in out
    assert "two headers named error.h: csrc/core/error.h, csrc/io/error.h" in out


def test_names_resolve_like_the_compiler_own_folder_first(tmp_path):
    # io/nifti.c's "volume.h" is io/volume.h (its own folder comes first),
    # so there is no edge to csrc/volume/ and no cycle through it
    files = layered({"volume/volume.c": ["volume.h", "nifti_api.h"], "io/nifti_api.h": ["volume.h"]})
    write_tree(tmp_path, files, FOLDER_IFLAGS)
    rc, out = run_check(tmp_path, "--layers", "cli > render > skip > io > volume > core > include")
    assert rc == 1 and "volume includes a folder above it (io)" in out, out
    assert "csrc/io/ -> csrc/volume/ -> csrc/io/" in out
    (tmp_path / "csrc" / "io" / "volume.h").write_text("int y;\n")
    rc, out = run_check(tmp_path, "--layers", "cli > render > skip > io > volume > core > include")
    assert "csrc/io/ -> csrc/volume/" not in out, out
    assert "two headers named volume.h" in out
