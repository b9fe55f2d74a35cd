// Executors: every chunk runs exactly once, blocked sums are bitwise the
// same for any back-end and thread count, names parse and print.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <vector>

#include "edgefem/core/error.hpp"
#include "edgefem/parallel/executors.hpp"
#include "edgefem/parallel/variant.hpp"

using namespace edgefem;

TEST(Executors, EveryChunkOnce) {
    for (Backend b : {Backend::Serial, Backend::OpenMP, Backend::TBB})
        for (int t : {1, 2, 3, 8})
            for (Schedule s : {Schedule::Static, Schedule::Dynamic}) {
                const auto ex = make_executor(b, t, s);
                EXPECT_EQ(ex->threads(), b == Backend::Serial ? 1 : t);
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
    for (Backend b : {Backend::Serial, Backend::OpenMP, Backend::TBB})
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

TEST(Executors, BlockedSumIndependentOfThreads) {
    const std::size_t n = 100003;
    std::vector<double> a(n);
    for (std::size_t i = 0; i < n; ++i) a[i] = std::sin(0.37 * double(i)) * std::exp(double(i % 97) / 7);
    const double ref = blocked_sum(SerialExecutor{}, n, [&](std::size_t i) { return a[i]; });
    for (Backend b : {Backend::OpenMP, Backend::TBB})
        for (int t : {1, 2, 3, 4, 8}) {
            const auto ex = make_executor(b, t);
            EXPECT_EQ(blocked_sum(*ex, n, [&](std::size_t i) { return a[i]; }), ref);
        }
}

TEST(Executors, Names) {
    EXPECT_EQ(parse_backend("serial"), Backend::Serial);
    EXPECT_EQ(parse_backend("omp"), Backend::OpenMP);
    EXPECT_EQ(parse_backend("openmp"), Backend::OpenMP);
    EXPECT_EQ(parse_backend("tbb"), Backend::TBB);
    EXPECT_THROW(parse_backend("cuda"), InvalidArgument);
    for (Backend b : {Backend::Serial, Backend::OpenMP, Backend::TBB}) EXPECT_EQ(parse_backend(to_string(b)), b);
    for (Variant v : kAllVariants)
        EXPECT_EQ(parse_variant(to_string(v)), v);
    EXPECT_EQ(parse_variant("color"), Variant::Colour);
    EXPECT_THROW(parse_variant("mutex"), InvalidArgument);
    EXPECT_EQ(parse_schedule("static"), Schedule::Static);
    EXPECT_STREQ(make_executor(Backend::TBB, 2)->name(), "tbb");
    EXPECT_STREQ(make_executor(Backend::OpenMP, 2)->name(), "omp");
}

// Two TBB executors with different thread counts coexist (each its arena).
TEST(Executors, IndependentArenas) {
    const auto a = make_executor(Backend::TBB, 2), b = make_executor(Backend::TBB, 3);
    std::atomic<int> n{0};
    a->for_chunks(10, [&](index_t) { b->for_chunks(5, [&](index_t) { n.fetch_add(1); }); });
    EXPECT_EQ(n.load(), 50);
}
