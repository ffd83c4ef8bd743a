#!/usr/bin/env bash
# tests/fuzz/run.sh SECONDS [TARGET...] - builds the libFuzzer targets
# (make fuzz: clang, ASan+UBSan), writes the seed corpus, replays
# tests/crashers/<target>/ and then fuzzes each target for SECONDS.
# tests/fuzz/run.sh replay [TARGET...] - the replay alone (no seeds, no
# fuzzing): what to run after fixing a crash.
# New crashes land in tests/crashers/<target>/ (a corpus that only grows;
# test_loaders replays it too). A target whose corpus folder is missing or
# holds no input fails before anything is built: a replay of nothing would
# pass whatever the loaders do. VOXLIGHT_CRASHERS names another corpus root
# (one folder per target; relative to the caller's working directory), as
# tests/cli/test_crash_replay.py does; the script runs from any directory.
# Prints the executions reached per target and a final "N passed, N failed"
# line (one check per replay and per run).
# Called by ./build.sh test (short) and ./build.sh fuzz (longer).
set -uo pipefail
caller_pwd=$(pwd)
cd "$(dirname "$0")/../.." || exit 1
crashers=${VOXLIGHT_CRASHERS:-tests/crashers}
[ -n "${VOXLIGHT_CRASHERS:-}" ] && [[ $crashers != /* ]] && crashers=$caller_pwd/$crashers
secs=${1:-20}
shift || true
replay_only=0
[ "$secs" = replay ] && replay_only=1
targets=("$@")
# vdb fuzzes in fork mode: see fuzz_contained_vdb below.
[ ${#targets[@]} -eq 0 ] && targets=(nifti nrrd metaimage tiff png dicom vdb label_table zarr brick_cache tiff_layout)

# The corpus first: every target needs at least one input to replay (dot
# files such as .keep do not count).
corpus_gaps=0
for t in "${targets[@]}"; do
    if [ ! -d "$crashers/$t" ]; then
        echo "fuzz_$t: FAIL: the crash corpus $crashers/$t/ is missing"
        corpus_gaps=$((corpus_gaps + 1))
    elif [ -z "$(find "$crashers/$t" -maxdepth 1 -type f ! -name '.*' -print -quit)" ]; then
        echo "fuzz_$t: FAIL: the crash corpus $crashers/$t/ is empty (it holds at least one hostile input; see tests/README.md)"
        corpus_gaps=$((corpus_gaps + 1))
    fi
done
if [ $corpus_gaps -gt 0 ]; then
    echo "0 passed, $corpus_gaps failed"
    exit 1
fi

if ! make -s -j"$(nproc)" fuzz; then
    echo "fuzz: build failed"
    echo "0 passed, 1 failed"
    exit 1
fi
if [ $replay_only -eq 0 ]; then
    build/fuzz/make_seeds build/fuzz/seeds || { echo "fuzz: seed writer failed"; echo "0 passed, 1 failed"; exit 1; }
    /usr/bin/python3 tests/fuzz/vdb_seeds.py build/fuzz/seeds/vdb || { echo "fuzz: vdb seed writer failed"; echo "0 passed, 1 failed"; exit 1; }
    /usr/bin/python3 tests/fuzz/zarr_seeds.py build/fuzz/seeds/zarr || { echo "fuzz: zarr seed writer failed"; echo "0 passed, 1 failed"; exit 1; }
    # brick caches of .nii.gz files, written by the cache's own test (the format's one writer)
    rm -rf build/fuzz/seeds/brick_cache
    { make -s -j"$(nproc)" build/tests/test_brick_cache && build/tests/test_brick_cache --write-seeds build/fuzz/seeds/brick_cache; } ||
        { echo "fuzz: brick cache seed writer failed"; echo "0 passed, 1 failed"; exit 1; }
    # the TIFF directory walk: the stack reader's seeds plus big-endian, BigTIFF and many-strip files
    # written by the streaming test
    rm -rf build/fuzz/seeds/tiff_layout
    { make -s -j"$(nproc)" build/tests/test_tiff_stream && build/tests/test_tiff_stream --write-seeds build/fuzz/seeds/tiff_layout &&
        cp build/fuzz/seeds/tiff/* build/fuzz/seeds/tiff_layout/; } ||
        { echo "fuzz: tiff layout seed writer failed"; echo "0 passed, 1 failed"; exit 1; }
fi

export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1

# Whose crash a replay log shows: Voxlight's when a frame of our code
# (csrc/, built with debug info into the target) comes before any frame of
# libopenvdb; otherwise it died in the third-party reader (an abort, an
# absurd allocation, or a time-out inside it), which the helper process
# contains. Exit 0 = not ours.
crash_is_upstream_openvdb() {
    awk '/^ *#[0-9]+ / { if ($0 ~ /csrc\//) exit 1; if ($0 ~ /openvdb/) exit 0 }' "$1"
}

# libopenvdb (inside OpenImageIO's open) aborts on an assertion or asks for
# absurd allocations on some corrupt files before csrc/io/vdb.cpp runs; the
# library contains that by reading .vdb files in a helper process
# (voxlight-read-oiio, csrc/io/reader_spawn.c), but fuzz_vdb runs the read in-process, where libFuzzer
# sees its coverage. So vdb fuzzes in fork mode, carrying on past crashes,
# and every crash is replayed afterwards: one that dies inside libopenvdb is
# the known upstream class (tests/fuzz/upstream/README.md) and is counted,
# any other fails the run and is kept in tests/crashers/vdb/ like any crash.
fuzz_contained_vdb() {  # bin corpus crash_dir log
    local bin=$1 corpus=$2 crash_dir=$3 log=$4 art upstream=0 ours=0 f rlog
    art=$(mktemp -d)
    ASAN_OPTIONS=detect_leaks=0 "$bin" -fork=1 -ignore_crashes=1 -ignore_ooms=1 -ignore_timeouts=1 \
        -max_total_time="$secs" -timeout=10 -rss_limit_mb=2048 -detect_leaks=0 -artifact_prefix="$art/" \
        "$corpus" build/fuzz/seeds/vdb >"$log" 2>&1
    execs=$(grep -oE '^#[0-9]+' "$log" | tail -n 1 | tr -d '#')
    execs=${execs:-0}
    rlog=$(mktemp)
    mkdir -p "$crash_dir"
    for f in "$art"/*; do
        [ -f "$f" ] || continue
        if ASAN_OPTIONS=detect_leaks=0 "$bin" -timeout=60 -rss_limit_mb=2048 "$f" >"$rlog" 2>&1; then
            # a fork-mode job died (e.g. its share of the memory limit) on an
            # input that is fine alone: nothing to keep
            echo "fuzz_vdb: $(basename "$f") does not reproduce on its own"
        elif crash_is_upstream_openvdb "$rlog"; then
            upstream=$((upstream + 1))
        else
            ours=$((ours + 1))
            cp "$f" "$crash_dir/"
            echo "fuzz_vdb: a crash outside libopenvdb: $crash_dir/$(basename "$f")"
            grep -E "ERROR|SUMMARY|runtime error|#[0-5] " "$rlog" | head -n 12
        fi
    done
    rm -rf "$art" "$rlog"
    if [ $ours -eq 0 ] && grep -qE '^#[0-9]+' "$log"; then
        echo "fuzz_vdb: $execs executions in ${secs}s, 0 crashes in Voxlight's code; $upstream inside libopenvdb (contained by the helper process)"
        pass=$((pass + 1))
    else
        echo "fuzz_vdb: FAIL: $ours crashes outside libopenvdb (or the fuzzer did not run)"
        tail -n 5 "$log"
        fail=$((fail + 1))
    fi
    total_execs=$((total_execs + execs))
}

pass=0
fail=0
total_execs=0
for t in "${targets[@]}"; do
    bin=build/fuzz/fuzz_$t
    crash_dir=$crashers/$t
    corpus=build/fuzz/corpus/$t
    mkdir -p "$corpus"
    # OpenImageIO's PNG reader longjmps over a std::string on truncated files
    # (31 bytes lost inside libOpenImageIO, not in Voxlight): leak checks
    # stay on for our own C loaders only. OpenVDB (under OpenImageIO's VDB
    # reader) also loses a 520 KiB block inside libopenvdb on bad files.
    leaks=1
    case $t in tiff|png|vdb) leaks=0 ;; esac

    # (never empty: checked above)
    mapfile -t inputs < <(find "$crash_dir" -maxdepth 1 -type f ! -name '.*' | sort)
    log=$(mktemp)
    if ASAN_OPTIONS=detect_leaks=$leaks "$bin" -detect_leaks=$leaks -timeout=10 -rss_limit_mb=2048 "${inputs[@]}" >"$log" 2>&1 \
        && [ "$(grep -c '^Executed ' "$log")" -eq ${#inputs[@]} ]; then
        echo "fuzz_$t: replayed ${#inputs[@]} crashers from $crash_dir/: ok"
        pass=$((pass + 1))
    else
        echo "fuzz_$t: FAIL replaying the crashers in $crash_dir/:"
        grep -E "ERROR|SUMMARY|runtime error|Running:|No such file" "$log" | tail -n 20
        fail=$((fail + 1))
    fi
    rm -f "$log"
    [ $replay_only -eq 1 ] && continue

    log=$(mktemp)
    if [ "$t" = vdb ]; then
        fuzz_contained_vdb "$bin" "$corpus" "$crash_dir" "$log"
        rm -f "$log"
        continue
    fi
    before=$(find "$crash_dir" -maxdepth 1 -type f | wc -l)
    ASAN_OPTIONS=detect_leaks=$leaks "$bin" -max_total_time="$secs" -timeout=10 -rss_limit_mb=2048 -detect_leaks=$leaks -print_final_stats=1 \
        -artifact_prefix="$crash_dir/" "$corpus" "build/fuzz/seeds/$t" >"$log" 2>&1
    rc=$?
    execs=$(grep -oE 'stat::number_of_executed_units: [0-9]+' "$log" | grep -oE '[0-9]+$' | tail -n 1)
    execs=${execs:-0}
    total_execs=$((total_execs + execs))
    after=$(find "$crash_dir" -maxdepth 1 -type f | wc -l)
    if [ $rc -eq 0 ] && [ "$after" -eq "$before" ]; then
        echo "fuzz_$t: $execs executions in ${secs}s, 0 crashes, corpus $(find "$corpus" -type f | wc -l) files"
        pass=$((pass + 1))
    else
        echo "fuzz_$t: FAIL after $execs executions (exit $rc); new crashers in $crash_dir:"
        find "$crash_dir" -maxdepth 1 -type f -newer "$log" | sed 's/^/  /'
        grep -E "ERROR|SUMMARY|runtime error|#0 |#1 |#2 |#3 " "$log" | head -n 20
        fail=$((fail + 1))
    fi
    rm -f "$log"
done
[ $replay_only -eq 1 ] || echo "fuzz: $total_execs executions in total"
echo "$pass passed, $fail failed"
[ $fail -eq 0 ]
