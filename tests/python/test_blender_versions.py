"""The add-on on a Blender older than it supports: a message in the
preferences and on the console, not a traceback. Runs without Blender: a
stand-in bpy module reports the old version, and the add-on package is
loaded under another name (as Blender 4.2+ does: bl_ext.<repo>.voxlight)."""

import importlib.util
import os
import sys
import types

import pytest

from voxlight import compat

PLUGIN = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(
    os.path.abspath(__file__)))), "plugin")


def test_supported_versions_have_no_message():
    for v in ((3, 4, 0), (3, 6, 5), (4, 2, 0), (4, 5, 4), (5, 0, 1), (5, 1, 0)):
        assert compat.unsupported_message(v) is None, v


def test_older_versions_are_named_with_the_minimum():
    msg = compat.unsupported_message((3, 3, 12))
    assert "3.4.0" in msg and "3.3.12" in msg
    assert compat.unsupported_message((2, 93, 0)) is not None


def test_wrap_keeps_every_word_within_the_width():
    text = compat.unsupported_message((2, 93, 0))
    lines = compat.wrap(text, 30)
    assert " ".join(lines) == " ".join(text.split())
    assert all(len(line) <= 30 for line in lines)


class _Layout:
    def __init__(self, log):
        self.log = log
        self.alert = False

    def column(self):
        return self

    def label(self, text="", icon="NONE"):
        self.log.append(text)


def _fake_bpy(version):
    registered = []
    bpy = types.ModuleType("bpy")
    bpy.app = types.SimpleNamespace(version=version)
    bpy.types = types.SimpleNamespace(AddonPreferences=type("AddonPreferences", (), {}))
    bpy.utils = types.SimpleNamespace(register_class=registered.append,
                                      unregister_class=registered.remove)
    return bpy, registered


def _load_addon(name):
    spec = importlib.util.spec_from_file_location(
        name, os.path.join(PLUGIN, "__init__.py"), submodule_search_locations=[PLUGIN])
    mod = importlib.util.module_from_spec(spec)
    sys.modules[name] = mod
    spec.loader.exec_module(mod)
    return mod


@pytest.mark.parametrize("version", [(3, 3, 0), (2, 93, 18)])
def test_old_blender_registers_only_a_message(monkeypatch, capsys, version):
    bpy, registered = _fake_bpy(version)
    monkeypatch.setitem(sys.modules, "bpy", bpy)
    name = "bl_ext.user_default.voxlight_old_%d_%d" % version[:2]
    for parent in ("bl_ext", "bl_ext.user_default"):
        monkeypatch.setitem(sys.modules, parent, types.ModuleType(parent))
    try:
        addon = _load_addon(name)
        addon.register()
        # Only the preferences that explain it, named after the package.
        assert len(registered) == 1 and registered[0].bl_idname == name
        out = capsys.readouterr().out
        assert "needs Blender 3.4.0" in out and "Traceback" not in out
        log = []
        registered[0].draw(types.SimpleNamespace(layout=_Layout(log)), None)
        assert "needs Blender 3.4.0" in " ".join(log)
        ok, msg = addon.library_status()
        assert not ok and "needs Blender" in msg
        # Nothing that uses newer API was imported.
        assert not [m for m in sys.modules if m.startswith(name + ".") and
                    m != name + ".compat"]
        addon.unregister()
        assert registered == []
    finally:
        for m in [m for m in sys.modules if m == name or m.startswith(name + ".")]:
            del sys.modules[m]
