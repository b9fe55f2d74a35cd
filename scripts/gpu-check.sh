#!/usr/bin/env bash
# The GPU check of the CUDA back-end (docs/gpu.md): the GPU tests, the GPU
# benchmarks and the CPU thread sweep of the same machine, then the linear
# solvers on all its cores (docs/solvers.md: CHOLMOD against the old
# factorisation with the serial and the threaded OpenBLAS; block-Jacobi
# against AMG on bunny-250k), in one log
# ($OUT/gpu-check.log when OUT is set, else ./gpu-check.log). Under 8
# minutes on 16 cores and one H100.
#
#   scripts/gpu-check.sh          on a GPU machine with the project's
#                                 dependencies: builds build-gpu/ with CUDA,
#                                 then runs the check;
#   scripts/gpu-check.sh pack     on a machine without a GPU (nvcc needed):
#                                 a portable CUDA build of the programs the
#                                 check runs, their Debian shared libraries
#                                 and the meshes, in .gpubundle/ (git-ignored);
#   .gpubundle/run.sh             on a GPU machine without the dependencies
#                                 (a lent machine with nothing installed):
#                                 the check from the bundle.
set -uo pipefail
cd "$(dirname "$0")/.."
PROGRAMS="edgefem edgefem_test_cuda_backend edgefem_bench_gpu edgefem_bench_solvers"
mesh_dir=${EDGEFEM_MESH_DIR:-../shared/meshes}

# run_prog SECONDS NAME ARGS...: a program of the build or the bundle
# ($BIN, started through $LAUNCH), with a time limit.
run_prog() {
    local s=$1 p=$2
    shift 2
    # shellcheck disable=SC2086
    timeout "$s" $LAUNCH "$BIN/$p" "$@"
}

# The check itself.
check() {
    echo "== gpu-check $(date -u +%FT%TZ)"
    nvidia-smi --query-gpu=name,driver_version,memory.total,clocks.max.sm --format=csv 2>&1 | head -3
    nvcc --version 2>/dev/null | tail -1
    echo "cpu: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2) x $(nproc)"
    echo "== GPU tests (whole output: $tests_log)"
    run_prog 300 edgefem_test_cuda_backend 2>&1 | tee "$tests_log" | grep -E "^\[ *(RUN|OK|FAILED|PASSED|SKIPPED) |Failure|error|beam, 1000|against CPU|Expected|Which is|actual"
    echo "tests rc=${PIPESTATUS[0]}"
    echo "== GPU benchmarks"
    run_prog 100 edgefem_bench_gpu --meshes armadillo-7k,bunny-250k,bunny-1m 2>&1
    echo "bench rc=$?"
    echo "== CLI: the built-in beam, 300 steps, on the GPU and on every CPU core"
    for b in cuda auto; do
        echo "-- --backend $b"
        run_prog 60 edgefem simulate --backend "$b" --steps 300 --quiet --out "${TMPDIR:-/tmp}/edgefem-gpu-check-$b" 2>&1 | tail -12
    done
    echo "== CPU sweep: semi-implicit step, 20 CG iterations, bunny-250k"
    for t in 1 2 4 8 16; do
        echo "-- threads $t"
        run_prog 30 edgefem bench "$EDGEFEM_MESH_DIR/bunny-250k" --kernel step --cg-iters 20 --backend pool --threads "$t" --seconds 2 2>&1 \
            | grep -E "median_ms|min_ms|backend|error" || true
    done
    echo "== Solvers on every core (docs/solvers.md): the direct solver against the old path, the beam"
    # CHOLMOD's factorisation is BLAS: the serial OpenBLAS the library
    # installs, then the threaded one where the bundle has it (lib-pthread/).
    # OpenBLAS falls back to generic kernels on a CPU it does not recognise
    # (a VM's "Intel Xeon Processor": 3x slower on the beam), so the kernels
    # of the CPU's vector width are timed too.
    local core=Haswell
    grep -qm1 avx512f /proc/cpuinfo && core=SkylakeX
    direct() { run_prog 60 edgefem_bench_solvers --parts direct --rounds 3 2>&1 | grep -E "^\| (Eigen|CHOLMOD)|BLAS"; }
    echo "-- serial OpenBLAS, its own choice of kernels"
    direct
    echo "-- serial OpenBLAS, OPENBLAS_CORETYPE=$core"
    OPENBLAS_CORETYPE=$core direct
    if [ -n "${LAUNCH_PTHREAD:-}" ]; then
        echo "-- threaded OpenBLAS, OPENBLAS_CORETYPE=$core OPENBLAS_NUM_THREADS=$(nproc)"
        OPENBLAS_CORETYPE=$core OPENBLAS_NUM_THREADS=$(nproc) LAUNCH=$LAUNCH_PTHREAD direct
    fi
    echo "== Solvers on every core: block-Jacobi against AMG per step, bunny-250k at 1 ms, $(nproc) threads"
    run_prog 150 edgefem_bench_solvers --parts step --meshes bunny-250k --dts 1 --rounds 1 --threads "$(nproc)" 2>&1 | grep -E "^\| bunny"
    echo "== gpu-check done $(date -u +%FT%TZ)"
}

log=${OUT:-.}/gpu-check.log
tests_log=${OUT:-.}/gpu-tests.log
case "${1:-build}" in
build)
    cmake -S . -B build-gpu -DCMAKE_BUILD_TYPE=Release -DEDGEFEM_CUDA=ON -DEDGEFEM_NATIVE=OFF >/dev/null || exit 1
    cmake --build build-gpu -j "$(nproc)" --target $PROGRAMS >/dev/null || exit 1
    export EDGEFEM_MESH_DIR=$mesh_dir
    BIN=build-gpu/bin LAUNCH=""
    check 2>&1 | tee "$log"
    ;;
pack)
    B=.gpubundle
    grep -qs "^/$B/" .git/info/exclude || { mkdir -p .git/info && echo "/$B/" >> .git/info/exclude; }
    cmake -S . -B build-gpubundle -DCMAKE_BUILD_TYPE=Release -DEDGEFEM_CUDA=ON -DEDGEFEM_NATIVE=OFF \
          -DEDGEFEM_BENCH_HYPRE=OFF -DCMAKE_CXX_FLAGS=-march=x86-64-v3 >/dev/null || exit 1
    cmake --build build-gpubundle -j "$(nproc)" --target $PROGRAMS || exit 1
    rm -rf "$B" && mkdir -p "$B/bin" "$B/lib" "$B/meshes"
    for p in $PROGRAMS; do cp "build-gpubundle/bin/$p" "$B/bin/"; done
    for l in $(ldd "$B"/bin/* | awk '/=>/ {print $3}' | grep -v libcuda | sort -u) /lib/x86_64-linux-gnu/libtbbmalloc.so.2; do
        [ -f "$l" ] && cp -L "$l" "$B/lib/"
    done
    cp -L /lib64/ld-linux-x86-64.so.2 "$B/lib/"
    # The threaded OpenBLAS (Debian's libopenblas0-pthread), for the direct
    # solver on every core, when the package can be fetched.
    deb_dir=$(mktemp -d)
    if (cd "$deb_dir" && apt-get download libopenblas0-pthread >/dev/null 2>&1); then
        dpkg-deb -x "$deb_dir"/libopenblas0-pthread_*.deb "$deb_dir/x"
        mkdir -p "$B/lib-pthread"
        for l in libblas.so.3 libopenblas.so.0; do  # lib/'s liblapack calls libopenblas.so.0
            cp -L "$(find "$deb_dir/x" -name "$l" | head -1)" "$B/lib-pthread/"
        done
    fi
    rm -rf "$deb_dir"
    for m in box-1200 spot-2k bunny-4k armadillo-7k bunny-50k armadillo-100k bunny-250k bunny-1m; do
        for e in node ele; do [ -f "$mesh_dir/$m.$e" ] && gzip -6 -c "$mesh_dir/$m.$e" > "$B/meshes/$m.$e.gz"; done
    done
    # Compressed, so that the bundle travels within the device tool's 64 MiB.
    gzip -9 "$B"/bin/* "$B"/lib/*
    [ -d "$B/lib-pthread" ] && gzip -9 "$B"/lib-pthread/*
    cp scripts/gpu-check.sh "$B/gpu-check.sh"
    cat > "$B/run.sh" <<'RUN'
#!/bin/bash
# Runs the GPU check from this bundle (scripts/gpu-check.sh pack).
B=$(cd "$(dirname "$0")" && pwd)
gunzip -f "$B"/bin/*.gz "$B"/lib/*.gz "$B"/lib-pthread/*.gz 2>/dev/null
(cd "$B/meshes" && for f in *.gz; do [ -f "$f" ] && { [ -f "${f%.gz}" ] || gunzip -kf "$f"; }; done)
export EDGEFEM_MESH_DIR=$B/meshes
# The driver's libcuda from the machine, everything else from the bundle.
cuda_dir=$(dirname "$(ldconfig -p | awk '/libcuda.so.1/ {print $NF; exit}')" 2>/dev/null)
exec bash "$B/gpu-check.sh" bundle "$B" "${cuda_dir:-.}:/usr/local/nvidia/lib64:/usr/lib/x86_64-linux-gnu${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
RUN
    chmod +x "$B/run.sh"
    du -sh "$B"
    ;;
bundle)
    export EDGEFEM_MESH_DIR=$2/meshes
    BIN=$2/bin LAUNCH="$2/lib/ld-linux-x86-64.so.2 --library-path $2/lib:$3"
    [ -d "$2/lib-pthread" ] && LAUNCH_PTHREAD="$2/lib/ld-linux-x86-64.so.2 --library-path $2/lib-pthread:$2/lib:$3"
    check 2>&1 | tee "$log"
    ;;
*)
    echo "usage: scripts/gpu-check.sh [build | pack]" >&2
    exit 2
    ;;
esac
