#!/usr/bin/env bash
# Installs every Debian package edgefem needs. Idempotent: when all are
# present it does nothing (and needs no network). Run as root on Debian 12.
set -euo pipefail

packages=(
  build-essential cmake git python3
  libeigen3-dev       # dense 3x3 algebra in set-up code
  libtbb-dev          # TBB back-end
  libmetis-dev        # partitioning / reordering
  libsuitesparse-dev  # CHOLMOD: the direct solver
  libopenblas0-serial # BLAS behind CHOLMOD's supernodal factorisation (4x the reference BLAS; docs/solvers.md)
  libhypre-dev        # benchmarks: hypre BoomerAMG, the AMG preconditioner's comparison
  libgtest-dev        # tests
  libbenchmark-dev    # benchmarks
  libcli11-dev        # command-line parsing
  nlohmann-json3-dev  # scene files
  zlib1g-dev          # compressed binary VTU output
  python3-getfem      # tests: GetFEM reference for `edgefem static` (system python3)
  libfmt-dev
  pybind11-dev        # Python bindings (build/python/edgefem/_edgefem*.so)
  python3-dev         # Python headers for the bindings
  python3-numpy       # Python bindings: arrays (system python3)
  python3-matplotlib  # bench/report: the plots of docs/benchmarks.md (system python3)
  python3-pytest      # tests: the Python suite
  doxygen             # API reference (ctest api_reference_doxygen)
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi

sudo=""
if [ "$(id -u)" -ne 0 ]; then sudo="sudo"; fi
echo "install-deps: installing ${missing[*]}"
$sudo apt-get update -qq
DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
