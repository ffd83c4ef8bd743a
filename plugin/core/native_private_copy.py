"""Private copies of libvoxlight, the libraries it loads from its own folder
and its reader helpers, so the library is never mapped from the add-on's
own folder (see below), and the execute bit Blender's zip install drops from
the helpers.

Part of the ctypes binding; plugin/core/native.py re-exports it."""

import errno
import hashlib
import os
import shutil
import tempfile
import time

from . import platform_rules

# The reader processes the library starts, found next to the library itself
# (csrc/io/reader_spawn.c, csrc/io/reader_stream.h): voxlight-read-oiio (TIFF/PNG
# stacks and OpenVDB) and voxlight-read-dicom; every voxlight-read-* file is
# shipped and copied with the library.
HELPER_PREFIX = "voxlight-read-"
VDB_HELPER_NAME = "voxlight-read-oiio"  # the one that reads .vdb files
OLD_VDB_HELPER_NAME = "voxlight-vdb-read"  # its name in older builds


# ------------------------------------------------- private library copies
#
# Installing an add-on over itself writes the new files where the old ones
# are; if libvoxlight.so were mapped from there, the running Blender would
# crash at its next call into it. So the library is loaded from a copy in a
# cache folder named by the content's hash, together with the reader helpers
# it starts from its own folder (found with dladdr, csrc/io/reader_spawn.c)
# and, on Windows, the DLLs it loads from there (zlib1.dll; the rules'
# is_companion), all of them part of the hash. An updated add-on has
# another hash, hence a new folder and a fresh dlopen (dlopen of the old
# path would hand back the old, already loaded library).
# Each process holds the folder it uses (platform_rules: a shared flock, or
# on Windows the lock file kept open); a folder nobody holds is stale and
# removed by the next load.

_LOCK_NAME = ".in-use"
_held_locks = {}  # folder -> open lock file, kept for the life of the process


def helper_names(folder, rules=None):
    """The helper executables shipped next to the library in folder."""
    rules = rules or platform_rules.current()
    try:
        names = os.listdir(folder)
    except OSError:
        return []
    return sorted(n for n in names
                  if (rules.is_helper(n, HELPER_PREFIX) or n == OLD_VDB_HELPER_NAME)
                  and os.path.isfile(os.path.join(folder, n)))


def companion_names(folder, rules=None, library=None):
    """The files besides the helpers that the library in folder needs next
    to it (rules.is_companion: on Windows the other DLLs), library's own
    name excepted."""
    rules = rules or platform_rules.current()
    library = rules.path.normcase(library or rules.library)
    try:
        names = os.listdir(folder)
    except OSError:
        return []
    return sorted(n for n in names
                  if rules.is_companion(n) and rules.path.normcase(n) != library
                  and os.path.isfile(os.path.join(folder, n)))


# Set by the add-on when Blender gives it a folder of its own (an
# extension's user folder, 4.2+; compat.private_data_dir).
CACHE_DIR = None


def cache_roots(rules=None, environ=None):
    """Where private copies may go, best first: VOXLIGHT_CACHE_DIR, the
    add-on's own folder (CACHE_DIR), the user's cache folder (XDG's, or
    Windows' local application data), then the temporary folder."""
    rules = rules or platform_rules.current()
    environ = os.environ if environ is None else environ
    roots = []
    for d in (environ.get("VOXLIGHT_CACHE_DIR"), CACHE_DIR):
        if d:
            roots.append(d)
    roots.append(rules.path.join(rules.cache_base(environ), "voxlight", "lib"))
    roots.append(platform_rules.temp_root(rules))
    return roots


def _content_key(files):
    h = hashlib.sha256()
    for f in files:
        h.update(os.path.basename(f).encode() + b"\0")
        with open(f, "rb") as fh:
            for block in iter(lambda: fh.read(1 << 20), b""):
                h.update(block)
        h.update(b"\0")
    return h.hexdigest()[:24]


def _hold(folder, rules):
    """Mark folder in use for this process's life; False when the folder
    went away meanwhile (a cleaner removed it)."""
    if folder in _held_locks:
        return True
    handle = rules.hold(os.path.join(folder, _LOCK_NAME))
    if handle is None:
        return False
    _held_locks[folder] = handle
    return True


def _complete(folder, files):
    return all(os.path.isfile(os.path.join(folder, os.path.basename(f))) and
               os.path.getsize(os.path.join(folder, os.path.basename(f))) == os.path.getsize(f)
               for f in files)


def _make_copy(root, key, files, rules):
    """root/key holding a copy of files (made atomically by renaming a
    finished folder into place); returns the folder."""
    folder = os.path.join(root, key)
    if os.path.isdir(folder) and _complete(folder, files) and _hold(folder, rules):
        return folder
    os.makedirs(root, exist_ok=True)
    stage = tempfile.mkdtemp(prefix=".stage-", dir=root)
    try:
        for f in files:
            name = os.path.basename(f)
            dest = os.path.join(stage, name)
            shutil.copyfile(f, dest)
            helper = rules.is_helper(name, HELPER_PREFIX) or name == OLD_VDB_HELPER_NAME
            os.chmod(dest, 0o755 if helper else 0o644)
        open(os.path.join(stage, _LOCK_NAME), "w").close()
        try:
            os.rename(stage, folder)
        except OSError:
            # Another process put it in place first, or a broken copy is in
            # the way: use this process's own copy under another name.
            if os.path.isdir(folder) and _complete(folder, files) and _hold(folder, rules):
                shutil.rmtree(stage, ignore_errors=True)
                return folder
            folder = "%s-%d" % (folder, os.getpid())
            shutil.rmtree(folder, ignore_errors=True)
            os.rename(stage, folder)
    except BaseException:
        shutil.rmtree(stage, ignore_errors=True)
        raise
    if not _hold(folder, rules):
        raise OSError(errno.ENOENT, "%s vanished" % folder)
    return folder


def clean_stale_copies(root, rules=None):
    """Remove copies no process holds. Safe while other Blenders run: a
    held folder is never touched."""
    rules = rules or platform_rules.current()
    try:
        names = os.listdir(root)
    except OSError:
        return
    for name in names:
        folder = os.path.join(root, name)
        if folder in _held_locks or not os.path.isdir(folder):
            continue
        if name.startswith(".stage-"):
            # A copy being made now, or left by a crash: only old ones go.
            try:
                if time.time() - os.path.getmtime(folder) > 3600:
                    shutil.rmtree(folder, ignore_errors=True)
            except OSError:
                pass
            continue
        lock = os.path.join(folder, _LOCK_NAME)
        if not os.path.isfile(lock):
            continue  # not ours (no lock file): leave it
        claim = rules.claim_unused(lock)
        if claim is None:
            continue  # in use by a running process
        try:
            # The lock file goes last, so that a loader that opened it
            # before the removal sees it gone (rules.hold).
            for entry in os.listdir(folder):
                if entry != _LOCK_NAME:
                    os.unlink(os.path.join(folder, entry))
            rules.remove_lock(lock)
            os.rmdir(folder)
        except OSError:
            pass
        finally:
            rules.release_claim(claim)


def private_copy(path, rules=None):
    """The path of a private copy of the library at path, with the files it
    needs (companion_names) and the helpers that sit next to it, or None
    when no cache folder is writable (the library is then loaded in
    place)."""
    rules = rules or platform_rules.current()
    src = os.path.dirname(os.path.abspath(path))
    names = companion_names(src, rules, os.path.basename(path)) + helper_names(src, rules)
    files = [os.path.abspath(path)] + [os.path.join(src, n) for n in names]
    try:
        key = _content_key(files)
    except OSError:
        return None
    for root in cache_roots(rules):
        try:
            folder = _make_copy(root, key, files, rules)
        except OSError:
            continue
        clean_stale_copies(root, rules)
        return os.path.join(folder, os.path.basename(path))
    return None


def restore_execute_bit(path):
    """Blender installs an add-on zip with zipfile.extractall, which drops
    file modes, so the shipped helper arrives without its execute bit: give
    it back (execute where it is readable). Returns whether path is now
    executable; a missing or read-only helper is left to the library, whose
    error names it when a .vdb is loaded."""
    try:
        mode = os.stat(path).st_mode
        if not os.access(path, os.X_OK):
            os.chmod(path, mode | ((mode & 0o444) >> 2))
    except OSError:
        return False
    return os.access(path, os.X_OK)
