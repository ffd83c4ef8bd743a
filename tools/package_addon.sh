#!/bin/sh
# package_addon.sh [BUILD_DIR] - makes BUILD_DIR/voxlight-linux-x64.zip, the
# extension for one platform, from plugin/, manifest/blender_manifest.toml
# (its `platforms` set to that platform alone), BUILD_DIR/libvoxlight.so and
# every reader helper the library starts from its own folder (BUILD_DIR/
# voxlight-read-*, and voxlight-vdb-read where a build still has it): only
# that platform's binaries, as Blender's extension platform is one per
# package.
# Blender's zip install drops the helpers' execute bit, which the add-on
# restores when it loads the library (plugin/core/native.py).
# Layout: voxlight/{__init__.py, ..., core/*.py, libvoxlight.so,
# voxlight-read-*, blender_manifest.toml},
# which installs both as a Blender 3.x legacy add-on (bl_info) and as a 4.2+
# extension (manifest in the package's single top-level folder).
# The zip has directory entries (voxlight/): Blender's legacy "overwrite"
# install removes the zip's top-level entries before extracting, so without
# the voxlight/ entry it would write the new files over the old ones.
set -eu
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BUILD=${1:-build}
case $BUILD in /*) ;; *) BUILD=$ROOT/$BUILD ;; esac
LIB=$BUILD/libvoxlight.so
if [ ! -f "$LIB" ]; then
    echo "package_addon: $LIB not found; run make first" >&2
    exit 1
fi
HELPERS=""
for f in "$BUILD"/voxlight-read-* "$BUILD"/voxlight-vdb-read; do
    [ -f "$f" ] && [ -x "$f" ] && HELPERS="$HELPERS $f"
done
if [ -z "$HELPERS" ]; then
    echo "package_addon: no reader helper (voxlight-read-*) in $BUILD; run make first" >&2
    exit 1
fi
STAGE=$(mktemp -d)
trap 'rm -rf "$STAGE"' EXIT
mkdir "$STAGE/voxlight" "$STAGE/voxlight/core"
for f in "$ROOT"/plugin/*.py "$ROOT"/plugin/*.md; do
    [ -f "$f" ] && cp "$f" "$STAGE/voxlight/"
done
# The bpy-free core (plugin/core/, a subpackage).
for f in "$ROOT"/plugin/core/*.py; do
    [ -f "$f" ] && cp "$f" "$STAGE/voxlight/core/"
done
PLATFORM=linux-x64
sed "s/^platforms = .*/platforms = [\"$PLATFORM\"]/" "$ROOT/manifest/blender_manifest.toml" >"$STAGE/voxlight/blender_manifest.toml"
cp "$LIB" "$STAGE/voxlight/libvoxlight.so"
for f in $HELPERS; do
    cp "$f" "$STAGE/voxlight/"
    chmod 755 "$STAGE/voxlight/$(basename "$f")"
done
OUT=$BUILD/voxlight-$PLATFORM.zip
rm -f "$OUT.tmp"
# Python's zipfile, not zip(1): always present where Blender's tests run.
(cd "$STAGE" && python3 - "$OUT.tmp" <<'PY'
import os, sys, zipfile
with zipfile.ZipFile(sys.argv[1], "w", zipfile.ZIP_DEFLATED) as z:
    for dirpath, dirs, files in os.walk("voxlight"):
        dirs.sort()
        z.write(dirpath)  # the directory entry ("voxlight/")
        for name in sorted(files):
            z.write(os.path.join(dirpath, name))
PY
)
mv "$OUT.tmp" "$OUT"
echo "package_addon: wrote $OUT"
