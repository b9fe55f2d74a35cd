#!/usr/bin/env bash
# README command (1): install, build, and run the main job on the built-in
# default scene: a soft beam of 19,200 tets clamped at one end, swinging
# under gravity for 1 s. Frames (VTU + PVD for ParaView) go to
# ./edgefem-out under the current directory.
set -euo pipefail
here="$(pwd)"
root="$(cd "$(dirname "$0")/.." && pwd)"
bash "$root/scripts/install-deps.sh"
bash "$root/scripts/build.sh"
cd "$here"
"$root/build/bin/edgefem" simulate
