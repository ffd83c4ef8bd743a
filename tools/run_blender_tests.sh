#!/bin/bash
# run_blender_tests.sh [BUILD_DIR] - runs the Blender add-on's tests:
#   * plain pytest of the ctypes binding and the bpy-free maths (tests/python);
#   * headless Blender scripts (tests/blender/test_*.py except test_gui*);
#   * the GUI viewport test under xvfb-run (tests/blender/test_gui.py).
# Prints one final line `N passed, M failed`; exits non-zero on any failure.
set -u
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BUILD=${1:-build}
case $BUILD in /*) ;; *) BUILD=$ROOT/$BUILD ;; esac
export BUILD
BLENDER=${BLENDER:-blender}
PYTHON=${PYTHON:-/usr/bin/python3}

passed=0
failed=0
note_fail() { failed=$((failed + 1)); echo "run_blender_tests: FAIL: $*" >&2; }

# The zip under test is always the current plugin/ + library.
if ! "$ROOT/tools/package_addon.sh" "$BUILD"; then
    note_fail "packaging"
    echo "$passed passed, $failed failed"
    exit 1
fi

# Blender installs add-ons into the user scripts folder: keep it private so
# the tests neither see nor change the user's own Blender set-up.
SANDBOX=$(mktemp -d)
trap 'rm -rf "$SANDBOX"' EXIT
export BLENDER_USER_SCRIPTS=$SANDBOX/scripts BLENDER_USER_CONFIG=$SANDBOX/config
unset VOXLIGHT_LIB  # Blender must use the library shipped in the zip

# --- plain pytest
log=$SANDBOX/pytest.log
(cd "$ROOT" && VOXLIGHT_LIB=$BUILD/libvoxlight.so "$PYTHON" -m pytest -q -p no:cacheprovider \
    tests/python) >"$log" 2>&1
cat "$log"
p=$(grep -Eo '[0-9]+ passed' "$log" | tail -1 | grep -Eo '[0-9]+')
f=$(grep -Eo '[0-9]+ (failed|errors?)' "$log" | awk '{s += $1} END {print s + 0}')
passed=$((passed + ${p:-0}))
failed=$((failed + ${f:-0}))
if [ "${p:-0}" -eq 0 ] && [ "${f:-0}" -eq 0 ]; then
    note_fail "pytest ran no tests"
fi

# --- Blender scripts: each prints `RESULT name: N passed, M failed`
run_script() {  # label, command...
    local label=$1
    shift
    local out=$SANDBOX/$label.log
    (cd "$SANDBOX" && timeout 600 "$@") >"$out" 2>&1
    local rc=$?
    grep -E '^(PASS|FAIL|RESULT)|Error|Traceback' "$out"
    local line
    line=$(grep -E "^RESULT $label: " "$out" | tail -1)
    if [ -z "$line" ]; then
        tail -40 "$out"
        note_fail "$label exited with $rc and no RESULT line"
        return
    fi
    local p f
    p=$(echo "$line" | sed -E 's/.*: ([0-9]+) passed.*/\1/')
    f=$(echo "$line" | sed -E 's/.* ([0-9]+) failed.*/\1/')
    passed=$((passed + p))
    failed=$((failed + f))
    if [ "$rc" -ne 0 ] && [ "$f" -eq 0 ]; then
        note_fail "$label exited with $rc"
    fi
}

for script in "$ROOT"/tests/blender/test_*.py; do
    label=$(basename "$script" .py)
    case $label in
        test_gui*)
            if ! command -v xvfb-run >/dev/null; then
                note_fail "$label needs xvfb-run"
                continue
            fi
            run_script "$label" xvfb-run -a -s "-screen 0 1280x1024x24" \
                "$BLENDER" --factory-startup --enable-event-simulate --python-exit-code 1 --python "$script"
            ;;
        *)
            run_script "$label" "$BLENDER" -b --factory-startup --python-exit-code 1 \
                --python "$script"
            ;;
    esac
done

echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
