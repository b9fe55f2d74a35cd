// The GPU benchmarks of the CUDA back-end (docs/gpu.md): on each mesh, the
// edge FE force and K x and the per-tet force and K x (medians of timed
// calls after warm-ups, with the bytes each pass must move at least and the
// fraction of the device's measured copy bandwidth that makes; each form of
// the edge K x, and the file's vertex order against RCM's), then a
// semi-implicit step with 20 CG iterations on the GPU and on every CPU core
// of the same machine (the step_benchmark_scene). Prints a markdown table.
//
//   edgefem_bench_gpu [--meshes armadillo-7k,bunny-250k,bunny-1m] [--calls 30] [--steps 20]
#include <cuda_runtime.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include "edgefem/core/backend.hpp"
#include "edgefem/core/coefficients.hpp"
#include "edgefem/core/edge_model.hpp"
#include "edgefem/parallel/cuda_backend.hpp"
#include "edgefem/parallel/executors.hpp"
#include "edgefem/parallel/run_options.hpp"
#include "lab/benchmark_scene.hpp"
#include "lab/deformations.hpp"
#include "lab/named_mesh.hpp"
#include "edgefem/partition/ordering.hpp"
#include "edgefem/partition/permute_mesh.hpp"

using namespace edgefem;

namespace {

double now_ms() {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

template <class F>
double median_ms(int calls, F&& f) {
    for (int k = 0; k < 3; ++k) f();
    cudaDeviceSynchronize();
    std::vector<double> t;
    for (int k = 0; k < calls; ++k) {
        const double t0 = now_ms();
        f();
        cudaDeviceSynchronize();
        t.push_back(now_ms() - t0);
    }
    std::nth_element(t.begin(), t.begin() + t.size() / 2, t.end());
    return t[t.size() / 2];
}

__global__ void empty_kernel() {}

__global__ void copy_kernel(std::size_t n, const double* a, double* b) {
    for (std::size_t i = blockIdx.x * std::size_t(blockDim.x) + threadIdx.x; i < n; i += std::size_t(gridDim.x) * blockDim.x)
        b[i] = a[i];
}

// GB/s of a device-to-device copy of 2 x 512 MiB, bytes read + written.
double copy_bandwidth() {
    const std::size_t n = std::size_t(64) << 20;
    double *a = nullptr, *b = nullptr;
    if (cudaMalloc(&a, n * 8) != cudaSuccess || cudaMalloc(&b, n * 8) != cudaSuccess) return 0;
    cudaMemset(a, 0, n * 8);
    const double ms = median_ms(20, [&] { copy_kernel<<<4096, 256>>>(n, a, b); });
    cudaFree(a);
    cudaFree(b);
    return 2.0 * double(n) * 8 / (ms * 1e6);
}

std::vector<std::string> split(const std::string& s) {
    std::vector<std::string> out;
    std::stringstream ss(s);
    for (std::string x; std::getline(ss, x, ',');)
        if (!x.empty()) out.push_back(x);
    return out;
}

}  // namespace

int main(int argc, char** argv) {
    std::vector<std::string> meshes = {"armadillo-7k", "bunny-250k", "bunny-1m"};
    int calls = 30, steps = 20;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--meshes" && i + 1 < argc) meshes = split(argv[++i]);
        else if (a == "--calls" && i + 1 < argc) calls = std::max(1, std::atoi(argv[++i]));
        else if (a == "--steps" && i + 1 < argc) steps = std::max(1, std::atoi(argv[++i]));
        else {
            std::fprintf(stderr, "edgefem_bench_gpu: unknown argument '%s'\n", a.c_str());
            return 2;
        }
    }
    const std::string why = cuda_unavailable_reason();
    if (!why.empty()) {
        std::fprintf(stderr, "edgefem_bench_gpu: %s\n", why.c_str());
        return 3;
    }
    std::printf("device: %s\n", cuda_device_description().c_str());
    const double bw = copy_bandwidth();
    std::printf("device copy bandwidth: %.0f GB/s (read + write)\n", bw);
    {  // what a step pays per launch and per scalar brought back
        double* d = nullptr;
        cudaMalloc(&d, sizeof(double));
        double h = 0;
        const double launch_us = 1e3 * median_ms(200, [] { empty_kernel<<<1, 32>>>(); });
        const double copy_us = 1e3 * median_ms(200, [&] { cudaMemcpy(&h, d, sizeof h, cudaMemcpyDeviceToHost); });
        const double queued_us = 1e3 * median_ms(20, [] { for (int k = 0; k < 100; ++k) empty_kernel<<<1, 32>>>(); }) / 100;
        cudaFree(d);
        std::printf("empty kernel + synchronise: %.1f us; 8 bytes to the host: %.1f us; queued empty kernels: %.2f us each\n\n",
                    launch_us, copy_us, queued_us);
    }
    std::printf("| mesh | tets | pass | ms | MB moved (at least) | GB/s | of copy |\n|---|---|---|---|---|---|---|\n");
    const Materials mat(Material{1e5, 0.3, 1000});
    const auto dev = make_cuda_backend<double>();
    struct StepRow {
        std::string mesh;
        double gpu, cpu;
        std::vector<double> other;  // GPU ms with K x on 1 and 4 lanes, atomics
    };
    std::vector<StepRow> step_rows;
    for (const std::string& name : meshes) {
        std::string origin;
        const Mesh file_mesh = load_named_mesh(mesh_dir(EDGEFEM_SHARED_MESHES), name, &origin);
        // Renumbered as a simulation numbers it (RunOptions::ordering's default).
        const Mesh mesh = permute_mesh(file_mesh, vertex_ordering(file_mesh, Ordering::RCM));
        const std::size_t nv = std::size_t(mesh.num_vertices()), nt = std::size_t(mesh.num_tets());
        const Topology topo = build_topology(mesh);
        const double ne = double(topo.edges.size()), np = double(topo.tseps.size());
        const std::vector<double> uh = deformation_displacement(mesh, Deformation::Twist);
        BackendVector<double> u(dev->memory(), 3 * nv), f(dev->memory(), 3 * nv), y(dev->memory(), 3 * nv);
        u.write(uh);
        const auto row = [&](const char* pass, double ms, double bytes) {
            std::printf("| %s | %zu | %s | %.3f | %.1f | %.0f | %.0f %% |\n", name.c_str(), nt, pass, ms, bytes / 1e6,
                        bytes / (ms * 1e6), 100 * bytes / (ms * 1e6) / bw);
        };
        {
            auto op = dev->make_operator(mesh, mat, ModelKind::FE, Method::Edge);
            // Each array once: edge model (ends 8, rest 24, L(E) 8, TSEP lists and L(P) ~24 per TSEP and
            // side), u read and f written (24 + 24 per vertex), the vertex lists (4 + 8 per edge), and
            // the per-edge state written then read (p 24, zeta 8, g 8: x2).
            const double force_bytes = ne * (8 + 24 + 8 + 12 + 2 * 40 + 8) + np * (8 + 8 + 16) + nv * (48 + 4);
            row("edge FE force", median_ms(calls, [&] { op->forces(u.data(), f.data(), false); }), force_bytes);
            op->build_stiffness(false);
            // K blocks (72), ends (8), vertex lists (12 per edge), x read and y written.
            const double kx_bytes = ne * (72 + 8 + 12) + nv * (48 + 4);
            row("edge FE K x, 8 lanes (default)", median_ms(calls, [&] { op->multiply(u.data(), y.data()); }), kx_bytes);
            // The other forms of K x (CudaOptions::multiply_lanes; the default is 8).
            for (int lanes : {1, 4, 0}) {
                const auto devl = make_cuda_backend<double>(CudaOptions{lanes});
                auto opl = devl->make_operator(mesh, mat, ModelKind::FE, Method::Edge);
                opl->forces(u.data(), f.data(), false);
                opl->build_stiffness(false);
                const std::string pass = lanes == 0 ? std::string("edge FE K x, atomics")
                                                    : "edge FE K x, " + std::to_string(lanes) + " lanes";
                row(pass.c_str(), median_ms(calls, [&] { opl->multiply(u.data(), y.data()); }), kx_bytes);
            }
            {  // the vertices as the file numbers them
                auto opi = dev->make_operator(file_mesh, mat, ModelKind::FE, Method::Edge);
                BackendVector<double> ui(dev->memory(), 3 * nv);
                ui.write(deformation_displacement(file_mesh, Deformation::Twist));
                opi->forces(ui.data(), f.data(), false);
                opi->build_stiffness(false);
                row("edge FE K x, file order", median_ms(calls, [&] { opi->multiply(ui.data(), y.data()); }), kx_bytes);
            }
            row("edge FE stiffness", median_ms(calls, [&] { op->build_stiffness(false); }),
                ne * (72 + 24 + 8 + 8 + 8) + np * 4 * 12);
        }
        {
            auto op = dev->make_operator(mesh, mat, ModelKind::FE, Method::Tet);
            op->forces(u.data(), f.data(), false);
            // tets (16), Dm^-1 and Lame (88), u read, per-tet slots written and read (96 x 2), f written.
            row("per-tet force", median_ms(calls, [&] { op->forces(u.data(), f.data(), false); }),
                double(nt) * (16 + 88 + 192 + 16) + nv * (48 + 4));
            op->build_stiffness(false);
            row("per-tet K x", median_ms(calls, [&] { op->multiply(u.data(), y.data()); }),
                double(nt) * (16 + 720 + 192 + 16) + nv * (48 + 4));
        }
        // One semi-implicit step, 20 CG iterations: GPU (each form of K x), then every CPU core.
        const Scene scene = step_benchmark_scene(mesh, mat);
        Simulator<double> gpu(scene, dev);
        const double gpu_ms = median_ms(steps, [&] { gpu.step(); });
        std::vector<double> other_ms;
        for (int lanes : {1, 4, 0}) {
            Simulator<double> gl(scene, make_cuda_backend<double>(CudaOptions{lanes}));
            other_ms.push_back(median_ms(steps, [&] { gl.step(); }));
        }
        RunOptions run;  // every core, the default ordering
        auto cpu = make_simulator<double>(scene, run);
        for (int k = 0; k < 2; ++k) cpu->step();
        std::vector<double> t;
        for (int k = 0; k < std::max(3, steps / 4); ++k) {
            const double t0 = now_ms();
            cpu->step();
            t.push_back(now_ms() - t0);
        }
        std::sort(t.begin(), t.end());
        step_rows.push_back({name + " (" + origin + ")", gpu_ms, t[t.size() / 2], other_ms});
    }
    std::printf("\n| mesh | semi-implicit step, 20 CG its: GPU ms | CPU ms (all %d cores) | CPU / GPU | GPU ms, K x on 1 lane | 4 lanes | atomics |\n|---|---|---|---|---|---|---|\n",
                hardware_threads());
    for (const StepRow& r : step_rows)
        std::printf("| %s | %.3f | %.3f | %.1f | %.3f | %.3f | %.3f |\n", r.mesh.c_str(), r.gpu, r.cpu, r.cpu / r.gpu,
                    r.other[0], r.other[1], r.other[2]);
    return 0;
}
