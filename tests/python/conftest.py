"""Makes the bpy-free add-on modules importable as voxlight.<module> in plain
Python: a namespace stub stands in for the package so plugin/__init__.py
(which needs bpy) is not executed."""

import os
import sys
import types

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
PLUGIN = os.path.join(ROOT, "plugin")
HERE = os.path.dirname(os.path.abspath(__file__))

if "voxlight" not in sys.modules:
    pkg = types.ModuleType("voxlight")
    pkg.__path__ = [PLUGIN]
    sys.modules["voxlight"] = pkg
if HERE not in sys.path:
    sys.path.insert(0, HERE)
# Tests use the library from the build tree unless VOXLIGHT_LIB says otherwise.
os.environ.setdefault("VOXLIGHT_LIB", os.path.join(ROOT, os.environ.get("BUILD", "build"),
                                                   "libvoxlight.so"))


# The library and a renderer without a volume, shared by the binding's tests
# (a test module may define its own `renderer` with a volume set).
import pytest  # noqa: E402


@pytest.fixture(scope="module")
def lib():
    from voxlight.core import native
    return native.load_library()


@pytest.fixture(scope="module")
def renderer(lib):
    from voxlight.core import native
    r = native.Renderer(lib=lib)
    yield r
    r.close()
