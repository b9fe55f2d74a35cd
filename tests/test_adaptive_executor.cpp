// AdaptiveExecutor: every chunk runs once and phases stay ordered whichever
// mode a site is in; a site goes serial where the wrapped executor is slow
// and stays parallel where the calling thread alone is slow (fake executors
// with millisecond delays, so the verdicts do not hang on timing noise);
// whole Simulator runs on it are bitwise the same as on the wrapped
// executor; bad arguments are refused.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstring>
#include <thread>
#include <vector>

#include "edgefem/core/error.hpp"
#include "edgefem/core/simulator.hpp"
#include "edgefem/parallel/adaptive_executor.hpp"
#include "edgefem/parallel/executors.hpp"
#include "executor_kinds.hpp"
#include "cpu/cpu_operator.hpp"
#include "cantilever.hpp"
#include "test_threads.hpp"

using namespace edgefem;

namespace {

thread_local bool in_fake_parallel = false;

// Runs the chunks on the calling thread, marked as "parallel", after a
// delay that stands for an expensive fork.
class FakeExecutor final : public Executor {
public:
    explicit FakeExecutor(std::chrono::microseconds fork) : fork_(fork) {}
    void set_fork(std::chrono::microseconds fork) { fork_ = fork; }
    int threads() const override { return 2; }
    const char* name() const override { return "fake"; }
    void for_chunks(index_t n, const std::function<void(index_t)>& body) const override {
        std::this_thread::sleep_for(fork_);
        in_fake_parallel = true;
        for (index_t c = 0; c < n; ++c) body(c);
        in_fake_parallel = false;
    }

private:
    std::chrono::microseconds fork_;
};

void busy(std::chrono::microseconds d) {
    const auto end = std::chrono::steady_clock::now() + d;
    while (std::chrono::steady_clock::now() < end) {
    }
}

}  // namespace

TEST(AdaptiveExecutor, EveryChunkOnceAndPhasesInOrder) {
    const std::vector<index_t> chunks{3, 0, 1, 16, 2};
    std::vector<index_t> first{0};
    for (index_t n : chunks) first.push_back(first.back() + n);
    for (ExecutorKind b : test::threaded_executor_kinds())
        for (int t : {2, 3}) {
            const AdaptiveExecutor ex(make_executor(b, t), 2);
            // Past the trial calls, so both modes run.
            for (int call = 0; call < 8; ++call) {
                for (index_t n : {0, 1, 5, 200}) {
                    std::vector<std::atomic<int>> hits(n);
                    ex.for_chunks(n, [&](index_t c) { hits[c].fetch_add(1); });
                    ex.for_uniform_chunks(n, [&](index_t c) { hits[c].fetch_add(1); });
                    for (index_t c = 0; c < n; ++c) ASSERT_EQ(hits[c].load(), 2) << to_string(b) << t << " " << n;
                }
                for (bool uniform : {false, true}) {
                    std::vector<std::vector<std::atomic<int>>> hits;
                    for (index_t n : chunks) hits.emplace_back(n);
                    std::vector<std::atomic<int>> done(chunks.size());
                    std::atomic<int> out_of_order{0};
                    const auto body = [&](int p, index_t c) {
                        for (int q = 0; q < p; ++q)
                            if (done[q].load() != int(chunks[q])) out_of_order.fetch_add(1);
                        hits[p][c].fetch_add(1);
                        done[p].fetch_add(1);
                    };
                    if (uniform)
                        ex.for_uniform_phases(int(chunks.size()), first.data(), body);
                    else
                        ex.for_phases(int(chunks.size()), first.data(), body);
                    ASSERT_EQ(out_of_order.load(), 0);
                    for (std::size_t p = 0; p < chunks.size(); ++p)
                        for (index_t c = 0; c < chunks[p]; ++c) ASSERT_EQ(hits[p][c].load(), 1);
                }
            }
            // 4 loop sites, all decided after 8 calls of 2 trials per mode
            // (n = 0 and 1 never reach a site: nothing to choose).
            const auto sites = ex.sites();
            EXPECT_EQ(sites.size(), 2u * 2 + 2);
            for (const auto& s : sites) {
                EXPECT_TRUE(s.decided) << s.loop;
                EXPECT_GT(s.serial_us, 0) << s.loop;
                EXPECT_GT(s.parallel_us, 0) << s.loop;
            }
        }
}

TEST(AdaptiveExecutor, SlowForkGoesSerial) {
    const AdaptiveExecutor ex(std::make_shared<FakeExecutor>(std::chrono::microseconds(3000)), 2);
    int serial_calls = 0;
    for (int call = 0; call < 10; ++call) {
        bool here = true;
        ex.for_chunks(4, [&](index_t) { here = here && !in_fake_parallel; });
        serial_calls += here;
    }
    // 2 timed calls on the calling thread, then 6 after the verdict.
    EXPECT_EQ(serial_calls, 8);
    const auto sites = ex.sites();
    ASSERT_EQ(sites.size(), 1u);
    EXPECT_TRUE(sites[0].decided && sites[0].faster_serial);
    EXPECT_GT(sites[0].parallel_us, 2000);
    EXPECT_EQ(sites[0].calls, 10);
    EXPECT_TRUE(ex.serial());
    EXPECT_EQ(ex.summary().rfind("serial (1 of 1 loops faster serially; calls x fastest call: ", 0), 0u) << ex.summary();
}

TEST(AdaptiveExecutor, SlowCallingThreadStaysParallel) {
    const AdaptiveExecutor ex(std::make_shared<FakeExecutor>(std::chrono::microseconds(0)), 3);
    int parallel_calls = 0;
    for (int call = 0; call < 10; ++call) {
        bool there = true;
        ex.for_chunks(4, [&](index_t) {
            if (!in_fake_parallel) busy(std::chrono::microseconds(1000));  // the "serial" path is the slow one
            there = there && in_fake_parallel;
        });
        parallel_calls += there;
    }
    EXPECT_EQ(parallel_calls, 7);  // 3 timed serial calls, the rest parallel
    const auto sites = ex.sites();
    ASSERT_EQ(sites.size(), 1u);
    EXPECT_TRUE(sites[0].decided && !sites[0].faster_serial);
    EXPECT_FALSE(ex.serial());
    EXPECT_EQ(ex.summary().rfind("threads (0 of 1 loops faster serially; calls x fastest call: ", 0), 0u) << ex.summary();
}

// One mode for all decided sites: a loop that is faster on the threads
// still runs serially when the loops together are faster serially (the
// sum of calls x fastest call decides).
TEST(AdaptiveExecutor, OneModeForAllSites) {
    const AdaptiveExecutor ex(std::make_shared<FakeExecutor>(std::chrono::microseconds(0)), 3);
    int fast_loop_serial = 0;
    for (int call = 0; call < 10; ++call) {
        ex.for_chunks(2, [](index_t c) {  // serial wins by 2 ms
            if (c == 0 && in_fake_parallel) busy(std::chrono::microseconds(2000));
        });
        bool here = true;
        ex.for_chunks(3, [&](index_t c) {  // threads win by 1 ms
            if (c == 0 && !in_fake_parallel) busy(std::chrono::microseconds(1000));
            here = here && !in_fake_parallel;
        });
        fast_loop_serial += here && call >= 6;  // past the 3 + 3 trial calls
    }
    // Serial: 0 + 1 ms per call of both; threads: 2 + 0 ms.
    EXPECT_TRUE(ex.serial()) << ex.summary();
    EXPECT_EQ(fast_loop_serial, 4);
    EXPECT_EQ(ex.summary().rfind("serial (1 of 2 loops faster serially", 0), 0u) << ex.summary();
}

// When the machine changes, the next round of trials follows it: serial
// while the fork is slow, back on the threads once the calling thread is
// the slow one (rounds after 40 calls, then 80).
TEST(AdaptiveExecutor, RetrialFollowsTheMachine) {
    auto fake = std::make_shared<FakeExecutor>(std::chrono::microseconds(1000));
    const AdaptiveExecutor ex(fake, 2, 40);
    bool slow_here = false;
    const auto call = [&] {
        bool here = true;
        ex.for_chunks(2, [&](index_t c) {
            if (c == 0 && slow_here && !in_fake_parallel) busy(std::chrono::microseconds(1000));
            here = here && !in_fake_parallel;
        });
        return here;
    };
    for (int k = 0; k < 20; ++k) call();
    EXPECT_TRUE(ex.serial());
    fake->set_fork(std::chrono::microseconds(0));
    slow_here = true;
    for (int k = 0; k < 30; ++k) call();  // past call 41: trials again
    EXPECT_FALSE(ex.serial()) << ex.summary();
    EXPECT_FALSE(call());
    EXPECT_EQ(ex.sites().at(0).rounds, 2);
}

// Distinct loops (lambda types) and chunk counts are distinct sites.
TEST(AdaptiveExecutor, SitesByLoopAndSize) {
    const AdaptiveExecutor ex(std::make_shared<FakeExecutor>(std::chrono::microseconds(0)), 1);
    for (int call = 0; call < 3; ++call) {
        ex.for_chunks(4, [](index_t) {});
        ex.for_chunks(5, [](index_t) {});
        ex.for_chunks(4, [](index_t) {});  // another lambda
    }
    EXPECT_EQ(ex.sites().size(), 3u);
}

// A caller whose chunk counts never repeat does not grow the records
// without bound (4096 sites), and its chunks still all run.
TEST(AdaptiveExecutor, SiteRecordsAreBounded) {
    const AdaptiveExecutor ex(std::make_shared<FakeExecutor>(std::chrono::microseconds(0)));
    long hits = 0, expected = 0;
    for (index_t n = 2; n < 5002; ++n) {
        ex.for_chunks(n, [&](index_t) { ++hits; });
        expected += n;
    }
    EXPECT_EQ(hits, expected);
    EXPECT_EQ(ex.sites().size(), 4096u);
}

// A whole simulation on the adaptive executor: bitwise the step of the
// wrapped executor, for the deterministic variants, whatever it chose.
TEST(AdaptiveExecutor, SimulatorStepsBitwiseUnchanged) {
    Scene scene = edgefem::test::clamped_box_scene(8, 3, 3);
    scene.integrator = Integrator::SemiImplicit;
    scene.dt = 2e-3;
    scene.solver.cg_tolerance = 1e-10;
    for (Method method : {Method::Edge, Method::Tet}) {
        scene.method = method;
        for (Variant var : {Variant::Auto, Variant::Colour, Variant::Gather})
            for (int t : {2, 3}) {
                const auto plain = make_executor(ExecutorKind::OpenMP, t);
                const auto adaptive = std::make_shared<AdaptiveExecutor>(plain, 1);
                Simulator<double> a(scene, plain, cpu_operator_factory<double>({plain, var}));
                Simulator<double> b(scene, adaptive, cpu_operator_factory<double>({adaptive, var}));
                for (int k = 0; k < 6; ++k) {
                    a.step();
                    b.step();
                }
                const std::string where = std::string(method == Method::Edge ? "edge/" : "tet/") + to_string(var) +
                                          "/" + std::to_string(t);
                ASSERT_EQ(a.displacement().size(), b.displacement().size());
                EXPECT_EQ(std::memcmp(a.displacement().data(), b.displacement().data(),
                                      a.displacement().size() * sizeof(double)),
                          0)
                    << where;
                EXPECT_EQ(std::memcmp(a.velocity().data(), b.velocity().data(), a.velocity().size() * sizeof(double)),
                          0)
                    << where;
                int decided = 0;
                for (const auto& s : adaptive->sites()) decided += s.decided;
                EXPECT_GT(decided, 0) << where;
            }
    }
}

TEST(AdaptiveExecutor, BadArguments) {
    EXPECT_THROW(AdaptiveExecutor(nullptr), InvalidArgument);
    EXPECT_THROW(AdaptiveExecutor(make_executor(ExecutorKind::OpenMP, 2), 0), InvalidArgument);
    EXPECT_THROW(AdaptiveExecutor(make_executor(ExecutorKind::OpenMP, 2), 3, 0), InvalidArgument);
    EXPECT_THROW(make_adaptive(make_executor(ExecutorKind::OpenMP, 2), -1), InvalidArgument);
    // One thread: nothing to choose, the executor itself comes back.
    const auto serial = make_executor(ExecutorKind::Serial);
    EXPECT_EQ(make_adaptive(serial).get(), serial.get());
    const auto two = make_executor(ExecutorKind::TBB, 2);
    const auto wrapped = make_adaptive(two);
    EXPECT_NE(wrapped.get(), two.get());
    EXPECT_EQ(wrapped->threads(), 2);
    EXPECT_STREQ(wrapped->name(), "tbb");
}
