#!/bin/sh
# package_addon.sh [BUILD_DIR] - makes one Blender extension zip per platform,
# each from plugin/ and manifest/blender_manifest.toml (its `platforms` set
# to that platform alone) plus that platform's binaries only, as Blender's
# extension platform is one per package:
# - BUILD_DIR/voxlight-linux-x64.zip: BUILD_DIR/libvoxlight.so and every
#   reader helper the library starts from its own folder (BUILD_DIR/
#   voxlight-read-*, and voxlight-vdb-read where a build still has it),
#   and the add-on's own helper voxlight-write-vdb (Convert to Blender
#   Volume; run from the add-on's folder, not copied with the library);
# - BUILD_DIR/voxlight-windows-x64.zip, when BUILD_DIR/windows-x64/
#   voxlight.dll exists: voxlight.dll, every other *.dll beside it (zlib1.dll,
#   which voxlight.dll loads from its own folder at run time) and any
#   voxlight-read-*.exe helpers; not the import library, the .def or the
#   test programs.
# Blender's zip install drops the helpers' execute bit, which the add-on
# restores when it loads the library (plugin/core/native.py).
# Layout: voxlight/{__init__.py, ..., core/*.py, <binaries>,
# blender_manifest.toml},
# which installs both as a Blender 3.x legacy add-on (bl_info) and as a 4.2+
# extension (manifest in the package's single top-level folder).
# The zip has directory entries (voxlight/): Blender's legacy "overwrite"
# install removes the zip's top-level entries before extracting, so without
# the voxlight/ entry it would write the new files over the old ones.
set -eu
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BUILD=${1:-build}
case $BUILD in /*) ;; *) BUILD=$ROOT/$BUILD ;; esac
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT

# package PLATFORM FILE... - BUILD/voxlight-PLATFORM.zip: the plugin, the
# manifest naming PLATFORM alone and FILE... (that platform's binaries) in
# the package's top folder.
package() {
    platform=$1
    shift
    stage=$TMP/$platform
    mkdir -p "$stage/voxlight/core"
    for f in "$ROOT"/plugin/*.py "$ROOT"/plugin/*.md; do
        [ -f "$f" ] && cp "$f" "$stage/voxlight/"
    done
    # The bpy-free core (plugin/core/, a subpackage).
    for f in "$ROOT"/plugin/core/*.py; do
        [ -f "$f" ] && cp "$f" "$stage/voxlight/core/"
    done
    sed "s/^platforms = .*/platforms = [\"$platform\"]/" "$ROOT/manifest/blender_manifest.toml" \
        >"$stage/voxlight/blender_manifest.toml"
    for f in "$@"; do
        name=$(basename "$f")
        cp "$f" "$stage/voxlight/$name"
        case $name in
            voxlight-read-*|voxlight-vdb-read) chmod 755 "$stage/voxlight/$name" ;;
        esac
    done
    out=$BUILD/voxlight-$platform.zip
    rm -f "$out.tmp"
    # Python's zipfile, not zip(1): always present where Blender's tests run.
    (cd "$stage" && python3 - "$out.tmp" <<'PY'
import os, sys, zipfile
with zipfile.ZipFile(sys.argv[1], "w", zipfile.ZIP_DEFLATED) as z:
    for dirpath, dirs, files in os.walk("voxlight"):
        dirs.sort()
        z.write(dirpath)  # the directory entry ("voxlight/")
        for name in sorted(files):
            z.write(os.path.join(dirpath, name))
PY
    )
    mv "$out.tmp" "$out"
    echo "package_addon: wrote $out"
}

# Linux x64
LIB=$BUILD/libvoxlight.so
if [ ! -f "$LIB" ]; then
    echo "package_addon: $LIB not found; run make first" >&2
    exit 1
fi
set -- "$LIB"
for f in "$BUILD"/voxlight-read-* "$BUILD"/voxlight-vdb-read; do
    # A Linux helper has no extension (the add-on's rule too): never a .exe.
    case ${f##*/} in voxlight-read-*.*) continue ;; esac
    # the DICOM reader on our own parser is a test helper here (Windows
    # ships it as voxlight-read-dicom.exe); Linux ships the dcmtk one
    [ "${f##*/}" = voxlight-read-dicom-own ] && continue
    [ -f "$f" ] && [ -x "$f" ] && set -- "$@" "$f"
done
if [ $# -lt 2 ]; then
    echo "package_addon: no reader helper (voxlight-read-*) in $BUILD; run make first" >&2
    exit 1
fi
# Without it the add-on still works; Convert to Blender Volume then says it is missing.
[ -x "$BUILD/voxlight-write-vdb" ] && set -- "$@" "$BUILD/voxlight-write-vdb"
package linux-x64 "$@"

# Windows x64: only where the Windows build ran (make windows).
WIN=$BUILD/windows-x64
if [ -f "$WIN/voxlight.dll" ]; then
    set -- "$WIN/voxlight.dll"
    for f in "$WIN"/*.dll "$WIN"/voxlight-read-*.exe; do
        [ -f "$f" ] && [ "$f" != "$WIN/voxlight.dll" ] && set -- "$@" "$f"
    done
    package windows-x64 "$@"
else
    # A zip left by an earlier build would no longer match the Linux one.
    rm -f "$BUILD/voxlight-windows-x64.zip"
    echo "package_addon: $WIN/voxlight.dll not found: voxlight-windows-x64.zip not made (make windows builds it)"
fi
