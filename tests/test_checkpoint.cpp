// Checkpoints (edgefem/core/checkpoint.hpp): 2N steps straight and N steps,
// a checkpoint, a new simulator loading it and N more steps give bitwise the
// same displacement and velocity, for every integrator, float and double,
// with damping, prescribed vertices, the lagged K and the AMG refreshed
// every 2nd K, on the reference back-end and the CPU back-end's pool and
// OpenMP executors at 2 threads; a checkpoint that cannot be read, or not
// into this simulator, is a CheckpointError naming the difference and
// leaves the state unchanged.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <numeric>
#include <string>
#include <type_traits>
#include <vector>

#include "cantilever.hpp"
#include "edgefem/core/checkpoint.hpp"
#include "edgefem/core/make_box.hpp"
#include "edgefem/core/simulator.hpp"
#include "edgefem/parallel/run_options.hpp"
#include "edgefem/partition/ordered_simulator.hpp"
#include "io_test_util.hpp"
#include "models.hpp"

namespace edgefem {
namespace {

using test::bitwise_equal;

constexpr int kHalf = 5;  // steps before and after the checkpoint



struct Case {
    std::string name;
    Integrator integrator;
    bool damping_and_prescribed = false;
    int amg_refresh = -1;  // >= 0: AMG with this refresh interval
    int stiffness_interval = 1;
    int auto_threshold = 0;  // > 0: the auto preconditioner with this threshold (else block-Jacobi)
};

// 8 x 3 x 3 cubes (144 vertices: the AMG gets one coarse level), clamped at
// x = min, under gravity. CG to 1e-8, or 1e-6 for a float model: its
// operator's products carry round-off of ~1e-7 relative (the assembled A of
// bdf2_linear_amg2 is symmetric to 2.6e-8 only), so whether CG gets below
// that is luck (it stalled at 1e-5 after a change of the Galerkin
// product's summation order of 1e-16).
Scene case_scene(const Case& c, bool single = false) {
    Scene s = test::clamped_box_scene(8, 3, 3);
    s.integrator = c.integrator;
    s.dt = is_explicit(c.integrator) ? 5e-4 : 2e-3;
    s.solver.cg_tolerance = single ? 1e-6 : 1e-8;
    s.solver.cg_max_iterations = 2000;
    if (c.damping_and_prescribed) {
        s.rayleigh_alpha = 0.5;
        if (c.integrator != Integrator::Verlet) s.rayleigh_beta = 2e-3;
        double xmax = -1;
        for (index_t v = 0; v < s.mesh.num_vertices(); ++v) xmax = std::max(xmax, s.mesh.X[3 * v]);
        for (index_t v = 0; v < s.mesh.num_vertices(); ++v)
            if (s.mesh.X[3 * v] > xmax - 1e-9)
                s.prescribed.push_back({v, {s.mesh.X[3 * v] + 0.004, s.mesh.X[3 * v + 1], s.mesh.X[3 * v + 2] + 0.01}});
        s.prescribed_steps = 2 * kHalf + 3;  // still ramping at the checkpoint
    }
    s.solver.preconditioner = PreconditionerKind::BlockJacobi;
    if (c.amg_refresh >= 0) {
        s.solver.preconditioner = PreconditionerKind::Amg;
        s.solver.amg_refresh_interval = c.amg_refresh;
    }
    if (c.auto_threshold > 0) {
        s.solver.preconditioner = PreconditionerKind::Auto;
        s.solver.auto_amg_iterations = c.auto_threshold;
    }
    s.solver.stiffness_interval = c.stiffness_interval;
    return s;
}

std::vector<Case> cases() {
    const std::pair<Integrator, const char*> all[] = {
        {Integrator::Explicit, "explicit"},
        {Integrator::Verlet, "verlet"},
        {Integrator::SemiImplicit, "semi_implicit"},
        {Integrator::Implicit, "implicit"},
        {Integrator::Newmark, "newmark"},
        {Integrator::NewmarkLinear, "newmark_linear"},
        {Integrator::GeneralizedAlpha, "generalized_alpha"},
        {Integrator::GeneralizedAlphaLinear, "generalized_alpha_linear"},
        {Integrator::Bdf2, "bdf2"},
        {Integrator::Bdf2Linear, "bdf2_linear"},
    };
    std::vector<Case> out;
    for (const auto& [integrator, name] : all) {
        out.push_back({name, integrator});
        out.push_back({std::string(name) + "_damped_prescribed", integrator, true});
        if (!is_explicit(integrator)) out.push_back({std::string(name) + "_amg2", integrator, true, 2});
    }
    out.push_back({"semi_implicit_lagged3", Integrator::SemiImplicit, true, -1, 3});
    out.push_back({"semi_implicit_lagged3_amg2", Integrator::SemiImplicit, true, 2, 3});
    out.push_back({"newmark_linear_amg_lagged", Integrator::NewmarkLinear, false, 0});
    // auto: AMG takes over after the first solve (threshold 1), before the
    // checkpoint; with a threshold no solve reaches, block-Jacobi throughout.
    out.push_back({"semi_implicit_auto_switch", Integrator::SemiImplicit, true, -1, 1, 1});
    out.push_back({"bdf2_linear_auto_switch", Integrator::Bdf2Linear, true, -1, 1, 1});
    out.push_back({"semi_implicit_auto_stays", Integrator::SemiImplicit, true, -1, 1, 100000});
    return out;
}

template <class S>
struct State {
    std::vector<S> u, v;
    double time;
    long step;
};

template <class Sim>
auto state_of(Sim& sim) {
    using S = typename std::remove_reference_t<decltype(sim.displacement())>::value_type;
    const auto u = sim.displacement(), v = sim.velocity();
    return State<S>{{u.begin(), u.end()}, {v.begin(), v.end()}, sim.time(), sim.step_index()};
}

template <class S>
void expect_same(const State<S>& a, const State<S>& b, const std::string& what) {
    EXPECT_TRUE(bitwise_equal(a.u, b.u)) << what << ": displacement, max rel diff " << test::rel_diff(a.u, b.u);
    EXPECT_TRUE(bitwise_equal(a.v, b.v)) << what << ": velocity, max rel diff " << test::rel_diff(a.v, b.v);
    EXPECT_EQ(a.time, b.time) << what;
    EXPECT_EQ(a.step, b.step) << what;
}

// make() gives a new simulator of the scene each time.
template <class Make>
void check_restart(const Make& make, const std::string& path, const std::string& what) {
    auto straight = make();
    for (int k = 0; k < 2 * kHalf; ++k) straight->step();
    auto first = make();
    for (int k = 0; k < kHalf; ++k) first->step();
    first->save_checkpoint(path);
    auto resumed = make();
    resumed->load_checkpoint(path);
    for (int k = 0; k < kHalf; ++k) resumed->step();
    expect_same(state_of(*straight), state_of(*resumed), what);
    // The simulator that wrote the checkpoint continues the same way too.
    for (int k = 0; k < kHalf; ++k) first->step();
    expect_same(state_of(*straight), state_of(*first), what + " (the writer)");
}

template <class S>
class CheckpointRestart : public ::testing::Test {};
using Scalars = ::testing::Types<double, float>;
TYPED_TEST_SUITE(CheckpointRestart, Scalars);

TYPED_TEST(CheckpointRestart, ReferenceBackendEveryIntegrator) {
    using S = TypeParam;
    test::TempDir dir("ckpt_ref");
    for (const Case& c : cases()) {
        const Scene scene = case_scene(c, std::is_same_v<S, float>);
        check_restart([&] { return std::make_unique<Simulator<S>>(scene); }, dir.file(c.name + ".ckpt"), c.name);
    }
}

// The program's, the Python module's and the C API's simulator: RCM
// ordering, the CPU back-end at 2 threads, adaptive (its timing-based
// choice of loops does not change the bits). Every integrator with damping
// and prescribed vertices, the lagged K, and the AMG with three of them
// (the AMG's own code is the same on every back-end).
std::vector<Case> cpu_cases() {
    std::vector<Case> out;
    for (const Case& c : cases())
        if (c.damping_and_prescribed && (c.amg_refresh < 0 || c.integrator == Integrator::Newmark ||
                                         c.integrator == Integrator::Bdf2Linear || c.stiffness_interval > 1 ||
                                         c.auto_threshold > 0))
            out.push_back(c);
    return out;
}

template <class S>
void check_cpu(const char* executor) {
    test::TempDir dir(std::string("ckpt_") + executor);
    RunOptions run;
    run.backend = executor;
    run.threads = 2;
    for (const Case& c : cpu_cases()) {
        const Scene scene = case_scene(c, std::is_same_v<S, float>);
        check_restart([&] { return make_simulator<S>(scene, run); }, dir.file(c.name + ".ckpt"),
                      std::string(executor) + " " + c.name);
    }
}

TYPED_TEST(CheckpointRestart, PoolTwoThreads) { check_cpu<TypeParam>("pool"); }
TYPED_TEST(CheckpointRestart, OpenMPTwoThreads) { check_cpu<TypeParam>("omp"); }

// What the checkpoint holds beyond u, v and time matters: a new simulator
// given only those diverges where the integrator has a history (the
// semi-implicit step's too: the last velocity, for CG's warm start) or the
// solver a set-up that outlives a step (so the tests above can fail), and
// continues bitwise where neither has one (backward Euler by Newton).
TEST(Checkpoint, HistoryAndSetUpsMatter) {
    for (const Case& c : {Case{"bdf2", Integrator::Bdf2}, Case{"newmark", Integrator::Newmark},
                          Case{"semi-implicit", Integrator::SemiImplicit},
                          Case{"lagged", Integrator::SemiImplicit, false, -1, 3},
                          Case{"amg2", Integrator::SemiImplicit, false, 2},
                          Case{"memoryless", Integrator::Implicit}}) {
        const Scene scene = case_scene(c);
        Simulator<double> straight(scene), copied(scene);
        for (int k = 0; k < kHalf; ++k) straight.step();
        std::ranges::copy(straight.displacement(), copied.displacement().begin());
        std::ranges::copy(straight.velocity(), copied.velocity().begin());
        for (int k = 0; k < kHalf; ++k) {
            straight.step();
            copied.step();
        }
        const auto a = state_of(straight), b = state_of(copied);
        EXPECT_EQ(bitwise_equal(a.u, b.u) && bitwise_equal(a.v, b.v), c.name == "memoryless") << c.name;
    }
}

// A scene for the error tests, and a checkpoint of it after 3 steps.
Scene error_scene(Integrator integrator = Integrator::Bdf2) {
    Scene s = test::clamped_box_scene(4, 2, 2);
    s.integrator = integrator;
    return s;
}

// A simulator of error_scene() after 3 steps, its checkpoint written to `path`.
Simulator<double> checkpointed(const std::string& path) {
    Simulator<double> sim(error_scene());
    for (int k = 0; k < 3; ++k) sim.step();
    sim.save_checkpoint(path);
    return sim;
}

std::string read_bytes(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), {}};
}
void write_bytes(const std::string& path, const std::string& bytes) {
    std::ofstream(path, std::ios::binary) << bytes;
}

// Loading `path` into `sim` throws CheckpointError whose message contains
// each of `parts`, and leaves the state as it was.
template <class Sim>
void expect_refused(Sim& sim, const std::string& path, const std::vector<std::string>& parts) {
    const auto before = state_of(sim);
    try {
        sim.load_checkpoint(path);
        ADD_FAILURE() << "loaded " << path;
    } catch (const CheckpointError& e) {
        for (const auto& p : parts) EXPECT_NE(std::string(e.what()).find(p), std::string::npos) << e.what() << " / " << p;
        EXPECT_EQ(e.path(), path);
    }
    expect_same(before, state_of(sim), "after a refused load");
}

TEST(Checkpoint, RefusesAnotherMeshIntegratorScalarOrNumbering) {
    test::TempDir dir("ckpt_mismatch");
    const std::string path = dir.file("a.ckpt");
    checkpointed(path);

    Simulator<double> integ(error_scene(Integrator::Newmark));
    integ.step();
    expect_refused(integ, path, {"integrator 'bdf2'", "'newmark'", path});

    Scene bigger = error_scene();
    bigger.mesh = make_box(5, 2, 2);
    Simulator<double> mesh(bigger);
    expect_refused(mesh, path, {"mesh of 45 vertices", "has 54"});

    Scene moved = error_scene();
    for (double& x : moved.mesh.X) x *= 1.01;
    Simulator<double> same_size(moved);
    expect_refused(same_size, path, {"another mesh of the same size"});

    Simulator<float> single(error_scene());
    expect_refused(single, path, {"scalar type 'double'", "'float'"});

    Scene amg = error_scene();
    amg.solver.preconditioner = PreconditionerKind::Amg;
    Simulator<double> solver(amg);
    expect_refused(solver, path, {"solver 'cg/auto'", "'cg/amg'"});

    // An OrderedSimulator's state is in its ordering's numbering.
    RunOptions rcm;
    rcm.backend = "serial";
    auto ordered = make_simulator<double>(error_scene(), rcm);
    expect_refused(*ordered, path, {"vertex numbering ''", "'rcm'"});
    ordered->save_checkpoint(path);
    RunOptions morton = rcm;
    morton.ordering = "morton";
    auto other = make_simulator<double>(error_scene(), morton);
    expect_refused(*other, path, {"vertex numbering 'rcm'", "'morton'"});
}

TEST(Checkpoint, RefusesMissingTruncatedCorruptAndForeignFiles) {
    test::TempDir dir("ckpt_corrupt");
    const std::string path = dir.file("a.ckpt");
    Simulator<double> sim = checkpointed(path);
    const std::string good = read_bytes(path);
    ASSERT_GT(good.size(), 100u);

    expect_refused(sim, dir.file("missing.ckpt"), {"cannot be opened", "No such file"});

    // Cut anywhere: the header's length says so (or, in the header itself,
    // it is not a checkpoint).
    for (const std::size_t keep : {std::size_t(0), std::size_t(10), std::size_t(30), good.size() / 2, good.size() - 1}) {
        write_bytes(path, good.substr(0, keep));
        expect_refused(sim, path, {keep < 20 ? "not an edgefem checkpoint" : "truncated"});
    }
    write_bytes(path, good + "x");
    expect_refused(sim, path, {"data appended"});

    // Any byte flipped after the header is caught by the checksum.
    for (const std::size_t at : {std::size_t(20), std::size_t(40), good.size() / 3, good.size() - 9, good.size() - 1}) {
        std::string bad = good;
        bad[at] = char(bad[at] ^ 0x10);
        write_bytes(path, bad);
        expect_refused(sim, path, {"corrupt: the checksum does not match"});
    }
    std::string version = good;
    version[8] = 7;
    write_bytes(path, version);
    expect_refused(sim, path, {"format version 7"});

    write_bytes(path, "<?xml version=\"1.0\"?> not a checkpoint at all");
    expect_refused(sim, path, {"not an edgefem checkpoint"});
    expect_refused(sim, dir.path(), {"checkpoint"});  // a folder

    // The good file still loads after all that.
    write_bytes(path, good);
    Simulator<double> fresh(error_scene());
    fresh.load_checkpoint(path);
    expect_same(state_of(sim), state_of(fresh), "the good file");
}

TEST(Checkpoint, WriteFailureIsIoErrorAndKeepsTheOldFile) {
    test::TempDir dir("ckpt_write");
    Simulator<double> sim(error_scene());
    EXPECT_THROW(sim.save_checkpoint(dir.file("no/such/folder/a.ckpt")), IoError);
    const std::string path = dir.file("a.ckpt");
    sim.save_checkpoint(path);
    sim.step();
    EXPECT_THROW(sim.save_checkpoint(dir.path()), IoError);  // a folder at the name
    Simulator<double> fresh(error_scene());
    fresh.load_checkpoint(path);
    EXPECT_EQ(fresh.step_index(), 0);
}

// A lagged AMG rebuilt (on its first build's aggregates) before the
// checkpoint: loading builds at the first point, rebuilds at the second and
// refreshes at the last, and the run goes on bitwise. A free box spinning
// about z (half a turn in 12 implicit steps of 20 ms): the rest shape's
// hierarchy, refreshed on the turned body, needs more than 1.5x its
// iterations, and the AMG rebuilds within the first 10 steps (seen with a
// probe; a loader that skips the rebuild differs by 1e-14 here).
TEST(Checkpoint, LaggedAmgRebuiltBeforeTheCheckpoint) {
    Scene s;
    s.mesh = make_box(8, 3, 3);
    s.materials = Material{1e6, 0.3, 1000};
    s.gravity = {0, 0, 0};
    s.integrator = Integrator::Implicit;
    s.dt = 20e-3;
    s.solver.cg_tolerance = 1e-8;
    s.solver.cg_max_iterations = 2000;
    s.solver.preconditioner = PreconditionerKind::Amg;
    s.solver.amg_refresh_interval = 0;
    double c[3] = {0, 0, 0};
    const std::size_t n = s.mesh.X.size();
    for (std::size_t i = 0; i < n; ++i) c[i % 3] += s.mesh.X[i] / double(n / 3);
    const double omega = 3.14159265358979 / (12 * s.dt);
    s.initial_velocity.assign(n, 0.0);
    for (std::size_t i = 0; i < n; i += 3) {
        s.initial_velocity[i] = -omega * (s.mesh.X[i + 1] - c[1]);
        s.initial_velocity[i + 1] = omega * (s.mesh.X[i] - c[0]);
    }
    test::TempDir dir("ckpt_rebuild");
    const std::string path = dir.file("rebuilt.ckpt");
    const int half = 10;
    Simulator<double> straight(s), first(s);
    for (int k = 0; k < 2 * half; ++k) straight.step();
    for (int k = 0; k < half; ++k) first.step();
    first.save_checkpoint(path);
    Simulator<double> resumed(s);
    resumed.load_checkpoint(path);
    for (int k = 0; k < half; ++k) resumed.step();
    expect_same(state_of(straight), state_of(resumed), "resumed");
}

// auto's state across a checkpoint written while block-Jacobi waits out
// its hold after going back (the soft box of
// Solvers.AutoPreconditionerGoesBackWhereAmgRefreshesEveryStep: AMG in
// steps 1-6, block-Jacobi from step 7, the AMG tried again from step 14):
// the resumed run tries it again in the same step, with the same bits.
TEST(Checkpoint, AutoPreconditionerWaitingToTryTheAmgAgain) {
    Scene s = test::clamped_box_scene(24, 6, 6, 1e4);
    s.dt = 33e-3;
    s.solver.cg_max_iterations = 5000;
    test::TempDir dir("ckpt_auto_wait");
    const std::string path = dir.file("waiting.ckpt");
    const int before = 10, after = 10;
    Simulator<double> straight(s), first(s);
    std::vector<int> straight_refreshes;
    for (int k = 0; k < before + after; ++k) straight_refreshes.push_back(straight.step().preconditioner_refreshes);
    for (int k = 0; k < before; ++k) first.step();
    first.save_checkpoint(path);
    Simulator<double> resumed(s);
    resumed.load_checkpoint(path);
    std::vector<int> resumed_refreshes;
    for (int k = 0; k < after; ++k) resumed_refreshes.push_back(resumed.step().preconditioner_refreshes);
    ASSERT_GT(std::accumulate(straight_refreshes.begin() + before, straight_refreshes.end(), 0), 0)
        << "the AMG tried again after the checkpoint";
    EXPECT_EQ(std::vector<int>(straight_refreshes.begin() + before, straight_refreshes.end()), resumed_refreshes);
    expect_same(state_of(straight), state_of(resumed), "resumed");
}

// A run checkpointed while it remembers a step halving (the nearly
// incompressible bar under the linearised generalized-alpha: its first
// halving, then 4 steps into the hold) goes on halved after a restart, with
// the same bits as the straight run; it fails if the halving state is not
// restored (the resumed run starts with whole steps).
TEST(Checkpoint, RememberedStepHalving) {
    const Scene s = test::bent_incompressible_bar(Integrator::GeneralizedAlphaLinear, 0.8, 3);
    test::TempDir dir("ckpt_halving");
    const std::string path = dir.file("halved.ckpt");
    Simulator<double> straight(s), first(s);
    int before = 0;
    while (first.step().halvings == 0) ASSERT_LT(++before, 1000) << "no halving";
    for (int k = 0; k < 4; ++k) ASSERT_EQ(first.step().halvings, 0);
    before += 5;
    first.save_checkpoint(path);
    for (int k = 0; k < before; ++k) straight.step();
    Simulator<double> resumed(s);
    resumed.load_checkpoint(path);
    std::vector<int> straight_depths, resumed_depths;
    for (int k = 0; k < 40; ++k) {
        straight_depths.push_back(straight.step().substep_depth);
        resumed_depths.push_back(resumed.step().substep_depth);
    }
    EXPECT_GT(straight_depths.front(), 0) << "halved after the checkpoint";
    EXPECT_EQ(straight_depths, resumed_depths);
    expect_same(state_of(straight), state_of(resumed), "resumed");
}

}  // namespace
}  // namespace edgefem
