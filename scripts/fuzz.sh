#!/usr/bin/env bash
# Builds the libFuzzer harnesses (tests/fuzz: the TetGen, Gmsh, MEDIT and
# Vega readers and the scene parser, under AddressSanitizer and UBSan) with
# clang into build-fuzz/ and runs each for SECONDS (default 5) from a copy of
# its seed corpus (tests/fuzz/corpus/<harness>). Exits non-zero on a crash,
# a leak, a timeout or an error; the input that caused it is left in
# build-fuzz/ (crash-*, leak-*, timeout-*). Needs clang++ (Debian: clang).
#   scripts/fuzz.sh            # 5 s each (CI)
#   scripts/fuzz.sh 600        # 10 min each
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-5}
cxx=${CLANGXX:-$(command -v clang++ || true)}
if [ -z "$cxx" ]; then
    echo "fuzz: clang++ not found; install clang to build the libFuzzer harnesses" >&2
    exit 1
fi
cmake -S tests/fuzz -B build-fuzz -DCMAKE_CXX_COMPILER="$cxx" -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
cmake --build build-fuzz -j "$(nproc)" >/dev/null
for harness in read_tetgen read_gmsh read_medit read_vega scene; do
    work=$(mktemp -d)
    cp tests/fuzz/corpus/"$harness"/* "$work"/
    echo "fuzz: $harness for ${seconds}s"
    # -max_len keeps inputs small (the readers are linear in the file);
    # -rss_limit_mb and -timeout turn a blow-up into a reported failure.
    rc=0
    (cd build-fuzz && ASAN_OPTIONS=detect_leaks=1 ./fuzz_"$harness" -max_total_time="$seconds" -max_len=4096 \
        -rss_limit_mb=2048 -timeout=10 -print_final_stats=1 "$work" >fuzz_"$harness".log 2>&1) || rc=$?
    grep -E "^(stat::number_of_executed_units|SUMMARY)" build-fuzz/fuzz_"$harness".log || true
    if [ "$rc" -ne 0 ]; then
        tail -n 40 build-fuzz/fuzz_"$harness".log >&2
        echo "fuzz: $harness FAILED (exit $rc; log and input in build-fuzz/)" >&2
        rm -rf "$work"
        exit 1
    fi
    rm -rf "$work"
done
echo "fuzz: all harnesses ran clean"
