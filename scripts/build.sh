#!/usr/bin/env bash
# Configures and builds edgefem into build/ (Release, -march=native unless
# EDGEFEM_NATIVE=OFF is given in the environment).
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DEDGEFEM_NATIVE="${EDGEFEM_NATIVE:-ON}" >/dev/null
cmake --build build -j "$(nproc)"
