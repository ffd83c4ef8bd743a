#!/usr/bin/env bash
# build.sh - the only set-up step. On a fresh Debian 12 machine:
#   ./build.sh demo    install what is missing, build, render the demo to demo.png
#   ./build.sh test    install, build (normal + ASan/UBSan), run every test
#   ./build.sh         install and build only
set -euo pipefail
cd "$(dirname "$0")"
ROOT=$(pwd)

# Debian packages the project needs: compilers, GL headers (we never link GL),
# OSMesa and Mesa's EGL for the offscreen context, OpenImageIO for image files,
# dcmtk for DICOM series,
# the demo brain (mricron-data), Blender and Xvfb for the add-on and its tests,
# numpy and pytest for the Python tests, clang with its sanitizer/libFuzzer
# runtime for the loader fuzz targets (tests/fuzz/), pyopenvdb to write test .vdb files.
PACKAGES=(gcc g++ make pkg-config zlib1g-dev libgl-dev libegl-dev libegl1 libegl-mesa0
          libgl1-mesa-dri libosmesa6 libosmesa6-dev libopenimageio-dev mricron-data blender
          xvfb xauth python3 python3-numpy python3-pytest zip unzip
          clang libclang-rt-14-dev python3-matplotlib python3-vtk9 python3-openvdb libdcmtk-dev)

install_deps() {
    local missing=()
    for p in "${PACKAGES[@]}"; do
        dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
    done
    [ ${#missing[@]} -eq 0 ] && return 0
    echo "build.sh: installing ${missing[*]}"
    local sudo=""
    [ "$(id -u)" -ne 0 ] && sudo="sudo"
    $sudo apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
}

build() {
    make -s -j"$(nproc)" BUILD=build
    if [ -x tools/package_addon.sh ]; then tools/package_addon.sh build; fi
}

build_asan() {
    make -s -j"$(nproc)" BUILD=build-asan SAN=1
}

# Runs each command, echoes its summary, and totals the pass/fail counts.
TOTAL_PASS=0
TOTAL_FAIL=0
run_suite() {
    local name=$1; shift
    echo "=== $name"
    local log
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
    rm -f "$log"
}

run_c_tests() {
    local dir=$1 fails=0 p=0 f=0
    for t in "$dir"/tests/test_*; do
        [ -x "$t" ] || continue
        local out
        set +e
        out=$("$t" 2>&1)
        local rc=$?
        set -e
        echo "$out" | grep -E 'FAIL|CHECK failed|REQUIRE failed|ERROR|runtime error' || true
        local line
        line=$(echo "$out" | grep -E '^[0-9]+ passed, [0-9]+ failed' | tail -n 1)
        echo "$(basename "$t"): ${line:-crashed (exit $rc)}"
        if [ -n "$line" ]; then
            p=$((p + $(echo "$line" | grep -oE '^[0-9]+')))
            f=$((f + $(echo "$line" | sed -E 's/^[0-9]+ passed, ([0-9]+) failed.*/\1/')))
        fi
        if [ $rc -ne 0 ] && { [ -z "$line" ] || echo "$line" | grep -q ' 0 failed'; }; then f=$((f + 1)); fi
    done
    echo "$p passed, $f failed"
    [ $f -eq 0 ]
}

cmd=${1:-build}
case "$cmd" in
    build)
        install_deps; build ;;
    demo)
        install_deps; build
        if [ -f tools/blender_demo.py ] && [ -f build/voxlight-blender.zip ]; then
            blender -b --factory-startup --python-exit-code 1 --python tools/blender_demo.py -- "$ROOT/demo.png"
        else
            ./build/voxlight render /usr/share/mricron/templates/ch2better.nii.gz -o demo.png --size 512x512 --azimuth 30 --elevation 15
        fi
        echo "build.sh: wrote $ROOT/demo.png" ;;
    test)
        install_deps; build; build_asan
        run_suite "C tests" run_c_tests build
        # Mesa and LLVM keep allocations until exit: their leaks are suppressed
        # by library name (tests/lsan.supp); ours are not.
        ASAN_OPTIONS=detect_leaks=1 LSAN_OPTIONS=suppressions="$ROOT/tests/lsan.supp" UBSAN_OPTIONS=print_stacktrace=1 \
            run_suite "C tests under ASan+UBSan" run_c_tests build-asan
        # every file loader under libFuzzer + ASan/UBSan, 20 s each, after
        # replaying tests/crashers/ (./build.sh fuzz runs them longer)
        run_suite "Loader fuzzing (ASan+UBSan)" tests/fuzz/run.sh 20
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
        # (nifti nrrd metaimage tiff png dicom) for SECONDS (default 300); crashes
        # are kept in tests/crashers/<target>/
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
        ./build/voxlight-storagebench $([ "$mode" = --quick ] && echo --quick) \
            --out "$([ "$mode" = --quick ] && echo bench/out/storage.csv || echo bench/storage.csv)"
        steps=$([ "$mode" = --quick ] && echo 0.5 || echo 1,0.5,0.25)
        xvfb-run -a -s "-screen 0 1024x768x24" /usr/bin/python3 bench/vtk_peer.py bench/out/scene_ch2better.json \
            --out bench/results.csv --steps "$steps"
        if [ "$mode" = --quick ]; then dest=bench/out/benchmark; else dest=docs/benchmark; fi
        /usr/bin/python3 bench/plot.py bench/results.csv --png "$dest.png" --md "$dest.md" --command "./build.sh bench $mode" ;;
    clean)
        make clean ;;
    *)
        echo "usage: ./build.sh [build|demo|test|fuzz [SECONDS [TARGET...]]|stress|bench [--quick]|clean]" >&2; exit 2 ;;
esac
