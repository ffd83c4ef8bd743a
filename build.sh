#!/usr/bin/env bash
# build.sh - the only set-up step. On a fresh Debian 12 or 13 machine:
#   ./build.sh demo    install what is missing, build, render the demo to demo.png
#   ./build.sh test    install, build (normal + ASan/UBSan), run every test
#   ./build.sh         install and build only
set -euo pipefail
cd "$(dirname "$0")"
ROOT=$(pwd)

# Debian packages the project needs: compilers, GL headers (we never link GL),
# Mesa's EGL and OSMesa for the offscreen context, OpenImageIO for image files,
# dcmtk for DICOM series, libzstd and libblosc for OME-Zarr chunks (the helper
# voxlight-read-zarr; tests/zarr_write.py also compresses through them),
# the demo brain (mricron-data), Blender and Xvfb for the add-on and its tests,
# numpy and pytest for the Python tests, clang with its sanitizer/libFuzzer
# runtime for the loader fuzz targets (tests/fuzz/) and llvm for llvm-symbolizer
# (sanitizer stacks name csrc/ files: tests/fuzz/run.sh reads them), pyopenvdb
# to write test .vdb files, VTK and matplotlib for the benchmark, and Python
# 3.11's and 3.13's venv for the bpy wheels (./build.sh bpy: 4.5 and 5.0 are
# cp311, 5.1 on cp313; where a release lacks one, a pyenv Python is used).
# Names differ between Debian releases (12 and 13 are supported), so each
# entry is one need: alternatives separated by '|', of which the first
# installed, else the first the apt lists offer, is used. '?' marks a need a
# release may not offer at all: OSMesa left Mesa in 25.1, and without it the
# library (and every test) renders through Mesa's surfaceless EGL; without
# Wine only the Windows tests cannot run (their suite says so). "clang-rt"
# stands for the sanitizer/libFuzzer runtime of clang's major version.
# libz-mingw-w64: zlib1.dll, shipped beside voxlight.dll (Windows has no
# system zlib).
# dcmtk: its command-line tools (dcmcrle) write the compressed DICOM the
# tests read, an encoder independent of our decoders.
# libopenjp2-7-dev: openjpeg.h, whose types the JPEG 2000 decoder's table
# of OpenJPEG's functions takes (libopenjp2.so.7 itself is opened at run
# time, never linked); libopenjp2-tools: opj_compress, which writes the
# JPEG 2000 images tests/test_dicom_j2k.c decodes. python3-pydicom writes
# the enhanced multi-frame DICOM files the tests read, and its own reference
# files (every encoding of one MR image and one RT dose) are read by
# tests/test_dicom_frames.c; dcm2niix is the peer bench/dicom_load.py times.
# libopenvdb-dev: OpenVDB's headers and library for the helper
# voxlight-write-vdb (csrc/io/vdb_write.cpp), which writes the add-on's
# Convert to Blender Volume files (Debian 12: OpenVDB 10, 13: OpenVDB 12;
# the same name on both). openimageio-tools: oiiotool writes the OpenEXR
# World maps tests/cli/test_cli_environment.py reads back.
NEEDS=(gcc g++ make pkg-config zlib1g-dev libgl-dev libegl-dev libegl1 libegl-mesa0
       libgl1-mesa-dri "?libosmesa6" libopenimageio-dev libdcmtk-dev libzstd-dev libblosc-dev mricron-data blender
       xvfb xauth python3 python3-numpy python3-pytest zip unzip clang clang-rt llvm
       python3-matplotlib "python3-vtk9|python3-vtk" python3-openvdb "?python3.11-venv" "?python3.13-venv"
       "?wine64|wine" libz-mingw-w64 dcmtk libopenjp2-7-dev libopenjp2-tools python3-pydicom dcm2niix
       libopenvdb-dev openimageio-tools)

# (output captured, not piped into grep -q: under pipefail an early grep exit
# would fail the pipeline)
pkg_installed() { [[ $(dpkg-query -W -f='${Status}' "$1" 2>/dev/null) == "install ok installed" ]]; }
# offered: the apt lists hold an installable version (virtual names have none)
pkg_offered() { [[ $(apt-cache policy "$1" 2>/dev/null) == *"Candidate: "[!\(]* ]]; }
apt_lists_present() { compgen -G '/var/lib/apt/lists/*_Packages*' >/dev/null; }

# The '|'-separated alternatives of one need (empty: not known yet).
need_alternatives() {
    local need=${1#\?} major
    if [ "$need" != clang-rt ]; then echo "$need"; return 0; fi
    # the installed clang's major version, else the one apt would install
    # (clang depends on clang-N)
    major=$(dpkg-query -W -f='${Depends}' clang 2>/dev/null | grep -oE 'clang-[0-9]+' | sed -n '1s/clang-//p')
    [ -n "$major" ] || major=$(apt-cache depends clang 2>/dev/null | grep -oE 'clang-[0-9]+' | sed -n '1s/clang-//p')
    # LLVM 14 on: libclang-rt-N-dev; before, the runtime was in libclang-common-N-dev
    if [ -n "$major" ]; then echo "libclang-rt-$major-dev|libclang-common-$major-dev"; fi
}

# Resolves every need into CHOSEN (what is used), MISSING (to install),
# ABSENT (optional needs this release does not offer) and UNRESOLVED (needs
# the apt lists, as they are, cannot satisfy). $1=1: the lists are fresh.
resolve_needs() {
    local fresh=$1 need alts a pick
    local -a alt
    CHOSEN=() MISSING=() ABSENT=() UNRESOLVED=()
    for need in "${NEEDS[@]}"; do
        alts=$(need_alternatives "$need")
        IFS='|' read -r -a alt <<<"$alts"
        pick=""
        for a in "${alt[@]}"; do pkg_installed "$a" && { pick=$a; break; }; done
        if [ -n "$pick" ]; then CHOSEN+=("$pick"); continue; fi
        for a in "${alt[@]}"; do pkg_offered "$a" && { pick=$a; break; }; done
        if [ -n "$pick" ]; then
            CHOSEN+=("$pick"); MISSING+=("$pick")
        elif [[ $need == \?* ]] && { [ "$fresh" = 1 ] || apt_lists_present; }; then
            ABSENT+=("${need#\?}")
        else
            UNRESOLVED+=("${alts:-$need}")
        fi
    done
}

install_deps() {
    resolve_needs 0
    if [ ${#MISSING[@]} -gt 0 ] || [ ${#UNRESOLVED[@]} -gt 0 ]; then
        local sudo=""
        [ "$(id -u)" -ne 0 ] && sudo="sudo"
        $sudo apt-get update -qq
        resolve_needs 1
        if [ ${#UNRESOLVED[@]} -gt 0 ]; then
            echo "build.sh: this release offers none of: ${UNRESOLVED[*]}" >&2
            exit 1
        fi
        if [ ${#MISSING[@]} -gt 0 ]; then
            echo "build.sh: installing ${MISSING[*]}"
            DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${MISSING[@]}" >/dev/null
        fi
    fi
    # what was chosen where releases differ
    local c rt="" vtk="" osmesa="none offered by this release: rendering uses EGL surfaceless"
    for c in "${CHOSEN[@]}"; do
        case $c in
            libclang-rt-*|libclang-common-*) rt=$c ;;
            python3-vtk*) vtk=$c ;;
            libosmesa*) osmesa=$c ;;
        esac
    done
    echo "build.sh: Debian packages: clang runtime $rt, VTK $vtk, OSMesa $osmesa"
}

# The library and CLI are compiled for glibc 2.28, the oldest glibc official
# Blender builds run on: Debian's compilers link this system's glibc, whose
# newer symbol versions (pthread_create@GLIBC_2.34 ...) stop the library
# loading there. zig's clang, from the package index, carries glibc 2.28's
# symbol lists; the system's headers come after its own (zlib.h, GL).
ZIG_VERSION=0.17.1
portable_cc() {
    local dir=build/zig py
    if ! "$dir/bin/python" -m ziglang version 2>/dev/null | grep -qx "$ZIG_VERSION"; then
        py=$(find_python 3.11 || find_python 3.13 || find_python "$(python3 -c 'import sys; print("%d.%d" % sys.version_info[:2])')") || return 1
        rm -rf "$dir"
        "$py" -m venv "$dir" >&2 && "$dir/bin/python" -m pip install -q --disable-pip-version-check "ziglang==$ZIG_VERSION" >&2 || return 1
    fi
    echo "$ROOT/$dir/bin/python -m ziglang cc -target x86_64-linux-gnu.2.28 -mcpu=x86_64 -idirafter /usr/include -idirafter /usr/include/$(cc -print-multiarch)"
}

# HTJ2K test frames (DICOM 1.2.840.10008.1.2.4.201-.203): no Debian tool
# encodes the HT block coder, so the tests' writers hand frames to pip's
# imagecodecs (OpenJPH inside) in a venv of its own, apart from the system's
# numpy and pydicom that the writers themselves use (tests/pydicom_util.py).
IMAGECODECS_VERSION=2026.3.6
htj2k_encoder() {
    local dir=build/imagecodecs py
    if ! "$dir/bin/python" -c "import imagecodecs, sys; sys.exit(imagecodecs.__version__ != '$IMAGECODECS_VERSION')" 2>/dev/null; then
        py=$(find_python 3.11 || find_python 3.13 || find_python "$(python3 -c 'import sys; print("%d.%d" % sys.version_info[:2])')") || return 1
        rm -rf "$dir"
        "$py" -m venv "$dir" >&2 && "$dir/bin/python" -m pip install -q --disable-pip-version-check "imagecodecs==$IMAGECODECS_VERSION" >&2 || return 1
    fi
}

build() {
    local lib_cc
    # without it the HTJ2K tests fail, naming the missing encoder
    htj2k_encoder || echo "build.sh: pip's imagecodecs $IMAGECODECS_VERSION (the HTJ2K test encoder) is unavailable" >&2
    if ! lib_cc=$(portable_cc); then
        # still a working build for this machine; tests/cli/test_library_deps.py then fails
        echo "build.sh: zig (pip's ziglang $ZIG_VERSION) is unavailable: the library is built for this glibc only" >&2
        lib_cc=cc
    fi
    make -s -j"$(nproc)" BUILD=build LIB_CC="$lib_cc"
    # Windows x64, cross-compiled by the same zig (its MinGW-w64 runtime):
    # the platform room's Windows files and their tests, run under Wine
    if [ "$lib_cc" != cc ]; then
        make -s -j"$(nproc)" BUILD=build windows WIN_CC="$ROOT/build/zig/bin/python -m ziglang cc -target x86_64-windows-gnu" \
            WIN_DLLTOOL="$ROOT/build/zig/bin/python -m ziglang dlltool"
    fi
    if [ -x tools/package_addon.sh ]; then tools/package_addon.sh build; fi
}

build_asan() {
    make -s -j"$(nproc)" BUILD=build-asan SAN=1
}

# Blender as a Python module (pip's bpy), one virtual environment per tested
# release under build/bpy/<major.minor>/: the current LTS (4.5) and the
# newest 5.x that install on Python 3.11 (5.0: the last cp311 wheels), and
# the newest 5.x on Python 3.13 (5.1 on are cp313 only: the Blender artists
# download today). A venv that already holds a matching bpy is kept (no
# network); BPY_REFRESH=1 looks again for a newer one.
find_python() {  # X.Y -> a Python X.Y with its venv module: the system's, PATH's or pyenv's
    local want=$1 c
    for c in "/usr/bin/python$want" "$(command -v "python$want" || true)" "$HOME"/.pyenv/versions/"$want"*/bin/"python$want"; do
        if [ -n "$c" ] && [ -x "$c" ] &&
            "$c" -c "import sys, venv, ensurepip; sys.exit('%d.%d' % sys.version_info[:2] != '$want')" 2>/dev/null; then
            echo "$c"; return 0
        fi
    done
    return 1
}

bpy_version_in() {  # venv dir -> installed bpy version, or nothing
    [ -x "$1/bin/python" ] || return 0
    "$1/bin/python" -c 'import importlib.metadata as m; print(m.version("bpy"))' 2>/dev/null || true
}

python_version_in() {  # venv dir -> its Python's X.Y, or nothing
    [ -x "$1/bin/python" ] || return 0
    "$1/bin/python" -c 'import sys; print("%d.%d" % sys.version_info[:2])' 2>/dev/null || true
}

bpy_venv_install() {  # python, venv dir, exact bpy version
    local py=$1 dir=$2 version=$3
    rm -rf "$dir"
    "$py" -m venv "$dir" || return 1
    "$dir/bin/python" -m pip install -q --disable-pip-version-check "bpy==$version" numpy pytest \
        || { rm -rf "$dir"; return 1; }
    "$dir/bin/python" -c 'import bpy' || { rm -rf "$dir"; return 1; }
    echo "build.sh: build/bpy/${version%.*}/ has bpy $version"
}

bpy_venv_extras() {  # venv dir: what the Blender test scripts import besides bpy
    "$1/bin/python" -c 'import numpy, pytest' 2>/dev/null ||
        "$1/bin/python" -m pip install -q --disable-pip-version-check numpy pytest
}

bpy_available() {  # python, version regex -> matching versions on the index for this Python, newest first
    "$1" -m pip index versions bpy --disable-pip-version-check 2>/dev/null \
        | sed -n 's/^Available versions: //p' | tr ',' '\n' | tr -d ' ' | grep -E "$2" || true
}

# The newest bpy matching a version regex that installs with one Python, in
# build/bpy/<major.minor>/; older venvs of the same Python and series go.
bpy_newest() {  # python X.Y, python, version regex, name for messages
    local want=$1 py=$2 re=$3 what=$4 dir v old
    if [ -z "${BPY_REFRESH:-}" ]; then
        for dir in build/bpy/*/; do
            dir=${dir%/}
            [ "$(python_version_in "$dir")" = "$want" ] || continue
            if [[ $(bpy_version_in "$dir") =~ $re ]]; then bpy_venv_extras "$dir"; return; fi
        done
    fi
    for v in $(bpy_available "$py" "$re"); do
        dir=build/bpy/${v%.*}
        if [ "$(bpy_version_in "$dir")" != "$v" ] && ! bpy_venv_install "$py" "$dir" "$v"; then
            echo "build.sh: bpy $v did not install here; trying an older one" >&2
            continue
        fi
        bpy_venv_extras "$dir" || return 1
        for old in build/bpy/*/; do
            old=${old%/}
            [ "$old" != "$dir" ] && [ "$(python_version_in "$old")" = "$want" ] &&
                [[ $(bpy_version_in "$old") =~ $re ]] && rm -rf "$old"
        done
        return 0
    done
    echo "build.sh: no bpy $what installs with $py (is the package index reachable?)" >&2
    return 1
}

bpy_venvs() {
    local py311 py313 ok=0
    mkdir -p build/bpy
    if py311=$(find_python 3.11); then
        bpy_newest 3.11 "$py311" '^4\.5\.[0-9]+$' "4.5.x" || ok=1
        bpy_newest 3.11 "$py311" '^5\.[0-9]+\.[0-9]+$' "5.x for Python 3.11" || ok=1
    else
        echo "build.sh: bpy 4.5 and 5.0 need Python 3.11 with its venv module; none found" \
             "(looked for /usr/bin/python3.11, python3.11 on PATH, ~/.pyenv/versions/3.11*)." \
             "Install python3.11 and python3.11-venv, or pyenv install 3.11." >&2
        ok=1
    fi
    if py313=$(find_python 3.13); then
        bpy_newest 3.13 "$py313" '^5\.[0-9]+\.[0-9]+$' "5.x for Python 3.13" || ok=1
    else
        echo "build.sh: bpy 5.1 and later need Python 3.13 with its venv module; none found" \
             "(looked for /usr/bin/python3.13, python3.13 on PATH, ~/.pyenv/versions/3.13*)." \
             "Install python3.13 and python3.13-venv, or pyenv install 3.13." >&2
        ok=1
    fi
    return $ok
}

# Runs each command, echoes its summary, and totals the pass/fail counts.
TOTAL_PASS=0
TOTAL_FAIL=0
run_suite() {
    local name=$1; shift
    echo "=== $name"
    local log started=$SECONDS
    log=$(mktemp)
    set +e
    "$@" 2>&1 | tee "$log"
    local rc=${PIPESTATUS[0]}
    set -e
    local line
    line=$(grep -E '^[0-9]+ passed, [0-9]+ failed' "$log" | tail -n 1 || true)
    if [ -z "$line" ]; then
        # pytest: "== 12 passed, 1 failed in 3.2s ==" or "== 12 passed in ... =="
        local p f
        p=$(grep -oE '[0-9]+ passed' "$log" | tail -n 1 | grep -oE '[0-9]+' || echo 0)
        f=$(grep -oE '[0-9]+ (failed|error)' "$log" | tail -n 1 | grep -oE '[0-9]+' || echo 0)
        line="$p passed, $f failed"
    fi
    local np nf
    np=$(echo "$line" | grep -oE '^[0-9]+')
    nf=$(echo "$line" | sed -E 's/^[0-9]+ passed, ([0-9]+) failed.*/\1/')
    if [ "$rc" -ne 0 ] && [ "$nf" -eq 0 ]; then nf=1; fi # a crash counts as a failure
    TOTAL_PASS=$((TOTAL_PASS + np))
    TOTAL_FAIL=$((TOTAL_FAIL + nf))
    # the suite's wall time, so CI's 30-minute budget can be watched per suite
    echo "=== $name: $((SECONDS - started)) s"
    rm -f "$log"
}

# run_c_tests DIR [LAUNCHER...]: every DIR/tests/test_* program (through
# LAUNCHER, e.g. Wine, when given), counting their summary lines.
run_c_tests() {
    local dir=$1 p=0 f=0 jobs=${VXL_TEST_JOBS:-$(nproc)}
    shift
    local tests=() t
    # test_stress is the longest by far: it starts first, and the other
    # programs share the second lane.
    for t in "$dir"/tests/test_stress* "$dir"/tests/test_*; do
        [ -x "$t" ] || continue
        case " ${tests[*]} " in *" $t "*) continue ;; esac
        tests+=("$t")
    done
    # Up to $jobs programs at once: most of a program's time is one thread
    # (LLVM compiling a shader, a parser, a codec), so a 2-core machine runs
    # two of them in little more than the time of one. Each writes its output
    # to a file of its own; the results are printed in order afterwards.
    # Only the programs' own processes are counted and waited for: the
    # caller may have background jobs of its own (with_xvfb's Xvfb).
    local out_dir i=0 pids=() running pid
    out_dir=$(mktemp -d)
    for t in "${tests[@]}"; do
        while :; do
            running=0
            for pid in "${pids[@]}"; do kill -0 "$pid" 2>/dev/null && running=$((running + 1)); done
            [ "$running" -lt "$jobs" ] && break
            sleep 0.2
        done
        ( local t0=$SECONDS rc=0
          "$@" "$t" >"$out_dir/$i.out" 2>&1 || rc=$?
          echo "$rc $((SECONDS - t0))" >"$out_dir/$i.rc" ) &
        pids+=($!)
        i=$((i + 1))
    done
    for pid in "${pids[@]}"; do wait "$pid" || true; done
    i=0
    for t in "${tests[@]}"; do
        local out rc=1 secs=0 line
        out=$(cat "$out_dir/$i.out" 2>/dev/null || true)
        [ -f "$out_dir/$i.rc" ] && read -r rc secs <"$out_dir/$i.rc"
        i=$((i + 1))
        echo "$out" | grep -E 'FAIL|CHECK failed|REQUIRE failed|ERROR|runtime error|^software backend:' || true
        # || true: under pipefail a crashed test (no summary line) must not
        # end the suite and hide the tests after it
        line=$(echo "$out" | grep -E '^[0-9]+ passed, [0-9]+ failed' | tail -n 1 || true)
        # a crash: show the end of its output (the sanitizer's report and stack)
        [ -n "$line" ] || echo "$out" | tail -n 60
        echo "$(basename "$t"): ${line:-crashed (exit $rc)} ($secs s)"
        if [ -n "$line" ]; then
            p=$((p + $(echo "$line" | grep -oE '^[0-9]+')))
            f=$((f + $(echo "$line" | sed -E 's/^[0-9]+ passed, ([0-9]+) failed.*/\1/')))
        fi
        if [ "$rc" -ne 0 ] && [ -n "$line" ] && [ "$rc" -eq 137 ] && [ "${VXL_SIGKILL_AFTER_SUMMARY_OK:-0}" = 1 ]; then
            echo "  ($(basename "$t") was killed after its summary line: counted as the summary says)"
        elif [ "$rc" -ne 0 ] && { [ -z "$line" ] || echo "$line" | grep -q ' 0 failed'; }; then
            f=$((f + 1))
        fi
    done
    rm -rf "$out_dir"
    echo "$p passed, $f failed"
    [ $f -eq 0 ]
}

# Debian 12's wine64 has /usr/lib/wine/wine64; later Wines run 64-bit
# programs with plain wine.
wine_binary() {
    local c
    for c in /usr/lib/wine/wine64 "$(command -v wine64 || true)" "$(command -v wine || true)"; do
        if [ -n "$c" ] && [ -x "$c" ]; then echo "$c"; return 0; fi
    done
    return 1
}

# Runs "$@" with DISPLAY on an Xvfb of its own, which ends with it (a
# shell function too, which xvfb-run cannot run).
with_xvfb() {
    local fifo pid display rc
    fifo=$(mktemp -u)
    mkfifo "$fifo"
    Xvfb -displayfd 3 -screen 0 640x480x24 -nolisten tcp 3>"$fifo" 2>/dev/null &
    pid=$!
    read -r display <"$fifo"
    rm -f "$fifo"
    DISPLAY=":$display" "$@" && rc=0 || rc=$?
    kill "$pid" 2>/dev/null
    wait "$pid" 2>/dev/null || true
    return $rc
}

# The Windows test programs of build/windows-x64/tests under Wine, in a
# Wine prefix of their own under build/ (made on the first run), on one
# Xvfb: Wine's OpenGL, which the render tests' WGL contexts use, is GLX on
# Mesa's llvmpipe.
run_wine_tests() {
    local dir=$1 wine
    if ! wine=$(wine_binary); then
        echo "build.sh: no Wine to run the Windows tests (apt-get install wine64)"
        echo "0 passed, 1 failed"
        return 1
    fi
    if ! compgen -G "$dir/tests/test_*.exe" >/dev/null; then
        echo "build.sh: no Windows test programs in $dir/tests (zig unavailable?)"
        echo "0 passed, 1 failed"
        return 1
    fi
    # Wine's server ends with SIGKILL a process that is slow to finish
    # exiting: on a loaded machine a test program that has run every test and
    # printed its summary was killed while its threads and DLLs shut down
    # (CI counted it as one failure, in two runs, with every program's
    # summary saying 0 failed), which says nothing of the tests. The summary
    # line is the verdict then; a program killed before printing it still
    # fails, and the kill is printed.
    WINEPREFIX="$ROOT/build/wine" WINEDEBUG=-all VXL_SIGKILL_AFTER_SUMMARY_OK=1 \
        with_xvfb wine_prefix_then_tests "$wine" "$dir"
}

# A new Wine prefix is made by the first program that runs in it; two test
# programs starting at once in a fresh clone raced for it (one lost its
# server: "chdir to ... server-...: No such file or directory"). So the
# prefix is made first, alone, then the programs run side by side.
wine_prefix_then_tests() {
    local wine=$1 dir=$2
    timeout 300 "$wine" wineboot --init >/dev/null 2>&1 || true
    run_c_tests "$dir" timeout 600 "$wine"
}

cmd=${1:-build}
case "$cmd" in
    build)
        install_deps; build ;;
    demo)
        install_deps; build
        if [ -f tools/blender_demo.py ] && [ -f build/voxlight-linux-x64.zip ]; then
            blender -b --factory-startup --python-exit-code 1 --python tools/blender_demo.py -- "$ROOT/demo.png"
        else
            ./build/voxlight render /usr/share/mricron/templates/ch2better.nii.gz -o demo.png --size 512x512 --azimuth 30 --elevation 15
        fi
        echo "build.sh: wrote $ROOT/demo.png" ;;
    test)
        install_deps; build; build_asan
        # Without them the Blender suite reports the missing versions as failures.
        bpy_venvs || echo "build.sh: the bpy venvs are incomplete" >&2
        # dependencies go one way: no include cycle between csrc/
        # files or folders, each folder above the ones it uses
        run_suite "Include cycles and layers (csrc/)" /usr/bin/python3 tools/check_includes.py
        run_suite "C tests" run_c_tests build
        run_suite "Windows x64 tests under Wine" run_wine_tests build/windows-x64
        # Mesa and LLVM keep allocations until exit: their leaks are suppressed
        # by library name (tests/lsan.supp); ours are not. Freed memory is
        # filled with 0xbe, so a read of freed memory inside a library ASan
        # does not instrument (Mesa) follows garbage and crashes at once,
        # every run, instead of by chance (tests/upstream/README.md).
        ASAN_OPTIONS=detect_leaks=1:max_free_fill_size=1048576:free_fill_byte=190 LSAN_OPTIONS=suppressions="$ROOT/tests/lsan.supp" UBSAN_OPTIONS=print_stacktrace=1 \
            run_suite "C tests under ASan+UBSan" run_c_tests build-asan
        # every file loader under libFuzzer + ASan/UBSan: tests/crashers/
        # replayed (failing when a loader's corpus is missing or empty), our
        # own parsers fuzzed with a fixed seed for a fixed number of inputs,
        # the third-party readers' seeds replayed: the outcome depends on the
        # commit only. ./build.sh fuzz searches open-endedly.
        run_suite "Loader fuzzing (ASan+UBSan)" tests/fuzz/run.sh ci
        run_suite "CLI tests" /usr/bin/python3 -m pytest -q -p no:cacheprovider tests/cli
        run_suite "Benchmark smoke" /usr/bin/python3 -m pytest -q -p no:cacheprovider tests/bench
        if [ -x tools/run_blender_tests.sh ]; then
            run_suite "Blender and binding tests" tools/run_blender_tests.sh build
        fi
        echo "=== all suites"
        echo "$TOTAL_PASS passed, $TOTAL_FAIL failed"
        [ "$TOTAL_FAIL" -eq 0 ] ;;
    fuzz)
        # ./build.sh fuzz [SECONDS [TARGET...]]: each loader's libFuzzer target
        # (nifti nrrd metaimage tiff png dicom dicom_own vdb label_table zarr brick_cache tiff_layout dicom_codecs hdr ome_xml) for SECONDS (default 300);
        # crashes are kept in tests/crashers/<target>/. SECONDS "replay":
        # replay tests/crashers/ only
        install_deps; build
        shift
        tests/fuzz/run.sh "${1:-300}" "${@:2}" ;;
    stress)
        # the larger stability sweep; the default matrix runs in ./build.sh test
        install_deps; build
        ./build/tests/test_stress --full ;;
    bench)
        # ./build.sh bench [--quick]: run time against error. --quick is the
        # smoke run (64^2, one backend) and writes its plot under bench/out;
        # the full run (512^2, every backend that opens) writes docs/.
        install_deps; build
        mode=${2:---full}
        mkdir -p bench/out
        ./build/voxlight-bench "$mode" --out bench/results.csv --scene-dir bench/out
        ./build/voxlight-skipbench $([ "$mode" = --quick ] && echo --quick) --out bench/skipping.csv
        ./build/voxlight-slicingbench $([ "$mode" = --quick ] && echo --quick) \
            --out "$([ "$mode" = --quick ] && echo bench/out/slicing.csv || echo bench/slicing.csv)"
        ./build/voxlight-storagebench $([ "$mode" = --quick ] && echo --quick) \
            --out "$([ "$mode" = --quick ] && echo bench/out/storage.csv || echo bench/storage.csv)"
        # shadows, occlusion and scattering (docs/lighting.md pastes bench/out/lighting_tables.md).
        light_csv=$([ "$mode" = --quick ] && echo bench/out/lighting.csv || echo bench/lighting.csv)
        ./build/voxlight-lightbench $([ "$mode" = --quick ] && echo --quick) --out "$light_csv"
        # scene shadows on against off (docs/scene_shadows.md).
        ./build/voxlight-sceneshadowbench $([ "$mode" = --quick ] && echo --quick || echo --frames 9) \
            --out "$([ "$mode" = --quick ] && echo bench/out/scene_shadows.csv || echo bench/scene_shadows.csv)"
        /usr/bin/python3 bench/plot_lighting.py "$light_csv" \
            --png "$([ "$mode" = --quick ] && echo bench/out/lighting.png || echo docs/lighting.png)" \
            --md bench/out/lighting_tables.md --command "./build.sh bench $mode"
        steps=$([ "$mode" = --quick ] && echo 0.5 || echo 1,0.5,0.25)
        xvfb-run -a -s "-screen 0 1024x768x24" /usr/bin/python3 bench/vtk_peer.py bench/out/scene_ch2better.json \
            --out bench/results.csv --steps "$steps"
        # Per covered pixel against VTK: two transfer functions on two volumes.
        cmp_csv=$([ "$mode" = --quick ] && echo bench/out/vtk_compare.csv || echo bench/vtk_compare.csv)
        xvfb-run -a -s "-screen 0 1024x768x24" /usr/bin/python3 bench/vtk_compare.py \
            --size "$([ "$mode" = --quick ] && echo 64 || echo 512)" --frames "$([ "$mode" = --quick ] && echo 3 || echo 5)" \
            --out "$cmp_csv" --md bench/out/vtk_compare.md --command "./build.sh bench $mode"
        if [ "$mode" = --quick ]; then dest=bench/out/benchmark; else dest=docs/benchmark; fi
        # the render modes' run time against error (docs/modes.md).
        ./build/voxlight-modesbench $([ "$mode" = --quick ] && echo --quick) \
            --out "$([ "$mode" = --quick ] && echo bench/out/modes.csv || echo bench/modes.csv)" --md bench/out/modes.md
        /usr/bin/python3 bench/plot.py bench/results.csv --png "$dest.png" --md "$dest.md" --command "./build.sh bench $mode"
        { echo; cat bench/out/vtk_compare.md; } >> "$dest.md"
        { echo; echo "## Render modes: run time against error"; echo;
          echo "\`build/voxlight-modesbench\` (bench/modes_study.c, docs/modes.md), from \`./build.sh bench $mode\`:";
          echo; cat bench/out/modes.md; } >> "$dest.md" ;;
    bpy)
        bpy_venvs ;;
    clean)
        make clean ;;
    *)
        echo "usage: ./build.sh [build|demo|test|bpy|fuzz [SECONDS [TARGET...]]|stress|bench [--quick]|clean]" >&2; exit 2 ;;
esac
