#!/usr/bin/env bash
# Configures and builds edgefem into build/ (Release) for THIS machine:
# -march=native (EDGEFEM_NATIVE=ON) unless EDGEFEM_NATIVE=OFF is given in the
# environment. build/ is what the tests, CI and the benchmarks of docs/ run,
# on the machine that built it, and the kernels are measurably faster native
# (docs/compilers.md, "-march=native"). It is not portable: to install or
# package, configure without EDGEFEM_NATIVE (the CMake default is OFF).
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DEDGEFEM_NATIVE="${EDGEFEM_NATIVE:-ON}" >/dev/null
cmake --build build -j "$(nproc)"
