// Executors: every chunk runs exactly once, blocked sums and CG are bitwise
// the same for any back-end, thread count and schedule, names parse and
// print.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <thread>
#include <vector>

#include "edgefem/core/cg.hpp"
#include "edgefem/core/error.hpp"
#include "lab/barrier_latency.hpp"
#include "edgefem/parallel/executors.hpp"
#include "executor_kinds.hpp"
#include "cpu/variant.hpp"
#include "test_threads.hpp"

using namespace edgefem;

TEST(Executors, EveryChunkOnce) {
    for (ExecutorKind b : test::executor_kinds())
        for (int t : {1, 2, 3, 8})
            for (Schedule s : {Schedule::Static, Schedule::Dynamic}) {
                const auto ex = make_executor(b, t, s);
                EXPECT_EQ(ex->threads(), b == ExecutorKind::Serial ? 1 : t);
                for (index_t n : {0, 1, 2, 7, 1000}) {
                    std::vector<std::atomic<int>> hits(n);
                    ex->for_chunks(n, [&](index_t c) { hits[c].fetch_add(1); });
                    for (index_t c = 0; c < n; ++c) EXPECT_EQ(hits[c].load(), 1) << to_string(b) << t << " " << n;
                }
            }
}

// Phases: every (phase, chunk) once, and no call of a phase starts before
// every call of the previous phase has finished (the barrier the coloured
// scatter relies on).
TEST(Executors, PhasesRunOnceAndInOrder) {
    const std::vector<index_t> chunks{3, 0, 1, 16, 2, 5};
    std::vector<index_t> first{0};  // the offsets for_phases takes
    for (index_t n : chunks) first.push_back(first.back() + n);
    for (ExecutorKind b : test::executor_kinds())
        for (int t : {1, 2, 3, 8})
            for (Schedule s : {Schedule::Static, Schedule::Dynamic}) {
                const auto ex = make_executor(b, t, s);
                std::vector<std::vector<std::atomic<int>>> hits;
                for (index_t n : chunks) hits.emplace_back(n);
                std::vector<std::atomic<int>> done(chunks.size());
                std::atomic<int> out_of_order{0};
                ex->for_phases(int(chunks.size()), first.data(), [&](int p, index_t c) {
                    for (int q = 0; q < p; ++q)
                        if (done[q].load() != int(chunks[q])) out_of_order.fetch_add(1);
                    volatile double x = 0;  // a little work so that calls overlap
                    for (int i = 0; i < 2000; ++i) x = x + i;
                    hits[p][c].fetch_add(1);
                    done[p].fetch_add(1);
                });
                EXPECT_EQ(out_of_order.load(), 0) << to_string(b) << t;
                for (std::size_t p = 0; p < chunks.size(); ++p)
                    for (index_t c = 0; c < chunks[p]; ++c) EXPECT_EQ(hits[p][c].load(), 1) << to_string(b) << t;
            }
}

// Linked phases: every (phase, chunk) once, and no chunk starts before the
// chunks it links to (and itself) have finished the phase before.
TEST(Executors, LinkedPhasesHonourTheirLinks) {
    const int phases = 4;
    const index_t n = 7;
    // Phase 1: chunk c needs its successor; phase 2: chunks 0..c; phase 3:
    // out-of-range ends (clamped to the chunks).
    std::vector<index_t> first, last;
    for (index_t c = 0; c < n; ++c) first.push_back(c), last.push_back(std::min<index_t>(c + 1, n - 1));
    for (index_t c = 0; c < n; ++c) first.push_back(0), last.push_back(c);
    for (index_t c = 0; c < n; ++c) first.push_back(-5), last.push_back(n + 5);
    for (ExecutorKind b : test::executor_kinds())
        for (int t : {1, 2, 3, 8}) {
            const auto ex = make_executor(b, t);
            for (int call = 0; call < 3; ++call) {  // the pool counts on from call to call
                std::vector<std::atomic<int>> done(std::size_t(phases * n));
                std::atomic<int> early{0};
                ex->for_linked_phases(phases, n, first.data(), last.data(), [&](int p, index_t c) {
                    if (p > 0) {
                        const std::size_t k = std::size_t(p - 1) * n + c;
                        const index_t lo = std::max<index_t>(0, std::min(first[k], c));
                        const index_t hi = std::min<index_t>(n - 1, std::max(last[k], c));
                        for (index_t d = lo; d <= hi; ++d)
                            if (done[std::size_t(p - 1) * n + d].load() != 1) early.fetch_add(1);
                    }
                    volatile double x = 0;  // a little work so that calls overlap
                    for (int i = 0; i < 2000; ++i) x = x + i;
                    done[std::size_t(p) * n + c].fetch_add(1);
                });
                EXPECT_EQ(early.load(), 0) << to_string(b) << t;
                for (const auto& d : done) EXPECT_EQ(d.load(), 1) << to_string(b) << t;
            }
            ex->for_linked_phases(0, n, first.data(), last.data(), [](int, index_t) { FAIL(); });
            ex->for_linked_phases(phases, 0, first.data(), last.data(), [](int, index_t) { FAIL(); });
        }
}

// And no barrier: on the pool and OpenMP a chunk linked only to itself goes
// on while another chunk of the phase before still runs. Here chunk 1 of
// phase 0 waits (at most 5 s) for chunk 0 of phase 1, which a barrier
// would hold back until the wait timed out.
TEST(Executors, LinkedPhasesHaveNoBarrier) {
    const index_t first[] = {0, 1}, last[] = {0, 1};
    for (ExecutorKind b : {ExecutorKind::OpenMP, ExecutorKind::Pool}) {
        const auto ex = make_executor(b, 2);
        std::atomic<bool> ran{false}, seen{false};
        ex->for_linked_phases(2, 2, first, last, [&](int p, index_t c) {
            if (p == 1 && c == 0) ran = true;
            if (p == 0 && c == 1) {
                const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(5);
                while (!ran.load() && std::chrono::steady_clock::now() < until) std::this_thread::yield();
                seen = ran.load();
            }
        });
        EXPECT_TRUE(seen.load()) << to_string(b);
    }
}

TEST(Executors, BlockedSumIndependentOfThreads) {
    const std::size_t n = 100003;
    std::vector<double> a(n);
    for (std::size_t i = 0; i < n; ++i) a[i] = std::sin(0.37 * double(i)) * std::exp(double(i % 97) / 7);
    const double ref = blocked_sum(SerialExecutor{}, n, [&](std::size_t i) { return a[i]; });
    for (ExecutorKind b : test::threaded_executor_kinds())
        for (int t : edgefem::test::test_thread_counts()) {
            const auto ex = make_executor(b, t);
            EXPECT_EQ(blocked_sum(*ex, n, [&](std::size_t i) { return a[i]; }), ref);
        }
}

// for_blocks hands every index to exactly one block, blocks start at
// multiples of kVectorBlock, for lengths around the block size and the
// one-group threshold.
TEST(Executors, ForBlocksVisitEveryIndexOnce) {
    const std::size_t B = kVectorBlock;
    for (std::size_t n : {std::size_t(0), std::size_t(1), B - 1, B, B + 1, kMinParallelBlocks * B - 1,
                          kMinParallelBlocks * B, kMinParallelBlocks * B + 7, std::size_t(100003)})
        for (ExecutorKind b : test::executor_kinds())
            for (Schedule sc : {Schedule::Static, Schedule::Dynamic})
                for (int t : {1, 2, 3, 8}) {
                    const auto ex = make_executor(b, t, sc);
                    std::vector<std::atomic<int>> hits(n);
                    std::atomic<int> misaligned{0};
                    for_blocks(*ex, n, [&](std::size_t lo, std::size_t hi) {
                        if (lo % B != 0 || hi - lo > B || (hi != n && hi - lo != B)) misaligned.fetch_add(1);
                        for (std::size_t i = lo; i < hi; ++i) hits[i].fetch_add(1);
                    });
                    EXPECT_EQ(misaligned.load(), 0) << n << " " << to_string(b) << t;
                    std::size_t wrong = 0;
                    for (auto& h : hits) wrong += h.load() != 1;
                    EXPECT_EQ(wrong, 0u) << n << " " << to_string(b) << t;
                }
}

// CG on a shifted 1-D Laplacian per component (3 dofs per vertex, every
// 7th vertex fixed at a value): the same iterates, bit for bit, on every
// executor, and a solution that satisfies the system.
TEST(Executors, ConjugateGradientSameBitsOnEveryExecutor) {
    const std::size_t nv = 2500, n = 3 * nv;  // ~20 blocks
    std::vector<std::uint8_t> free_dof(n, 1);
    std::vector<double> b(n), x0(n, 0.0), mass(n);
    for (std::size_t i = 0; i < n; ++i) {
        b[i] = std::cos(0.1 * double(i)) + 0.5;
        mass[i] = 0.01 * (1.0 + double(i % 5));
        if ((i / 3) % 7 == 0) {
            free_dof[i] = 0;
            x0[i] = 0.25 * double(i % 3);
        }
    }
    const auto apply_A = [&](const double* in, double* out) {  // Laplacian along each component
        for (std::size_t i = 0; i < n; ++i) {
            const double l = i >= 3 ? in[i - 3] : 0.0, r = i + 3 < n ? in[i + 3] : 0.0;
            out[i] = 2 * in[i] - l - r;
        }
    };
    const auto finish_A = [&](std::size_t lo, std::size_t hi, const double* in, double* out) {
        for (std::size_t i = lo; i < hi; ++i) out[i] += mass[i] * in[i];
    };
    const auto jacobi = [&](std::size_t lo, std::size_t hi, const double* r, double* z) {
        for (std::size_t i = lo; i < hi; ++i) z[i] = r[i] / (2 + mass[i]);
    };
    const auto solve = [&](const Executor& ex, std::vector<double>& x) {
        x = x0;
        CgWork w;
        return conjugate_gradient(ex, n, free_dof.data(), apply_A, finish_A, jacobi, b.data(), x.data(), 1e-12, 2000,
                                  0, w);
    };
    std::vector<double> ref;
    const CgResult r0 = solve(SerialExecutor{}, ref);
    ASSERT_TRUE(r0.converged);
    // The free rows hold, the fixed values stay.
    std::vector<double> Ax(n);
    apply_A(ref.data(), Ax.data());
    finish_A(0, n, ref.data(), Ax.data());
    double worst = 0, bmax = 0;
    for (std::size_t i = 0; i < n; ++i) {
        if (free_dof[i]) {
            worst = std::max(worst, std::abs(Ax[i] - b[i]));
            bmax = std::max(bmax, std::abs(b[i]));
        } else {
            EXPECT_EQ(ref[i], x0[i]);
        }
    }
    EXPECT_LT(worst, 1e-9 * bmax);
    for (ExecutorKind bk : test::threaded_executor_kinds())
        for (Schedule sc : {Schedule::Static, Schedule::Dynamic})
            for (int t : {1, 2, 3, 8}) {
                std::vector<double> x;
                const CgResult r = solve(*make_executor(bk, t, sc), x);
                EXPECT_EQ(r.iterations, r0.iterations) << to_string(bk) << t;
                EXPECT_EQ(r.residual, r0.residual) << to_string(bk) << t;
                EXPECT_TRUE(x == ref) << to_string(bk) << " " << t << " threads";
            }
}

// The barrier probe runs on every executor, and says what is wrong with
// its arguments.
TEST(Executors, PhaseBarrierProbe) {
    for (ExecutorKind b : test::executor_kinds()) {
        const auto ex = make_executor(b, 2);
        const double us = phase_barrier_us(*ex, 50, 3);
        EXPECT_TRUE(std::isfinite(us) && us >= 0) << to_string(b) << " " << us;
        EXPECT_THROW(phase_barrier_us(*ex, 0), InvalidArgument);
        EXPECT_THROW(phase_barrier_us(*ex, 10, 0), InvalidArgument);
    }
}

TEST(Executors, Names) {
    EXPECT_EQ(parse_executor_kind("serial"), ExecutorKind::Serial);
    EXPECT_EQ(parse_executor_kind("omp"), ExecutorKind::OpenMP);
    EXPECT_EQ(parse_executor_kind("openmp"), ExecutorKind::OpenMP);
    EXPECT_EQ(parse_executor_kind("tbb"), ExecutorKind::TBB);
    EXPECT_THROW(parse_executor_kind("cuda"), InvalidArgument);
    for (ExecutorKind b : test::executor_kinds()) EXPECT_EQ(parse_executor_kind(to_string(b)), b);
    for (Variant v : kAllVariants)
        EXPECT_EQ(parse_variant(to_string(v)), v);
    EXPECT_EQ(parse_variant("color"), Variant::Colour);
    EXPECT_THROW(parse_variant("mutex"), InvalidArgument);
    EXPECT_EQ(parse_schedule("static"), Schedule::Static);
    EXPECT_STREQ(make_executor(ExecutorKind::TBB, 2)->name(), "tbb");
    EXPECT_STREQ(make_executor(ExecutorKind::OpenMP, 2)->name(), "omp");
    EXPECT_EQ(parse_executor_kind("pool"), ExecutorKind::Pool);
    EXPECT_STREQ(make_executor(ExecutorKind::Pool, 2)->name(), "pool");
}

// OpenMP starts as many threads as asked (1e5 crashed in libgomp): past
// kMaxThreads both back-ends refuse; oversubscription below it is fine.
TEST(Executors, ThreadLimit) {
    for (ExecutorKind b : test::threaded_executor_kinds()) {
        EXPECT_THROW(make_executor(b, kMaxThreads + 1), InvalidArgument) << to_string(b);
        EXPECT_THROW(make_executor(b, 100000), InvalidArgument) << to_string(b);
        EXPECT_EQ(make_executor(b, 16)->threads(), 16) << to_string(b);
    }
    EXPECT_NO_THROW(make_executor(ExecutorKind::Serial, 100000));  // serial ignores the count
}

// Two TBB executors with different thread counts coexist (each its arena).
TEST(Executors, IndependentArenas) {
    if (test::kThreadSanitizer) GTEST_SKIP() << "libtbb is not instrumented for ThreadSanitizer";
    const auto a = make_executor(ExecutorKind::TBB, 2), b = make_executor(ExecutorKind::TBB, 3);
    std::atomic<int> n{0};
    a->for_chunks(10, [&](index_t) { b->for_chunks(5, [&](index_t) { n.fetch_add(1); }); });
    EXPECT_EQ(n.load(), 50);
}

// The pool: a call from inside one of its own calls runs on the calling
// thread (no thread waits for itself), calls from two threads at once take
// turns, and an exception from a chunk comes back to the caller, with every
// thread past every barrier (the pool stays usable).
TEST(Executors, PoolNestingConcurrencyExceptions) {
    const auto pool = make_executor(ExecutorKind::Pool, 3);
    std::atomic<int> n{0};
    pool->for_chunks(10, [&](index_t) { pool->for_chunks(5, [&](index_t) { n.fetch_add(1); }); });
    EXPECT_EQ(n.load(), 50);
    const index_t first[] = {0, 4, 9};
    n = 0;
    pool->for_phases(2, first, [&](int, index_t) {
        pool->for_phases(2, first, [&](int, index_t) { n.fetch_add(1); });
    });
    EXPECT_EQ(n.load(), 81);

    std::vector<std::atomic<int>> hits(2 * 1000);
    const auto caller = [&](int who) {
        for (int call = 0; call < 20; ++call)
            pool->for_chunks(1000, [&, who](index_t c) { hits[1000 * who + c].fetch_add(1); });
    };
    std::thread other(caller, 1);
    caller(0);
    other.join();
    for (const auto& h : hits) EXPECT_EQ(h.load(), 20);

    for (Schedule s : {Schedule::Static, Schedule::Dynamic}) {
        const auto ex = make_executor(ExecutorKind::Pool, 3, s);
        EXPECT_THROW(ex->for_chunks(100, [](index_t c) {
            if (c == 57) throw InvalidArgument("chunk 57");
        }), InvalidArgument);
        EXPECT_THROW(ex->for_phases(2, first, [](int p, index_t c) {
            if (p == 0 && c == 1) throw InvalidArgument("phase 0 chunk 1");
        }), InvalidArgument);
        std::atomic<int> after{0};
        ex->for_phases(2, first, [&](int, index_t) { after.fetch_add(1); });
        EXPECT_EQ(after.load(), 9);
    }
    // Linked phases: inline when nested, exceptions back to the caller with
    // no chunk left waiting, the pool usable after.
    const index_t lf[] = {0, 0, 0, 0, 0}, ll[] = {4, 4, 4, 4, 4};
    n = 0;
    pool->for_linked_phases(2, 5, lf, ll, [&](int, index_t) {
        pool->for_linked_phases(2, 5, lf, ll, [&](int, index_t) { n.fetch_add(1); });
    });
    EXPECT_EQ(n.load(), 100);
    EXPECT_THROW(pool->for_linked_phases(2, 5, lf, ll, [](int p, index_t c) {
        if (p == 0 && c == 3) throw InvalidArgument("phase 0 chunk 3");
    }), InvalidArgument);
    n = 0;
    pool->for_linked_phases(2, 5, lf, ll, [&](int, index_t) { n.fetch_add(1); });
    EXPECT_EQ(n.load(), 10);
}
