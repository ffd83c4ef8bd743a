#!/bin/bash
# run_blender_tests.sh [BUILD_DIR] - runs the Blender add-on's tests:
#   * plain pytest of the ctypes binding and the bpy-free maths (tests/python);
#   * in Debian's Blender ($BLENDER, default `blender`): the headless scripts
#     (tests/blender/test_*.py except test_gui*) with -b, and the GUI viewport
#     test under xvfb-run (tests/blender/test_gui*.py);
#   * in every Blender Python module venv (build/bpy/<major.minor>/, made by
#     ./build.sh bpy: 4.5, 5.0 and the newest 5.x on Python 3.13;
#     BPY_VENVS="dir ..." picks others): the same headless scripts, run by the
#     venv's python (the releases between the oldest and the newest leave
#     out the tests marked test_oldest_and_newest);
#   * the extension manifest validated by each Blender that has the
#     extension tools (4.2+).
# Every Blender starts from factory settings with private user scripts,
# config, extensions and cache folders. Prints one line per Blender,
# `blender X.Y.Z: N passed, M failed`, then the overall `N passed, M failed`;
# exits non-zero on any failure.
set -u
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BUILD=${1:-build}
case $BUILD in /*) ;; *) BUILD=$ROOT/$BUILD ;; esac
export BUILD
BLENDER=${BLENDER:-blender}
unset VOXLIGHT_BLENDER_COVERAGE  # every test, unless set below per release
PYTHON=${PYTHON:-/usr/bin/python3}
MISSING_BPY=""
if [ -z "${BPY_VENVS+set}" ]; then
    BPY_VENVS=$(ls -d "$ROOT"/build/bpy/*/ 2>/dev/null | sed 's:/$::')
    # The releases every run must cover: the LTS, the last 5.x on Python
    # 3.11 (5.0) and the newest 5.x, which is on Python 3.13.
    [ -d "$ROOT/build/bpy/4.5" ] || MISSING_BPY="$MISSING_BPY 4.5"
    [ -d "$ROOT/build/bpy/5.0" ] || MISSING_BPY="$MISSING_BPY 5.0"
    ls "$ROOT"/build/bpy/5.*/bin/python3.13 >/dev/null 2>&1 || MISSING_BPY="$MISSING_BPY 5.x-on-Python-3.13"
fi

passed=0 failed=0          # overall
b_passed=0 b_failed=0      # the Blender being run
summaries=()
note_fail() { b_failed=$((b_failed + 1)); echo "run_blender_tests: FAIL: $*" >&2; }

# The zip under test is always the current plugin/ + library.
if ! "$ROOT/tools/package_addon.sh" "$BUILD"; then
    echo "run_blender_tests: FAIL: packaging" >&2
    echo "0 passed, 1 failed"
    exit 1
fi
ZIP=$BUILD/voxlight-linux-x64.zip

# Blender installs add-ons into the user scripts (legacy) or extensions
# (4.2+) folder: keep them private so the tests neither see nor change the
# user's own Blender set-up. The add-on's private library copies go to the
# sandbox's cache too.
SANDBOX=$(mktemp -d)
trap 'rm -rf "$SANDBOX"' EXIT
unset VOXLIGHT_LIB  # Blender must use the library shipped in the zip

sandbox_env() {  # tag: a fresh set of user folders for one Blender
    local d=$SANDBOX/$1
    mkdir -p "$d"
    export BLENDER_USER_SCRIPTS=$d/scripts BLENDER_USER_CONFIG=$d/config
    export BLENDER_USER_EXTENSIONS=$d/extensions XDG_CACHE_HOME=$d/cache
}

b_enable=""  # the first script's add-on enable time (cold: no bytecode cache yet)
finish_blender() {  # name: print its summary, add to the totals
    [ -n "$b_enable" ] && echo "$1: add-on enable took $b_enable (first enable after install)"
    b_enable=""
    local line="$1: $b_passed passed, $b_failed failed"
    echo "$line"
    summaries+=("$line")
    passed=$((passed + b_passed))
    failed=$((failed + b_failed))
    b_passed=0 b_failed=0
}

# --- plain pytest
sandbox_env pytest
log=$SANDBOX/pytest.log
(cd "$ROOT" && VOXLIGHT_LIB=$BUILD/libvoxlight.so "$PYTHON" -m pytest -q -p no:cacheprovider \
    tests/python) >"$log" 2>&1
cat "$log"
p=$(grep -Eo '[0-9]+ passed' "$log" | tail -1 | grep -Eo '[0-9]+')
f=$(grep -Eo '[0-9]+ (failed|errors?)' "$log" | awk '{s += $1} END {print s + 0}')
b_passed=${p:-0}
b_failed=${f:-0}
if [ "${p:-0}" -eq 0 ] && [ "${f:-0}" -eq 0 ]; then
    note_fail "pytest ran no tests"
fi
finish_blender "python tests (no Blender)"

# --- Blender scripts: each prints `RESULT name: N passed, M failed`
# Up to LANES scripts run at once, each in user folders of its own (its
# own add-on install and caches, so two never write the same folder): most
# of a script's time is Blender starting and Python on one thread, so a
# 2-core machine runs two in little more than the time of one. Their
# results are read in the order they were started, once all have ended
# (finish_scripts).
LANES=${VOXLIGHT_BLENDER_LANES:-$(nproc)}
started_scripts=()
script_pids=()
start_script() {  # tag, label, command...
    local tag=$1 label=$2
    shift 2
    local out=$SANDBOX/$tag-$label.log
    local running p
    while :; do
        running=0
        for p in "${script_pids[@]}"; do kill -0 "$p" 2>/dev/null && running=$((running + 1)); done
        [ "$running" -lt "$LANES" ] && break
        sleep 0.2
    done
    (
        sandbox_env "$tag/$label"
        local t0=$SECONDS rc=0
        (cd "$SANDBOX" && timeout 600 "$@") >"$out" 2>&1 || rc=$?
        echo "$rc $((SECONDS - t0))" >"$out.rc"
    ) &
    script_pids+=($!)
    started_scripts+=("$tag $label")
}

finish_scripts() {  # wait for the started scripts and count their results
    local pid
    for pid in "${script_pids[@]}"; do wait "$pid" || true; done
    script_pids=()
    local entry tag label out rc secs line p f
    for entry in "${started_scripts[@]}"; do
        tag=${entry%% *}
        label=${entry#* }
        out=$SANDBOX/$tag-$label.log
        rc=1 secs=0
        [ -f "$out.rc" ] && read -r rc secs <"$out.rc"
        echo "TIME $tag $label: $secs s"  # CI's 30-minute budget, per script
        grep -E '^(PASS|FAIL|RESULT)|^install_addon:|^enable:|Error|Traceback' "$out"
        [ -n "$b_enable" ] || b_enable=$(sed -n 's/^enable: //p' "$out" | head -n 1)
        line=$(grep -E "^RESULT $label: " "$out" | tail -1)
        if [ -z "$line" ]; then
            tail -40 "$out"
            note_fail "$tag $label exited with $rc and no RESULT line"
            continue
        fi
        p=$(echo "$line" | sed -E 's/.*: ([0-9]+) passed.*/\1/')
        f=$(echo "$line" | sed -E 's/.* ([0-9]+) failed.*/\1/')
        b_passed=$((b_passed + p))
        b_failed=$((b_failed + f))
        if [ "$rc" -ne 0 ] && [ "$f" -eq 0 ]; then
            note_fail "$tag $label exited with $rc"
        fi
    done
    started_scripts=()
}

# One script alone, its result counted at once.
run_script() {  # tag, label, command...
    start_script "$@"
    finish_scripts
}

at_least_4_2() { [ "$(printf '%s\n4.2\n' "$1" | sort -V | head -n 1)" = 4.2 ]; }

validate_manifest() {  # tag, command... : the extension validator, one test
    local tag=$1
    shift
    local out=$SANDBOX/$tag-validate.log
    if (cd "$SANDBOX" && timeout 300 "$@") >"$out" 2>&1 && ! grep -q "FATAL_ERROR" "$out"; then
        echo "PASS manifest validates"
        b_passed=$((b_passed + 1))
    else
        cat "$out"
        note_fail "$tag: the extension manifest does not validate"
    fi
}

# Debian's Blender: headless and GUI, as a user runs it.
if command -v "$BLENDER" >/dev/null; then
    version=$("$BLENDER" --version 2>/dev/null | sed -n 's/^Blender \([0-9][0-9.]*\).*/\1/p' | head -n 1)
    tag=blender-${version:-unknown}
    echo "=== blender ${version:-?} ($BLENDER)"
    sandbox_env "$tag"
    # headless scripts side by side; then the GUI scripts one at a time
    # (each on an Xvfb xvfb-run -a picks: two starting together could pick
    # the same display), as their frame timings are what they test
    for script in "$ROOT"/tests/blender/test_*.py; do
        label=$(basename "$script" .py)
        case $label in test_gui*) continue ;; esac
        start_script "$tag" "$label" "$BLENDER" -b --factory-startup --python-exit-code 1 \
            --python "$script"
    done
    finish_scripts
    for script in "$ROOT"/tests/blender/test_gui*.py; do
        label=$(basename "$script" .py)
        if ! command -v xvfb-run >/dev/null; then
            note_fail "$label needs xvfb-run"
            continue
        fi
        run_script "$tag" "$label" xvfb-run -a -s "-screen 0 1280x1024x24" \
            "$BLENDER" --factory-startup --enable-event-simulate --python-exit-code 1 --python "$script"
    done
    if at_least_4_2 "${version:-0}"; then
        validate_manifest "$tag" "$BLENDER" --command extension validate "$ZIP"  # implies -b
    fi
    finish_blender "blender ${version:-?}"
else
    b_failed=1
    finish_blender "blender ($BLENDER not found)"
fi

# Blender as a Python module: the headless scripts, one venv per release.
for v in $MISSING_BPY; do
    echo "run_blender_tests: FAIL: no bpy $v venv under build/bpy/ (run ./build.sh bpy)" >&2
    b_failed=1
    finish_blender "blender $v (bpy module missing)"
done
# The newest module runs every test; the releases between it and Debian's
# Blender (the oldest) leave out the few marked test_oldest_and_newest
# (tests/blender/_util.py says which and why), to keep CI's time.
NEWEST_BPY=$(for v in $BPY_VENVS; do echo "$v"; done | sort -V | tail -n 1)
for venv in $BPY_VENVS; do
    py=$venv/bin/python
    if [ "$venv" = "$NEWEST_BPY" ]; then unset VOXLIGHT_BLENDER_COVERAGE; else export VOXLIGHT_BLENDER_COVERAGE=api; fi
    version=$("$py" -c 'import bpy; print(bpy.app.version_string.split()[0])' 2>/dev/null)
    tag=bpy-${version:-$(basename "$venv")}
    echo "=== blender ${version:-?} (bpy module in $venv)${VOXLIGHT_BLENDER_COVERAGE:+, coverage: $VOXLIGHT_BLENDER_COVERAGE}"
    sandbox_env "$tag"
    if [ -z "$version" ]; then
        note_fail "$py cannot import bpy"
        finish_blender "blender $(basename "$venv") (bpy)"
        continue
    fi
    for script in "$ROOT"/tests/blender/test_*.py; do
        label=$(basename "$script" .py)
        case $label in test_gui*) continue ;; esac  # no window in a module
        start_script "$tag" "$label" "$py" "$script"
    done
    finish_scripts
    # Blender 5.2 on: a background script that draws calls gpu.init() first;
    # F12 and its composite must work after it too.
    if "$py" -c 'import sys, bpy, gpu; sys.exit(not hasattr(gpu, "init"))' 2>/dev/null; then
        for label in test_render; do
            run_script "$tag-gpu-init" "$label" env VOXLIGHT_TEST_GPU_INIT=1 "$py" "$ROOT/tests/blender/$label.py"
        done
    fi
    if at_least_4_2 "$version"; then
        # The module has no --command; its extension tool is the same script.
        ext=$("$py" -c 'import bpy, os; print(os.path.join(bpy.utils.system_resource("SCRIPTS"), "addons_core", "bl_pkg", "cli", "blender_ext.py"))' 2>/dev/null)
        if [ -f "$ext" ]; then
            validate_manifest "$tag" "$py" "$ext" validate "$ZIP"
        else
            note_fail "$tag: blender_ext.py not found to validate the manifest"
        fi
    fi
    finish_blender "blender $version (bpy)"
done

unset VOXLIGHT_BLENDER_COVERAGE
echo "=== Blender summary"
for s in "${summaries[@]}"; do echo "$s"; done
echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
