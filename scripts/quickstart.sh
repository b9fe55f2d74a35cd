#!/usr/bin/env bash
# README command (1): install, build, and run the main job on the built-in
# default scene (the paper's 1,200-tet box, generated, twisted).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh
mkdir -p out
build/bin/edgefem info box:10x5x4
build/bin/edgefem forces box:10x5x4 --young 1e5 --poisson 0.3 --deform twist --out out/box-twist
build/bin/edgefem bench box:10x5x4 --kernel force+stiffness --seconds 0.5
