"""Both OS rule sets of the add-on (plugin/core/platform_rules.py), on
Linux: the names of the library and helpers, where private copies go (with
Windows' drive letters, backslashes and a non-ASCII user name), and how a
copy in use by another Blender is kept while a stale one is removed. The
Windows rule that a file a process holds open cannot be deleted is
emulated by a fake file system; the POSIX rules run on the real one."""

import os

import pytest

from voxlight.core import native_private_copy as npc
from voxlight.core import platform_rules


class WindowsFiles:
    """What Windows does with files held open: remove() of one raises
    PermissionError (the add-on's lock files, and a loaded DLL)."""

    def __init__(self):
        self.held = set()

    def open(self, path, mode="rb"):
        files = self

        class Handle:
            def close(self):
                files.held.discard(os.path.abspath(path))
        if not os.path.exists(path):
            raise FileNotFoundError(path)
        self.held.add(os.path.abspath(path))
        return Handle()

    def remove(self, path):
        if os.path.abspath(path) in self.held:
            raise PermissionError(13, "The process cannot access the file because it is being used", path)
        os.remove(path)


def _addon(tmp_path, rules):
    """An installed add-on's folder: the library, this OS's helper and the
    other OS's helper (which is not this platform's, so never copied)."""
    d = tmp_path / "addon"
    d.mkdir(parents=True)
    (d / rules.library).write_bytes(b"library bytes")
    (d / ("voxlight-read-oiio" + rules.helper_suffix)).write_bytes(b"helper")
    other = ".exe" if rules.helper_suffix == "" else ""
    (d / ("voxlight-read-dicom" + other)).write_bytes(b"the other platform's helper")
    return d


@pytest.fixture(autouse=True)
def _forget_held(monkeypatch):
    monkeypatch.setattr(npc, "_held_locks", {})
    monkeypatch.setattr(npc, "CACHE_DIR", None)


def test_names_per_platform():
    assert platform_rules.PosixRules().library == "libvoxlight.so"
    assert platform_rules.WindowsRules().library == "voxlight.dll"
    assert platform_rules.WindowsRules().helper_suffix == ".exe"
    assert isinstance(platform_rules.current(), platform_rules.PosixRules)  # this machine


def test_helpers_of_this_platform_only(tmp_path):
    for rules in (platform_rules.PosixRules(), platform_rules.WindowsRules()):
        d = _addon(tmp_path / rules.name, rules)
        assert npc.helper_names(str(d), rules) == ["voxlight-read-oiio" + rules.helper_suffix]


def test_windows_cache_folders_have_drive_letters_and_any_user_name():
    rules = platform_rules.WindowsRules()
    env = {"LOCALAPPDATA": "C:\\Users\\José\\AppData\\Local"}
    roots = npc.cache_roots(rules, env)
    assert roots[0] == "C:\\Users\\José\\AppData\\Local\\voxlight\\lib"
    env = {"USERPROFILE": "D:\\Profiles\\Zoë"}
    assert npc.cache_roots(rules, env)[0] == "D:\\Profiles\\Zoë\\AppData\\Local\\voxlight\\lib"
    env = {"VOXLIGHT_CACHE_DIR": "E:\\cache", "LOCALAPPDATA": "C:\\x"}
    assert npc.cache_roots(rules, env)[:2] == ["E:\\cache", "C:\\x\\voxlight\\lib"]


def test_posix_cache_folders():
    rules = platform_rules.PosixRules()
    assert npc.cache_roots(rules, {"XDG_CACHE_HOME": "/home/josé/.c"})[0] == "/home/josé/.c/voxlight/lib"


def _scenario(tmp_path, monkeypatch, rules, hold_elsewhere):
    """A copy made and held by this process, a copy held by another
    process (hold_elsewhere marks it) and a stale one; cleaning keeps the
    first two. Returns (ours, others, stale) folders."""
    addon = _addon(tmp_path, rules)
    cache = tmp_path / "cache"
    monkeypatch.setenv("VOXLIGHT_CACHE_DIR", str(cache))
    ours = os.path.dirname(_copy(addon, cache, rules))
    others, stale = cache / "held-elsewhere", cache / "stale"
    for d in (others, stale):
        d.mkdir()
        (d / rules.library).write_bytes(b"old")
        (d / npc._LOCK_NAME).write_bytes(b"")
    keep = hold_elsewhere(str(others / npc._LOCK_NAME))
    npc.clean_stale_copies(str(cache), rules)
    return ours, others, stale, keep


def _copy(addon, cache, rules, companions=()):
    path = npc.private_copy(str(addon / rules.library), rules)
    assert path and path.startswith(str(cache)), path
    assert os.path.basename(path) == rules.library
    assert sorted(os.listdir(os.path.dirname(path))) == sorted(
        [rules.library, "voxlight-read-oiio" + rules.helper_suffix, npc._LOCK_NAME, *companions])
    return path


def test_windows_copy_holds_the_dlls_voxlight_dll_loads_from_its_folder(tmp_path, monkeypatch):
    """voxlight.dll loads zlib1.dll from its own folder, which is the
    private copy's: the copy must hold it, and a new zlib1.dll must make a
    new copy (a fresh folder) rather than reuse the old one."""
    files = WindowsFiles()
    rules = platform_rules.WindowsRules(remove=files.remove, open_file=files.open)
    addon = _addon(tmp_path, rules)
    (addon / "zlib1.dll").write_bytes(b"zlib 1.3")
    # Build outputs that are not run-time files never travel.
    (addon / "libvoxlight.dll.a").write_bytes(b"import library")
    (addon / "voxlight.def").write_bytes(b"EXPORTS")
    cache = tmp_path / "cache"
    monkeypatch.setenv("VOXLIGHT_CACHE_DIR", str(cache))
    assert npc.companion_names(str(addon), rules) == ["zlib1.dll"]
    first = _copy(addon, cache, rules, companions=["zlib1.dll"])
    copied = os.path.join(os.path.dirname(first), "zlib1.dll")
    assert open(copied, "rb").read() == b"zlib 1.3"

    (addon / "zlib1.dll").write_bytes(b"zlib 1.3.1")
    second = _copy(addon, cache, rules, companions=["zlib1.dll"])
    assert os.path.dirname(second) != os.path.dirname(first), "zlib1.dll is not in the content hash"
    assert open(os.path.join(os.path.dirname(second), "zlib1.dll"), "rb").read() == b"zlib 1.3.1"
    assert open(copied, "rb").read() == b"zlib 1.3", "the copy in use was written over"


def test_posix_copy_takes_no_dll(tmp_path, monkeypatch):
    """libvoxlight.so needs only the system's libraries: a DLL beside it
    (another platform's file) is neither copied nor hashed."""
    rules = platform_rules.PosixRules()
    addon = _addon(tmp_path, rules)
    cache = tmp_path / "cache"
    monkeypatch.setenv("VOXLIGHT_CACHE_DIR", str(cache))
    before = _copy(addon, cache, rules)
    (addon / "zlib1.dll").write_bytes(b"zlib 1.3")
    assert npc.companion_names(str(addon), rules) == []
    assert _copy(addon, cache, rules) == before


def test_windows_rules_keep_held_copies_and_remove_stale_ones(tmp_path, monkeypatch):
    files = WindowsFiles()
    rules = platform_rules.WindowsRules(remove=files.remove, open_file=files.open)
    ours, others, stale, keep = _scenario(tmp_path, monkeypatch, rules, lambda lock: files.open(lock))
    assert os.path.isdir(ours) and os.path.isdir(others), "a held copy was removed"
    assert not stale.exists(), "a stale copy stayed"
    # This process holds its own copy's lock file open, as a loaded DLL is.
    assert os.path.join(ours, npc._LOCK_NAME) in files.held
    keep.close()  # the other Blender quits: its copy is stale now
    npc.clean_stale_copies(str(tmp_path / "cache"), rules)
    assert not others.exists() and os.path.isdir(ours)


def test_posix_rules_keep_held_copies_and_remove_stale_ones(tmp_path, monkeypatch):
    import fcntl
    rules = platform_rules.PosixRules()

    def hold(lock):
        fd = os.open(lock, os.O_RDONLY)
        fcntl.flock(fd, fcntl.LOCK_SH)
        return fd
    # flock is per open file description: one held here stands for another
    # process's (this process's own copy is skipped by name, _held_locks).
    ours, others, stale, keep = _scenario(tmp_path, monkeypatch, rules, hold)
    assert os.path.isdir(ours) and os.path.isdir(others)
    assert not stale.exists()
    os.close(keep)
    npc.clean_stale_copies(str(tmp_path / "cache"), rules)
    assert not others.exists() and os.path.isdir(ours)
