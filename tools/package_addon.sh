#!/bin/sh
# package_addon.sh [BUILD_DIR] - makes BUILD_DIR/voxlight-blender.zip from
# plugin/, manifest/blender_manifest.toml, BUILD_DIR/libvoxlight.so and
# BUILD_DIR/voxlight-vdb-read (the process that reads .vdb files for the
# library, csrc/vdb_spawn.c; Blender's zip install drops its execute bit,
# which the add-on restores when it registers: plugin/native.py).
# Layout: voxlight/{__init__.py, ..., libvoxlight.so, voxlight-vdb-read,
# blender_manifest.toml},
# which installs both as a Blender 3.x legacy add-on (bl_info) and as a 4.2+
# extension (manifest in the package's single top-level folder).
set -eu
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BUILD=${1:-build}
case $BUILD in /*) ;; *) BUILD=$ROOT/$BUILD ;; esac
LIB=$BUILD/libvoxlight.so
HELPER=$BUILD/voxlight-vdb-read
for f in "$LIB" "$HELPER"; do
    if [ ! -f "$f" ]; then
        echo "package_addon: $f not found; run make first" >&2
        exit 1
    fi
done
STAGE=$(mktemp -d)
trap 'rm -rf "$STAGE"' EXIT
mkdir "$STAGE/voxlight"
for f in "$ROOT"/plugin/*.py "$ROOT"/plugin/*.md; do
    [ -f "$f" ] && cp "$f" "$STAGE/voxlight/"
done
cp "$ROOT/manifest/blender_manifest.toml" "$STAGE/voxlight/"
cp "$LIB" "$STAGE/voxlight/libvoxlight.so"
cp "$HELPER" "$STAGE/voxlight/voxlight-vdb-read"
chmod 755 "$STAGE/voxlight/voxlight-vdb-read"
OUT=$BUILD/voxlight-blender.zip
rm -f "$OUT.tmp"
# Python's zipfile, not zip(1): always present where Blender's tests run.
(cd "$STAGE" && python3 - "$OUT.tmp" <<'PY'
import os, sys, zipfile
with zipfile.ZipFile(sys.argv[1], "w", zipfile.ZIP_DEFLATED) as z:
    for dirpath, _dirs, files in os.walk("voxlight"):
        for name in sorted(files):
            z.write(os.path.join(dirpath, name))
PY
)
mv "$OUT.tmp" "$OUT"
echo "package_addon: wrote $OUT"
