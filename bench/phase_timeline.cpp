// Where a parallel kernel's time goes, thread by thread: runs the owner
// variant's force, stiffness or K x on an executor wrapped in a tracer that
// stamps every (phase, part) with the thread that ran it and its start and
// end, then prints, per phase and thread, the median busy time and the
// median start and end within a call, and per part its median time. With
// --compare it also alternates rounds of calls with the phases linked
// (Executor::for_linked_phases, the default) and with a barrier between
// phases (the Executor base class's for_linked_phases), and prints each
// round's medians and their ratio: the two run in one process, paired
// round by round (measured with it: docs/lab/parallel-log.md, Update 7).
// `step` instead runs semi-implicit steps (bench_step's scene, 20 CG
// iterations) and prints the wall time per step of every executor call site
// (the loop body's type): where a step's time goes on N threads. A
// diagnostic, not a benchmark: the tracer's stamps cost ~20 ns per part.
//
//   edgefem_phase_timeline MESH [force|stiffness|kx|step] [--backend pool|omp|tbb|serial]
//                          [--threads N] [--barriers] [--calls N] [--compare ROUNDS]
//
// MESH: a name of bench_meshes.hpp (box-1200, bunny-4k, ...: ../shared/meshes
// or a generated box of the same size), renumbered by RCM.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <vector>

#include <cxxabi.h>

#include <map>
#include <typeindex>

#include "bench_meshes.hpp"
#include "lab/benchmark_scene.hpp"
#include "edgefem/core/coefficients.hpp"
#include "edgefem/core/simulator.hpp"
#include "cpu/cpu_operator.hpp"
#include "lab/deformations.hpp"
#include "cpu/tet_edge_form.hpp"
#include "edgefem/parallel/executors.hpp"
#include "cpu/parallel_edge_kernels.hpp"

using namespace edgefem;
using Clock = std::chrono::steady_clock;

namespace {

constexpr int kMaxTracedThreads = 256;

double now_ns() { return std::chrono::duration<double, std::nano>(Clock::now().time_since_epoch()).count(); }

struct Stamp {
    int phase;
    index_t part;
    double begin, end;  // ns
};

// Thread numbers in order of first appearance (the pool's and OpenMP's
// threads live as long as their executor, so a number stays one thread).
std::atomic<int> next_thread{0};
thread_local int this_thread = -1;

class TracingExecutor final : public Executor {
public:
    explicit TracingExecutor(std::shared_ptr<const Executor> inner)
        : stamps_(kMaxTracedThreads), inner_(std::move(inner)) {}
    int threads() const override { return inner_->threads(); }
    const char* name() const override { return inner_->name(); }
    void for_chunks(index_t n, const std::function<void(index_t)>& body) const override {
        timed(body.target_type(), "chunks", [&] { inner_->for_chunks(n, body); });
    }
    void for_uniform_chunks(index_t n, const std::function<void(index_t)>& body) const override {
        timed(body.target_type(), "uniform chunks", [&] { inner_->for_uniform_chunks(n, body); });
    }
    void for_phases(int phases, const index_t* first, const std::function<void(int, index_t)>& body) const override {
        timed(body.target_type(), "phases", [&] { inner_->for_phases(phases, first, traced(body)); });
    }
    void for_uniform_phases(int phases, const index_t* first,
                            const std::function<void(int, index_t)>& body) const override {
        timed(body.target_type(), "uniform phases", [&] { inner_->for_uniform_phases(phases, first, traced(body)); });
    }
    void for_linked_phases(int phases, index_t chunks, const index_t* need_first, const index_t* need_last,
                           const std::function<void(int, index_t)>& body) const override {
        if (barriers)  // the base class: for_uniform_phases, a barrier between phases
            Executor::for_linked_phases(phases, chunks, need_first, need_last, body);
        else
            timed(body.target_type(), "linked phases", [&] {
                inner_->for_linked_phases(phases, chunks, need_first, need_last, traced(body));
            });
    }

    bool barriers = false;
    bool recording = false;  // stamps of phased calls
    bool sites = false;      // wall time per call site
    // Per thread, its stamps in time order.
    mutable std::vector<std::vector<Stamp>> stamps_;
    struct Site {
        double ns = 0;
        long calls = 0;
    };
    mutable std::map<std::pair<std::type_index, std::string>, Site> site_;

private:
    template <class Run>
    void timed(const std::type_info& type, const char* kind, Run&& run) const {
        const double t0 = sites ? now_ns() : 0;
        run();
        if (!sites) return;
        Site& s = site_[{std::type_index(type), kind}];
        s.ns += now_ns() - t0;
        ++s.calls;
    }
    std::function<void(int, index_t)> traced(const std::function<void(int, index_t)>& body) const {
        return [this, &body](int p, index_t c) {
            const double t0 = now_ns();
            body(p, c);
            if (!recording) return;
            if (this_thread < 0) this_thread = next_thread.fetch_add(1);
            if (this_thread < kMaxTracedThreads) stamps_[std::size_t(this_thread)].push_back({p, c, t0, now_ns()});
        };
    }
    std::shared_ptr<const Executor> inner_;
};

double median(std::vector<double> v) {
    if (v.empty()) return 0;
    std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(v.size() / 2), v.end());
    return v[v.size() / 2];
}

[[noreturn]] void usage(const std::string& why) {
    std::fprintf(stderr,
                 "edgefem_phase_timeline: %s\nusage: edgefem_phase_timeline MESH [force|stiffness|kx|step] "
                 "[--backend pool|omp|tbb|serial] [--threads N] [--barriers] [--calls N] [--compare ROUNDS]\n",
                 why.c_str());
    std::exit(2);
}

int positive(const char* s, const char* what) {
    char* end = nullptr;
    const long v = std::strtol(s, &end, 10);
    if (!end || *end || v <= 0 || v > 100000000) usage(std::string(what) + " must be a positive integer, got '" + s + "'");
    return int(v);
}

std::string demangled(const std::type_index& t) {
    int status = 0;
    char* s = abi::__cxa_demangle(t.name(), nullptr, nullptr, &status);
    std::string out = status == 0 && s ? s : t.name();
    std::free(s);
    return out;
}

// `calls` steps (after 20 to warm up), then the wall time per step of every
// call site, largest first.
int step_sites(const Mesh& mesh, const std::string& name, Backend b, int threads, int calls) {
    auto tracer = std::make_shared<TracingExecutor>(make_executor(b, threads));
    Scene scene = step_benchmark_scene(mesh, Materials(Material{1e5, 0.3, 1000}));
    scene.solver.cg_fixed_iterations = 20;
    Simulator<double> sim(std::move(scene), tracer, cpu_operator_factory<double>({tracer, Variant::Auto}));
    for (int i = 0; i < 20; ++i) sim.step();
    tracer->sites = true;
    const double t0 = now_ns();
    for (int i = 0; i < calls; ++i) sim.step();
    const double step = (now_ns() - t0) / calls;
    tracer->sites = false;
    std::vector<std::pair<double, std::string>> rows;
    double in_calls = 0;
    for (const auto& [key, site] : tracer->site_) {
        in_calls += site.ns / calls;
        char head[64];
        std::snprintf(head, sizeof head, "%5.1f calls, %s: ", double(site.calls) / calls, key.second.c_str());
        rows.emplace_back(site.ns / calls, head + demangled(key.first).substr(0, 160));
    }
    std::sort(rows.rbegin(), rows.rend());
    std::printf("mesh %s (%d tets), step (20 CG iterations), backend %s x%d: %.1f us per step, %.1f in executor "
                "calls\n",
                name.c_str(), mesh.num_tets(), tracer->name(), tracer->threads(), step / 1e3, in_calls / 1e3);
    for (const auto& [ns, what] : rows)
        if (ns >= 100) std::printf("%8.1f us  %s\n", ns / 1e3, what.c_str());
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 2) usage("no mesh given");
    const std::string mesh_name = argv[1];
    std::string kernel = "force", backend = "pool";
    int threads = 2, calls = 0, compare = 0;  // calls 0: 3000 kernel calls or 200 steps
    bool barriers = false;
    for (int i = 2; i < argc; ++i) {
        const std::string a = argv[i];
        const auto value = [&]() -> const char* {
            if (i + 1 >= argc) usage(a + " needs a value");
            return argv[++i];
        };
        if (a == "force" || a == "stiffness" || a == "kx" || a == "step") kernel = a;
        else if (a == "--backend") backend = value();
        else if (a == "--threads") threads = positive(value(), "--threads");
        else if (a == "--calls") calls = positive(value(), "--calls");
        else if (a == "--compare") compare = positive(value(), "--compare");
        else if (a == "--barriers") barriers = true;
        else usage("unknown argument '" + a + "'");
    }
    Backend b;
    try {
        b = parse_backend(backend);
    } catch (const std::exception& e) {
        usage(e.what());
    }

    const Mesh* loaded = nullptr;
    try {
        loaded = &bench::bench_mesh(mesh_name + "@rcm");
    } catch (const std::exception& e) {
        std::fprintf(stderr, "edgefem_phase_timeline: %s\n", e.what());
        return 2;
    }
    const Mesh& mesh = *loaded;
    if (kernel == "step") return step_sites(mesh, mesh_name, b, threads, calls > 0 ? calls : 200);
    if (calls == 0) calls = 3000;
    const Topology topo = build_topology(mesh);
    const Materials mat(Material{1e5, 0.3, 1000});
    const EdgeModel<double> model = make_edge_model<double>(topo, compute_coefficients(mesh, topo, mat));
    const TetEdgeForm<double> form = make_tet_edge_form<double>(mesh, topo, mat);
    const std::vector<double> u = deformation_displacement(mesh, Deformation::Twist);
    auto tracer = std::make_shared<TracingExecutor>(make_executor(b, threads, Schedule::Static));
    const ParallelEdgeKernels<double> k(model, tracer, Variant::Owner, PlanOptions{}, form);
    std::vector<double> f(u.size()), x(u.size()), y(u.size());
    for (std::size_t i = 0; i < x.size(); ++i) x[i] = std::sin(0.7 * double(i));
    EdgeState<double> st;
    EdgeStiffness<double> K;
    k.resize(K);
    k.forces<ModelKind::FE, false>(u.data(), f.data(), st);
    k.stiffness<ModelKind::FE>(st, K);
    const auto call = [&] {
        if (kernel == "force")
            k.forces<ModelKind::FE, false>(u.data(), f.data(), st);
        else if (kernel == "stiffness")
            k.stiffness<ModelKind::FE>(st, K);
        else
            k.multiply(K, x.data(), y.data());
    };
    // Median time per call over `n` calls.
    const auto timed = [&](int n) {
        std::vector<double> t(static_cast<std::size_t>(n));
        for (auto& ti : t) {
            const double t0 = now_ns();
            call();
            ti = now_ns() - t0;
        }
        return median(t);
    };
    std::printf("mesh %s (%d tets), %s, backend %s x%d, owner parts %d\n", mesh_name.c_str(), mesh.num_tets(),
                kernel.c_str(), tracer->name(), tracer->threads(), int(k.vertex_parts().parts()));
    for (int i = 0; i < std::min(calls, 2000); ++i) call();  // warm-up

    if (compare > 0) {
        std::vector<double> ratio;
        for (int r = 0; r < compare; ++r) {
            tracer->barriers = false;
            const double linked = timed(calls);
            tracer->barriers = true;
            const double barrier = timed(calls);
            ratio.push_back(linked / barrier);
            std::printf("round %d: linked %.2f us, barriers %.2f us, linked / barriers %.3f\n", r + 1, linked / 1e3,
                        barrier / 1e3, ratio.back());
        }
        std::printf("median linked / barriers: %.3f\n", median(ratio));
    }

    tracer->barriers = barriers;
    std::vector<std::pair<double, double>> span(static_cast<std::size_t>(calls));
    tracer->recording = true;
    for (auto& s : span) {
        s.first = now_ns();
        call();
        s.second = now_ns();
    }
    tracer->recording = false;
    std::vector<double> wall;
    for (const auto& s : span) wall.push_back(s.second - s.first);
    std::printf("%s: call median %.2f us over %d calls\n", barriers ? "barriers" : "linked", median(wall) / 1e3, calls);

    // Per phase and thread: busy time, first start and last end within the call.
    int phases = 0;
    for (const auto& ts : tracer->stamps_)
        for (const Stamp& s : ts) phases = std::max(phases, s.phase + 1);
    for (int p = 0; p < phases; ++p)
        for (std::size_t t = 0; t < tracer->stamps_.size(); ++t) {
            const auto& ts = tracer->stamps_[t];
            if (ts.empty()) continue;
            std::vector<double> busy, begin, end;
            std::vector<std::vector<double>> part_time;
            std::size_t j = 0;
            for (const auto& s : span) {
                double sum = 0, first = 1e300, last = 0;
                bool any = false;
                for (; j < ts.size() && ts[j].begin < s.second; ++j) {
                    const Stamp& e = ts[j];
                    if (e.phase != p || e.begin < s.first) continue;
                    any = true;
                    sum += e.end - e.begin;
                    first = std::min(first, e.begin - s.first);
                    last = std::max(last, e.end - s.first);
                    if (part_time.size() <= std::size_t(e.part)) part_time.resize(std::size_t(e.part) + 1);
                    part_time[std::size_t(e.part)].push_back(e.end - e.begin);
                }
                if (any) busy.push_back(sum), begin.push_back(first), end.push_back(last);
            }
            if (busy.empty()) continue;
            std::printf("phase %d thread %zu: busy %7.2f us, from %7.2f to %7.2f us (%zu calls);", p, t,
                        median(busy) / 1e3, median(begin) / 1e3, median(end) / 1e3, busy.size());
            for (std::size_t q = 0; q < part_time.size(); ++q)
                if (!part_time[q].empty()) std::printf(" part %zu %.2f", q, median(part_time[q]) / 1e3);
            std::printf("\n");
        }
    return 0;
}
