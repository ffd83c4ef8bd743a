"""plugin/core/ is the add-on's Blender-free core: no module there may
import bpy, mathutils, gpu or bgl (or their bpy_extras/gpu_extras helpers),
directly, inside a function, or through a module above core/ (`from ..`),
so that tests/python can test all of it in plain Python."""

import ast
import os
import subprocess
import sys
import textwrap

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
CORE = os.path.join(ROOT, "plugin", "core")
BLENDER_ONLY = ("bpy", "bpy_extras", "mathutils", "gpu", "gpu_extras", "bgl")


def _imports_by_name(node):
    """__import__("x") or importlib.import_module("x") with a literal name."""
    if not (isinstance(node, ast.Call) and node.args and isinstance(node.args[0], ast.Constant)
            and isinstance(node.args[0].value, str)):
        return False
    f = node.func
    return ((isinstance(f, ast.Name) and f.id == "__import__")
            or (isinstance(f, ast.Attribute) and f.attr == "import_module"))


def blender_imports(folder):
    """['file:line: what'] for every import in folder/*.py that needs Blender
    or reaches out of the folder (a relative import of level 2 or more)."""
    found = []
    for name in sorted(os.listdir(folder)):
        if not name.endswith(".py"):
            continue
        path = os.path.join(folder, name)
        with open(path, encoding="utf-8") as f:
            tree = ast.parse(f.read(), path)
        for node in ast.walk(tree):
            if isinstance(node, ast.Import):
                tops = [a.name.split(".")[0] for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                if node.level >= 2:
                    found.append("%s:%d: from %s" % (name, node.lineno, "." * node.level))
                    continue
                tops = [(node.module or "").split(".")[0]] if node.level == 0 else []
            elif _imports_by_name(node):
                tops = [node.args[0].value.split(".")[0]]
            else:
                continue
            found += ["%s:%d: %s" % (name, node.lineno, t) for t in tops if t in BLENDER_ONLY]
    return found


def test_core_modules_do_not_import_blender():
    modules = [n for n in os.listdir(CORE) if n.endswith(".py") and n != "__init__.py"]
    assert len(modules) >= 10, modules  # the folder is really there and populated
    assert blender_imports(CORE) == []


def test_the_scan_finds_each_kind_of_blender_import(tmp_path):
    # The scan above must be able to fail: each of these is one finding.
    (tmp_path / "a.py").write_text("import bpy\nimport numpy\n")
    (tmp_path / "b.py").write_text("def f():\n    from mathutils import Matrix\n")
    (tmp_path / "c.py").write_text("from .. import tf\nfrom . import depth\n")
    (tmp_path / "d.py").write_text("import importlib\nimportlib.import_module('gpu.types')\n")
    (tmp_path / "e.py").write_text("import bgl, os\n")
    assert blender_imports(str(tmp_path)) == [
        "a.py:1: bpy", "b.py:2: mathutils", "c.py:1: from ..", "d.py:2: gpu", "e.py:1: bgl"]


def test_every_core_module_imports_with_blender_absent():
    # In a fresh interpreter where importing any Blender module raises, so a
    # bpy import hidden anywhere the scan cannot see still fails here.
    script = textwrap.dedent("""
        import importlib, os, sys, types
        blocked = %r

        class NoBlender:
            def find_spec(self, name, path=None, target=None):
                if name.split(".")[0] in blocked:
                    raise ImportError("Blender module imported: " + name)
                return None

        sys.meta_path.insert(0, NoBlender())
        pkg = types.ModuleType("voxlight")
        pkg.__path__ = [os.path.dirname(%r)]
        sys.modules["voxlight"] = pkg
        for name in sorted(os.listdir(%r)):
            if name.endswith(".py") and name != "__init__.py":
                importlib.import_module("voxlight.core." + name[:-3])
        print("imported", sum(m.startswith("voxlight.core.") for m in sys.modules))
    """) % (BLENDER_ONLY, CORE, CORE)
    r = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    count = len([n for n in os.listdir(CORE) if n.endswith(".py") and n != "__init__.py"])
    assert r.stdout.split() == ["imported", str(count)]
