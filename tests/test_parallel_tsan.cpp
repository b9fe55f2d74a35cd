// The parallel kernels and a Simulator step on an executor built from
// std::thread only (threads started and joined per call, chunks taken from
// an atomic counter). ThreadSanitizer sees all of its synchronisation, so a
// TSan build of this test checks the kernels' write sets for races without
// the false positives of the uninstrumented OpenMP and TBB runtimes (see
// parallel/README.md). In a normal build it is one more determinism check.
#include <gtest/gtest.h>

#include <atomic>
#include <cstring>
#include <thread>

#include "lab/deformations.hpp"
#include "edgefem/core/make_box.hpp"
#include "edgefem/core/simulator.hpp"
#include "edgefem/parallel/adaptive_executor.hpp"
#include "edgefem/parallel/executors.hpp"
#include "cpu/parallel_edge_kernels.hpp"
#include "cpu/cpu_operator.hpp"
#include "cpu/parallel_tet_kernels.hpp"
#include "cantilever.hpp"
#include "models.hpp"

using namespace edgefem;

namespace {

class ThreadExecutor final : public Executor {
public:
    explicit ThreadExecutor(int threads) : threads_(threads) {}
    int threads() const override { return threads_; }
    const char* name() const override { return "std::thread"; }
    void for_chunks(index_t n, const std::function<void(index_t)>& body) const override {
        std::atomic<index_t> next{0};
        auto work = [&] {
            for (index_t c; (c = next.fetch_add(1)) < n;) body(c);
        };
        std::vector<std::thread> pool;
        for (int t = 1; t < threads_; ++t) pool.emplace_back(work);
        work();
        for (auto& t : pool) t.join();
    }

private:
    int threads_;
};

using test::bitwise_equal;

}  // namespace

TEST(ParallelTsan, EdgeKernels) {
    const Mesh mesh = make_box(6, 5, 4);
    const auto models = edgefem::test::make_models<double>(mesh);
    const auto u = deformation_displacement(mesh, Deformation::Twist);
    const auto x = deformation_displacement(mesh, Deformation::Random);
    const TetEdgeForm<double> form = make_tet_edge_form<double>(mesh, models.topo, Materials(Material{1e5, 0.3, 1000}));
    for (bool tet_local : {false, true}) {  // with the form: its stiffness pass, and the owner variant's force from it
        for (Variant v : kAllVariants) {
            std::vector<double> ref_f, ref_y, ref_D, ref_K;
            for (int threads : {1, 3}) {
                PlanOptions opts;
                opts.owner_parts = 5;        // the owner variant's spill windows in use (every part spills)
                opts.form_tile_batches = 2;  // and several tiles per part (FormTile)
                ParallelEdgeKernels<double> k(models.edge, std::make_shared<ThreadExecutor>(threads), v, opts,
                                              tet_local ? form : TetEdgeForm<double>{});
                std::vector<double> f(u.size()), y(u.size()), D(3 * u.size());
                EdgeState<double> st;
                EdgeStiffness<double> K;
                k.forces<ModelKind::FE, true>(u.data(), f.data(), st);
                k.stiffness<ModelKind::FE, false>(st, K);
                k.multiply(K, x.data(), y.data());
                k.diagonal_blocks(K, D.data());
                std::vector<double> Ke(K.K.begin(), K.K.begin() + 9 * std::size_t(models.edge.num_edges()));
                if (threads == 1) {
                    ref_f = f, ref_y = y, ref_D = D, ref_K = Ke;
                } else if (is_deterministic(v)) {
                    EXPECT_TRUE(bitwise_equal(f, ref_f) && bitwise_equal(y, ref_y) && bitwise_equal(D, ref_D) && bitwise_equal(Ke, ref_K)) << to_string(v);
                } else {
                    EXPECT_LE(edgefem::test::rel_diff(f, ref_f), 1e-12);
                    EXPECT_LE(edgefem::test::rel_diff(Ke, ref_K), 1e-12);
                }
            }
        }
    }
}

TEST(ParallelTsan, TetKernelsAndStep) {
    for (Method method : {Method::Edge, Method::Tet})
        for (Variant v : kAllVariants) {
            Scene s = edgefem::test::clamped_box_scene(5, 2, 2);
            s.integrator = Integrator::SemiImplicit;
            s.method = method;
            s.dt = 2e-3;
            s.count_inverted_tets = true;
            std::vector<std::vector<double>> u;
            for (int threads : {1, 3}) {
                const auto ex = std::make_shared<ThreadExecutor>(threads);
                Simulator<double> sim(s, ex, cpu_operator_factory<double>({ex, v}));
                sim.step();
                sim.step();
                u.emplace_back(sim.displacement().begin(), sim.displacement().end());
            }
            if (is_deterministic(v) || (method == Method::Tet && v != Variant::Private))
                EXPECT_TRUE(bitwise_equal(u[0], u[1]));
            else
                EXPECT_LE(edgefem::test::rel_diff(u[1], u[0]), 1e-12);
        }
}

// The adaptive executor over the std::thread one: a Simulator's steps move
// between the threads and the calling thread with the same results, and
// two callers timing the same loop at once share its record safely.
TEST(ParallelTsan, AdaptiveExecutor) {
    Scene s = edgefem::test::clamped_box_scene(5, 2, 2);
    s.integrator = Integrator::SemiImplicit;
    s.dt = 2e-3;
    const auto plain = std::make_shared<ThreadExecutor>(3);
    const auto adaptive = std::make_shared<AdaptiveExecutor>(plain, 1);
    Simulator<double> a(s, plain, cpu_operator_factory<double>({plain, Variant::Auto}));
    Simulator<double> b(s, adaptive, cpu_operator_factory<double>({adaptive, Variant::Auto}));
    for (int k = 0; k < 4; ++k) {
        a.step();
        b.step();
    }
    EXPECT_TRUE(bitwise_equal(std::vector<double>(a.displacement().begin(), a.displacement().end()),
                     std::vector<double>(b.displacement().begin(), b.displacement().end())));

    std::vector<std::atomic<int>> hits(2 * 16);
    const auto caller = [&](int who) {
        for (int call = 0; call < 10; ++call)
            adaptive->for_chunks(16, [&, who](index_t c) { hits[16 * who + c].fetch_add(1); });
    };
    std::thread other(caller, 1);
    caller(0);
    other.join();
    for (const auto& h : hits) EXPECT_EQ(h.load(), 10);
}

// The pool executor (std::threads and atomics only, so TSan sees all of it):
// every variant's Simulator steps on 3 pool threads against 1.
TEST(ParallelTsan, PoolExecutor) {
    for (Variant v : kAllVariants) {
        Scene s = edgefem::test::clamped_box_scene(5, 2, 2);
        s.integrator = Integrator::SemiImplicit;
        s.dt = 2e-3;
        std::vector<std::vector<double>> u;
        for (int threads : {1, 3}) {
            for (Schedule sched : {Schedule::Dynamic, Schedule::Static}) {
                const auto ex = make_executor(ExecutorKind::Pool, threads, sched);
                Simulator<double> sim(s, ex, cpu_operator_factory<double>({ex, v}));
                sim.step();
                sim.step();
                u.emplace_back(sim.displacement().begin(), sim.displacement().end());
            }
        }
        for (std::size_t k = 1; k < u.size(); ++k) {
            if (is_deterministic(v))
                EXPECT_TRUE(bitwise_equal(u[0], u[k])) << to_string(v);
            else
                EXPECT_LE(edgefem::test::rel_diff(u[k], u[0]), 1e-12) << to_string(v);
        }
    }
}

// Newton on the pool (an implicit step with damping, a static solve): its
// residual, norms, line search and updates run on the executor's blocks;
// 3 threads give the bits of 1.
TEST(ParallelTsan, PoolNewton) {
    std::vector<std::vector<double>> out;
    for (int threads : {1, 3}) {
        const auto ex = make_executor(ExecutorKind::Pool, threads);
        Scene s = edgefem::test::clamped_box_scene(5, 2, 2);
        s.integrator = Integrator::Implicit;
        s.dt = 2e-3;
        s.rayleigh_alpha = 0.5;
        s.rayleigh_beta = 1e-3;
        Simulator<double> sim(s, ex, cpu_operator_factory<double>({ex, Variant::Auto}));
        sim.step();
        Simulator<double> st(edgefem::test::clamped_box_scene(5, 2, 2), ex, cpu_operator_factory<double>({ex, Variant::Auto}));
        EXPECT_TRUE(st.solve_static().converged);
        std::vector<double> u(sim.displacement().begin(), sim.displacement().end());
        u.insert(u.end(), st.displacement().begin(), st.displacement().end());
        out.push_back(std::move(u));
    }
    EXPECT_TRUE(bitwise_equal(out[0], out[1]));
}

// Linked phases on the pool: each chunk writes plain (non-atomic) data that
// the chunks linked to it read in the next phase, so a TSan build sees a
// race if a link's happens-before (the chunk counts' release and acquire)
// were missing; in any build the values read must be the finished ones.
TEST(ParallelTsan, PoolLinkedPhases) {
    const int phases = 4;
    const index_t n = 9;
    std::vector<index_t> first, last;
    for (int p = 1; p < phases; ++p)
        for (index_t c = 0; c < n; ++c) {
            first.push_back(p % 2 ? c : std::max<index_t>(0, c - 2));  // successors, then predecessors
            last.push_back(p % 2 ? std::min<index_t>(n - 1, c + 2) : c);
        }
    for (int threads : {2, 3, 4}) {
        const auto ex = make_executor(ExecutorKind::Pool, threads);
        for (int call = 1; call <= 5; ++call) {
            std::vector<long> value(std::size_t(phases) * n, 0);
            std::atomic<int> wrong{0};
            ex->for_linked_phases(phases, n, first.data(), last.data(), [&](int p, index_t c) {
                long sum = 0;
                if (p > 0) {
                    const std::size_t k = std::size_t(p - 1) * n + c;
                    for (index_t d = std::min(first[k], c); d <= std::max(last[k], c); ++d) {
                        const long v = value[std::size_t(p - 1) * n + d];
                        if (v != call * 100 + (p - 1)) wrong.fetch_add(1);
                        sum += v;
                    }
                }
                value[std::size_t(p) * n + c] = call * 100 + p + 0 * sum;
            });
            EXPECT_EQ(wrong.load(), 0) << threads << " threads, call " << call;
        }
    }
}
