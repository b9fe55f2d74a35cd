#!/usr/bin/env bash
# Builds edgefem and its test suite under a sanitizer and runs the suite.
#   scripts/sanitize.sh address [CTEST ARGS...]   # AddressSanitizer + UBSan, build-asan/
#   scripts/sanitize.sh thread  [CTEST ARGS...]   # ThreadSanitizer, build-tsan/
# e.g. scripts/sanitize.sh address -R 'read_mesh|SceneJson|write_vtu|cli_'
# Any sanitizer report fails the test that triggered it (halt_on_error,
# UBSan non-recoverable). Left out: install_consumer (it builds a separate
# CMake project with plain flags against the instrumented static libraries,
# which then lack the sanitizer runtime at link time), the tests that limit the address space
# (ASan reserves terabytes of it), the Python tests (an instrumented
# extension needs the sanitizer runtime preloaded into python3), and under
# TSan the OpenMP and TBB executors' tests, whose runtimes are not
# instrumented (parallel/README.md, "ThreadSanitizer": the std::thread
# executors, test_parallel_tsan, are what TSan checks). The CUDA back-end
# (nvcc compiles its host code without the sanitizer) and the Python module
# (its tests are left out) are not built.
set -euo pipefail
cd "$(dirname "$0")/.."
kind=${1:?usage: scripts/sanitize.sh address|thread [ctest args...]}
shift
case "$kind" in
    address)
        dir=build-asan
        flags="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer -O1 -g"
        # ASan reserves terabytes of address space: the tests that limit it
        # (ulimit -v, RLIMIT_AS) cannot run under it.
        exclude='^python_|^install_consumer$|cli_error_out_of_memory|cli_error_box_memory_estimate|MemoryEstimateRefuses'
        export ASAN_OPTIONS=${ASAN_OPTIONS:-halt_on_error=1:detect_leaks=1}
        export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
        ;;
    thread)
        dir=build-tsan
        flags="-fsanitize=thread -O1 -g"
        exclude='^python_|^install_consumer$|omp|tbb|Omp|Tbb|OpenMP'
        export TSAN_OPTIONS=${TSAN_OPTIONS:-halt_on_error=1:second_deadlock_stack=1}
        ;;
    *) echo "sanitize: expected 'address' or 'thread', got '$kind'" >&2; exit 2 ;;
esac
cmake -S . -B "$dir" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DEDGEFEM_BUILD_BENCHMARKS=OFF \
    -DEDGEFEM_CUDA=OFF -DEDGEFEM_BUILD_PYTHON=OFF \
    -DCMAKE_CXX_FLAGS="$flags" -DCMAKE_C_FLAGS="$flags" \
    -DCMAKE_EXE_LINKER_FLAGS="${flags%% *}" -DCMAKE_SHARED_LINKER_FLAGS="${flags%% *}" >/dev/null
cmake --build "$dir" -j "$(nproc)"
cd "$dir"
ctest --output-on-failure -j "$(nproc)" -E "$exclude" "$@"
