#!/usr/bin/env bash
# `edgefem static` against GetFEM on the same scene (the static acceptance
# check; ctest runs it on tests/data/static/{beam,bar}.json):
#
#   static_reference.sh EDGEFEM PYTHON SCENE.json OUTDIR [TOLERANCE]
#
# EDGEFEM: the edgefem program; PYTHON: a python3 that can import getfem and
# numpy (Debian's python3-getfem installs for /usr/bin/python3). Solves the
# scene with `edgefem static` and with tests/tools/getfem_static.py, then
# compares the displacements with tests/tools/compare_disp.py: exits 0 iff
# max |u_getfem - u_edgefem| / max |u_getfem| <= TOLERANCE (default 1e-8).
set -euo pipefail

if [ $# -lt 4 ] || [ $# -gt 5 ]; then
  sed -n '2,11p' "$0" | sed 's/^# \{0,1\}//' >&2
  exit 2
fi
edgefem=$1 python=$2 scene=$3 outdir=$4 tol=${5:-1e-8}
tools=$(cd "$(dirname "$0")" && pwd)
name=$(basename "$scene" .json)
mkdir -p "$outdir"

echo "== edgefem static $scene"
"$edgefem" static "$scene" --out "$outdir/$name.edgefem"
echo "== GetFEM ($tools/getfem_static.py)"
"$python" "$tools/getfem_static.py" --scene "$scene" --out "$outdir/$name.getfem.disp"
echo "== compare"
"$python" "$tools/compare_disp.py" "$outdir/$name.getfem.disp" "$outdir/$name.edgefem.disp" "$tol"
