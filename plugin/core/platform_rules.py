"""The add-on's only OS-specific code: how the library, the files that
travel with it and its reader helpers are named, where private copies of
them go, and how a process marks a copy as in use so that no other Blender
removes it (the copies themselves: native_private_copy.py). One rule set
per OS, chosen by os.name; both are exercised on Linux by
tests/python/test_platform_rules.py.

POSIX: libvoxlight.so and voxlight-read-*, copies under $XDG_CACHE_HOME,
in use while a shared flock is held on the copy's lock file (a cleaner
takes the lock exclusively, without waiting, to know it is free).

Windows: voxlight.dll, the DLLs shipped beside it (zlib1.dll) and
voxlight-read-*.exe, copies under %LOCALAPPDATA%; a loaded DLL, and any
file a process holds open, cannot be deleted or overwritten there, so a
process holds the lock file open and a cleaner knows a copy is free when it
can delete that file. Paths have drive letters and backslashes (ntpath),
and may hold any Unicode (the library takes UTF-8)."""

import ntpath
import os
import posixpath
import tempfile


class PosixRules:
    name = "posix"
    library = "libvoxlight.so"
    helper_suffix = ""
    path = posixpath
    # The program that writes OpenVDB files for Convert to Blender Volume,
    # shipped beside the library (None: this platform has no OpenVDB build).
    vdb_writer = "voxlight-write-vdb"
    no_vdb_writer = ""

    def is_helper(self, name, prefix):
        """A helper program of this platform: no extension (a .exe is
        Windows')."""
        return name.startswith(prefix) and "." not in name[len(prefix):]

    def is_companion(self, name):
        """A file the library needs beside it in its private copy, besides
        the helpers: none, as libvoxlight.so opens only the system's
        libraries (libz.so.1 by its soname)."""
        return False

    def cache_base(self, environ):
        """The user's cache folder."""
        return environ.get("XDG_CACHE_HOME") or self.path.join(self.path.expanduser("~"), ".cache")

    def user_tag(self):
        """Names the user in a shared temporary folder."""
        return str(os.getuid())

    def hold(self, lock_path):
        """An open handle that marks the copy in use for as long as it is
        open, or None (the file is gone). Compared by identity so a lock
        file replaced meanwhile is not mistaken for the one opened."""
        import fcntl
        try:
            fd = os.open(lock_path, os.O_RDONLY)
        except OSError:
            return None
        try:
            fcntl.flock(fd, fcntl.LOCK_SH)
            st, held = os.stat(lock_path), os.fstat(fd)
            if (st.st_dev, st.st_ino) != (held.st_dev, held.st_ino):
                raise OSError("%s was replaced" % lock_path)
        except OSError:
            os.close(fd)
            return None
        return fd

    def claim_unused(self, lock_path):
        """A handle proving no process holds the copy (then the caller
        removes it and, last, the lock file), or None when it is in use or
        not ours."""
        import fcntl
        try:
            fd = os.open(lock_path, os.O_RDONLY)
        except OSError:
            return None
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            os.close(fd)
            return None
        return fd

    def remove_lock(self, lock_path):
        os.unlink(lock_path)

    def release_claim(self, claim):
        os.close(claim)


class WindowsRules:
    name = "windows"
    library = "voxlight.dll"
    helper_suffix = ".exe"
    path = ntpath
    vdb_writer = None
    no_vdb_writer = ("Convert to Blender Volume needs OpenVDB, which the Windows build of Voxlight "
                     "does not include yet: convert on Linux, where the add-on ships voxlight-write-vdb")

    def __init__(self, remove=os.remove, open_file=open):
        # Windows' own behaviour, injectable so Linux tests can emulate it:
        # remove() of a file some process holds open raises PermissionError.
        self._remove = remove
        self._open = open_file

    def is_helper(self, name, prefix):
        return name.startswith(prefix) and name.lower().endswith(".exe")

    def is_companion(self, name):
        """Every other DLL shipped beside voxlight.dll (zlib1.dll):
        voxlight.dll loads them from its own folder, which is the private
        copy's once loaded from there. Windows' names ignore case."""
        lower = name.lower()
        return lower.endswith(".dll") and lower != self.library

    def cache_base(self, environ):
        return environ.get("LOCALAPPDATA") or self.path.join(
            environ.get("USERPROFILE") or self.path.expanduser("~"), "AppData", "Local")

    def user_tag(self):
        return os.environ.get("USERNAME") or "user"

    def hold(self, lock_path):
        try:
            return self._open(lock_path, "rb")
        except OSError:
            return None

    def claim_unused(self, lock_path):
        """Deleting the lock file is the test: it fails while any process
        holds it open, and once it is gone no loader can take the copy."""
        try:
            self._remove(lock_path)
        except OSError:  # PermissionError: held open by a running Blender
            return None
        return True

    def remove_lock(self, lock_path):
        pass  # claim_unused removed it already

    def release_claim(self, claim):
        pass


def current():
    return WindowsRules() if os.name == "nt" else PosixRules()


def temp_root(rules):
    """A per-user folder under the system's temporary folder."""
    return rules.path.join(tempfile.gettempdir(), "voxlight-%s" % rules.user_tag(), "lib")
