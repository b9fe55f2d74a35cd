#!/usr/bin/env bash
# README command (2): install, build and run the whole test suite; then,
# when clang++ is installed, the libFuzzer harnesses for 5 s each
# (docs/testing.md).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh
(cd build && ctest --output-on-failure -j "$(nproc)")
if command -v clang++ >/dev/null; then
    bash scripts/fuzz.sh 5
else
    echo "test: clang++ not found: the fuzz harnesses (docs/testing.md) were not run"
fi
