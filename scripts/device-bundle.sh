#!/usr/bin/env bash
# Packs the benchmark programs for a machine without the project's
# dependencies (e.g. a lent many-core machine): a portable build
# (x86-64-v3, no -march=native), the Debian shared libraries and loader they
# need, the reference meshes (gzip) and a runner, in .devbundle/ (git-ignored
# via .git/info/exclude). On the other machine:
#   .devbundle/run.sh info                  # machine facts -> $OUT/machine.txt
#   .devbundle/run.sh bp NAME FILTER SECONDS [benchmark flags]
#       edgefem_bench_parallel with that filter, 3 repetitions, medians to
#       $OUT/NAME.log and NAME.json (bench/scaling_tables reads the log)
#   .devbundle/run.sh tests [gtest flags]  # the parallel and simulator tests
#       (bitwise determinism at 1..16 threads on real cores) -> $OUT/tests.log
set -euo pipefail
cd "$(dirname "$0")/.."
B=.devbundle
grep -qs "^/$B/" .git/info/exclude || { mkdir -p .git/info && echo "/$B/" >> .git/info/exclude; }
cmake -S . -B build-dev -DCMAKE_BUILD_TYPE=Release -DEDGEFEM_NATIVE=OFF -DCMAKE_CXX_FLAGS=-march=x86-64-v3 \
      -DEDGEFEM_BUILD_TESTS=ON -DEDGEFEM_BUILD_PYTHON=OFF -DEDGEFEM_BUILD_EXAMPLES=OFF > /dev/null
cmake --build build-dev -j "$(nproc)" --target edgefem_bench_parallel edgefem edgefem_test_parallel_kernels edgefem_test_parallel_simulator edgefem_test_parallel_executors edgefem_test_async_tangent
rm -rf "$B" && mkdir -p "$B/bin" "$B/lib" "$B/meshes"
cp build-dev/bin/edgefem_bench_parallel build-dev/bin/edgefem build-dev/bin/edgefem_test_* "$B/bin/"
for l in $(ldd "$B"/bin/* | awk '/=>/ {print $3}' | sort -u) /lib/x86_64-linux-gnu/libtbbmalloc.so.2; do
    [ -f "$l" ] && cp -L "$l" "$B/lib/"
done
cp -L /lib64/ld-linux-x86-64.so.2 "$B/lib/"
mesh_dir=${EDGEFEM_MESH_DIR:-../shared/meshes}
for m in box-1200 spot-2k bunny-4k armadillo-7k bunny-250k bunny-1m; do
    for e in node ele; do [ -f "$mesh_dir/$m.$e" ] && gzip -6 -c "$mesh_dir/$m.$e" > "$B/meshes/$m.$e.gz"; done
done
cat > "$B/run.sh" <<'RUN'
#!/bin/bash
set -u
B=$(cd "$(dirname "$0")" && pwd)
OUT=${OUT:-/tmp/out}
mkdir -p "$OUT"
(cd "$B/meshes" && for f in *.gz; do [ -f "$f" ] && { [ -f "${f%.gz}" ] || gunzip -kf "$f"; }; done)
export EDGEFEM_MESH_DIR=$B/meshes
X() { "$B/lib/ld-linux-x86-64.so.2" --library-path "$B/lib" "$@"; }
info() { { date -u; uname -a; nproc; lscpu; free -g; } > "$OUT/machine.txt" 2>&1; grep -E "Model name|^CPU\(s\)|L2|L3" "$OUT/machine.txt"; }
bp() {
  local name=$1 filter=$2 to=$3; shift 3
  timeout "$to" "$B/lib/ld-linux-x86-64.so.2" --library-path "$B/lib" "$B/bin/edgefem_bench_parallel" \
    --benchmark_filter="$filter" --benchmark_repetitions=3 --benchmark_report_aggregates_only=true \
    --benchmark_min_time=0.15 --benchmark_out="$OUT/$name.json" --benchmark_out_format=json "$@" 2>&1 \
    | grep -v "_stddev\|_cv\|_mean" > "$OUT/$name.log"
  echo "$name rc=${PIPESTATUS[0]} rows=$(grep -c median "$OUT/$name.log")"
}
tests() {
  local rc=0
  for t in edgefem_test_parallel_kernels edgefem_test_parallel_simulator edgefem_test_parallel_executors edgefem_test_async_tangent; do
    X "$B/bin/$t" --gtest_brief=1 "$@" >> "$OUT/tests.log" 2>&1 || rc=1
  done
  tail -5 "$OUT/tests.log"; echo "tests rc=$rc"
}
export B; export -f X
"$@"
RUN
chmod +x "$B/run.sh"
du -sh "$B"
