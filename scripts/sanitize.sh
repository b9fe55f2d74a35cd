#!/usr/bin/env bash
# Builds edgefem and its test suite under a sanitizer and runs the suite.
#   scripts/sanitize.sh address [CTEST ARGS...]   # AddressSanitizer + UBSan, build-asan/
#   scripts/sanitize.sh thread  [CTEST ARGS...]   # ThreadSanitizer, build-tsan/
# e.g. scripts/sanitize.sh address -R 'read_mesh|SceneJson|write_vtu|cli_'
# Any sanitizer report fails the test that triggered it (halt_on_error,
# UBSan non-recoverable). Left out: install_consumer (it builds a separate
# CMake project with plain flags against the instrumented static libraries,
# which then lack the sanitizer runtime at link time), the tests that limit
# the address space, the Python tests (an instrumented
# extension needs the sanitizer runtime preloaded into python3), and under
# TSan without clang the OpenMP and TBB executors' tests. The CUDA
# back-end (nvcc compiles its host code without the sanitizer) and the
# Python module (its tests are left out) are not built.
#
# TSan and OpenMP: GCC's libgomp is not instrumented, and TSan cannot see
# its barriers, so every OpenMP region looks like a race to it (a TSan run
# of the whole suite with GCC, 2026-11-27: 41 of its 43 reports were in
# OpenMP regions, ours and CHOLMOD's). The thread build therefore uses clang
# with LLVM's libomp and its Archer tool (libarcher.so, which tells TSan
# about OpenMP's synchronisation) when clang is installed; CHOLMOD's and
# OpenBLAS's own code is not instrumented and is ignored
# (ignore_noninstrumented_modules). Without clang, the OpenMP and oneTBB
# tests are left out.
set -euo pipefail
cd "$(dirname "$0")/.."
kind=${1:?usage: scripts/sanitize.sh address|thread [ctest args...]}
shift
# Both sanitizers reserve terabytes of address space: the tests that limit
# it (ulimit -v, RLIMIT_AS) cannot run under them.
address_space_tests='cli_error_out_of_memory|cli_error_box_memory_estimate|MemoryEstimateRefuses'
case "$kind" in
    address)
        dir=build-asan
        flags="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer -O1 -g"
        exclude="^python_|^install_consumer\$|$address_space_tests"
        export ASAN_OPTIONS=${ASAN_OPTIONS:-halt_on_error=1:detect_leaks=1}
        export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
        ;;
    thread)
        dir=build-tsan
        flags="-fsanitize=thread -O1 -g"
        exclude="^python_|^install_consumer\$|$address_space_tests|omp|tbb|Omp|Tbb|OpenMP"
        export TSAN_OPTIONS=${TSAN_OPTIONS:-halt_on_error=1:second_deadlock_stack=1:ignore_noninstrumented_modules=1}
        archer=$(ls /usr/lib/llvm-*/lib/libarcher.so 2>/dev/null | sort -V | tail -1 || true)
        if command -v clang++ >/dev/null && [ -n "$archer" ]; then
            export CC=clang CXX=clang++ OMP_TOOL_LIBRARIES=$archer
            exclude="^python_|^install_consumer\$|$address_space_tests"
        fi
        ;;
    *) echo "sanitize: expected 'address' or 'thread', got '$kind'" >&2; exit 2 ;;
esac
launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
cmake -S . -B "$dir" "${launcher[@]}" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DEDGEFEM_BUILD_BENCHMARKS=OFF \
    -DEDGEFEM_CUDA=OFF -DEDGEFEM_BUILD_PYTHON=OFF \
    -DCMAKE_CXX_FLAGS="$flags" -DCMAKE_C_FLAGS="$flags" \
    -DCMAKE_EXE_LINKER_FLAGS="${flags%% *}" -DCMAKE_SHARED_LINKER_FLAGS="${flags%% *}" >/dev/null
cmake --build "$dir" -j "$(nproc)"
cd "$dir"
ctest --output-on-failure -j "$(nproc)" -E "$exclude" "$@"
