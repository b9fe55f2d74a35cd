// The library's entry points against a caller's mistakes (issues #26, #27):
// every operator factory and write_vtu refuse tets whose indices a kernel
// would follow outside its arrays (MeshError naming the tet, not a crash or
// an "internal" error); a non-finite value the application wrote into the
// state or the loads is named as bad input (InvalidArgument), not reported
// as an instability; and a simulator used from two threads at once throws
// instead of racing.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <condition_variable>
#include <filesystem>
#include <limits>
#include <mutex>
#include <string>
#include <thread>

#include "edgefem/core/elastic_operator.hpp"
#include "edgefem/core/error.hpp"
#include "edgefem/core/make_box.hpp"
#include "edgefem/core/reference_operator.hpp"
#include "edgefem/core/simulator.hpp"
#include "edgefem/core/write_vtu.hpp"
#include "edgefem/parallel/cpu_backend.hpp"
#include "edgefem/parallel/executors.hpp"
#include "edgefem/parallel/run_options.hpp"
#include "cantilever.hpp"
#include "forwarding_operator.hpp"

using namespace edgefem;

namespace {

// make_box(2, 2, 2) with tet 5's vertex `k` replaced by `value`.
Mesh box_with_index(int k, index_t value) {
    Mesh m = make_box(2, 2, 2);
    m.tets[4 * 5 + k] = value;
    return m;
}

template <class Call>
std::string mesh_error_of(Call&& call) {
    try {
        call();
    } catch (const MeshError& e) {
        return e.what();
    } catch (const std::exception& e) {
        ADD_FAILURE() << "not a MeshError: " << e.what();
        return "";
    }
    ADD_FAILURE() << "accepted";
    return "";
}

}  // namespace

TEST(EntryPointGuards, OperatorFactoriesRejectIndicesOutsideTheMesh) {
    const Materials mat(Material{});
    const struct {
        Mesh mesh;
        const char* what;
    } cases[] = {
        {box_with_index(3, -5), "-5"},
        {box_with_index(2, 27), "27"},  // 27 vertices: one past the end
        {box_with_index(1, 1000), "1000"},
        {box_with_index(3, make_box(2, 2, 2).tets[4 * 5 + 0]), "twice"},  // a repeated vertex
    };
    for (const auto& c : cases)
        for (const Method method : {Method::Edge, Method::Tet}) {
            const std::string ref = mesh_error_of(
                [&] { make_reference_operator<double>(c.mesh, mat, ModelKind::FE, method); });
            const std::string cpu =
                mesh_error_of([&] { make_cpu_operator<double>(c.mesh, mat, ModelKind::FE, method); });
            const std::string pool = mesh_error_of([&] {
                make_cpu_operator<double>(c.mesh, mat, ModelKind::FE, method, {make_executor(ExecutorKind::Pool, 2)});
            });
            for (const std::string& msg : {ref, cpu, pool}) {
                EXPECT_NE(msg.find("tet 5"), std::string::npos) << msg;
                EXPECT_NE(msg.find(c.what), std::string::npos) << msg;
                EXPECT_EQ(msg.find("internal"), std::string::npos) << msg;
            }
        }
    // A float32 operator too, and the spring network.
    mesh_error_of([&] { make_cpu_operator<float>(cases[0].mesh, mat, ModelKind::SN, Method::Edge); });
}

TEST(EntryPointGuards, WriteVtuRejectsConnectivityOutsideTheMesh) {
    const auto path = std::filesystem::temp_directory_path() / "edgefem_guard_bad_connectivity.vtu";
    std::filesystem::remove(path);
    const std::string msg = mesh_error_of([&] { write_vtu(path.string(), box_with_index(0, 99)); });
    EXPECT_NE(msg.find("99"), std::string::npos) << msg;
    EXPECT_FALSE(std::filesystem::exists(path));
}

namespace {

// A non-finite value written into one of the simulator's inputs: named.
template <class Sim>
void expect_named_as_input(Sim& sim, std::span<double> (Sim::*view)(), const char* name, index_t vertex) {
    const auto a = (sim.*view)();
    const double saved = a[3 * std::size_t(vertex) + 1];
    a[3 * std::size_t(vertex) + 1] = std::numeric_limits<double>::quiet_NaN();
    for (int call = 0; call < 3; ++call) {
        try {
            if (call == 0) sim.step();
            if (call == 1) sim.solve_static();
            if (call == 2) sim.energies();
            ADD_FAILURE() << name << ": accepted";
        } catch (const InvalidArgument& e) {
            const std::string msg = e.what();
            EXPECT_NE(msg.find(name), std::string::npos) << msg;
            EXPECT_NE(msg.find("vertex " + std::to_string(vertex)), std::string::npos) << msg;
        } catch (const std::exception& e) {
            ADD_FAILURE() << name << ": not an InvalidArgument: " << e.what();
        }
    }
    a[3 * std::size_t(vertex) + 1] = saved;
    EXPECT_NO_THROW(sim.step());
}

}  // namespace

TEST(EntryPointGuards, NonFiniteInputsAreNamedNotReportedAsInstability) {
    const Scene scene = test::cantilever_scene();
    Simulator<double> core(scene);
    expect_named_as_input(core, &Simulator<double>::external_forces, "external_forces", 17);
    expect_named_as_input(core, &Simulator<double>::velocity, "velocity", 20);
    expect_named_as_input(core, &Simulator<double>::displacement, "displacement", 30);
    // In the user's numbering when the simulator runs on another one.
    RunOptions run;
    run.ordering = "random";
    const auto ordered = make_simulator<double>(scene, run);
    ASSERT_FALSE(ordered->new_of_old().empty());
    expect_named_as_input(*ordered, &OrderedSimulator<double>::external_forces, "external_forces", 17);
    expect_named_as_input(*ordered, &OrderedSimulator<double>::velocity, "velocity", 20);
}

namespace {

// The wrapped operator, whose forces() can be held until released: a step
// stays inside the simulator as long as the test wants.
class GateOperator final : public test::ForwardingOperator {
public:
    struct Gate {
        std::mutex m;
        std::condition_variable cv;
        bool armed = false, entered = false, open = false;
    };
    GateOperator(std::unique_ptr<ElasticOperator<double>> op, Gate& gate) : ForwardingOperator(std::move(op)), g_(gate) {}
    double forces(const double* u, double* f, bool energy) override {
        std::unique_lock lock(g_.m);
        if (g_.armed) {
            g_.entered = true;
            g_.cv.notify_all();
            g_.cv.wait(lock, [&] { return g_.open; });
        }
        lock.unlock();
        return op_->forces(u, f, energy);
    }

private:
    Gate& g_;
};

// Holds a step of `sim` inside the operator on another thread while `second`
// runs on this one; returns what `second` threw ("" when nothing).
template <class Sim, class Second>
std::string while_stepping(Sim& sim, GateOperator::Gate& gate, Second&& second) {
    {
        std::lock_guard lock(gate.m);
        gate.armed = true;
        gate.entered = gate.open = false;
    }
    std::string first_error;
    std::thread first([&] {
        try {
            sim.step();
        } catch (const std::exception& e) {
            first_error = e.what();
        }
    });
    {
        std::unique_lock lock(gate.m);
        gate.cv.wait(lock, [&] { return gate.entered; });
    }
    std::string error;
    try {
        second();
    } catch (const InvalidArgument& e) {
        error = e.what();
    }
    {
        std::lock_guard lock(gate.m);
        gate.open = true;
        gate.armed = false;
    }
    gate.cv.notify_all();
    first.join();
    EXPECT_EQ(first_error, "");
    return error;
}

}  // namespace

TEST(EntryPointGuards, ASimulatorUsedFromTwoThreadsAtOnceThrows) {
    GateOperator::Gate gate;
    const OperatorFactory<double> factory = [&gate](const Mesh& m, const Materials& mat, ModelKind k, Method me)
        -> std::unique_ptr<ElasticOperator<double>> {
        return std::make_unique<GateOperator>(make_cpu_operator<double>(m, mat, k, me), gate);
    };
    const Scene scene = test::cantilever_scene();
    Simulator<double> core(scene, nullptr, factory);
    for (int call = 0; call < 3; ++call) {
        const std::string msg = while_stepping(core, gate, [&] {
            if (call == 0) core.step();
            if (call == 1) core.solve_static();
            if (call == 2) core.energies();
        });
        EXPECT_NE(msg.find("one thread at a time"), std::string::npos) << msg;
    }
    EXPECT_EQ(core.step_index(), 3);  // the held steps completed; the refused calls did nothing
    // Another simulator is independent: it steps while the first is busy.
    Simulator<double> other(scene);
    EXPECT_EQ(while_stepping(core, gate, [&] { other.step(); }), "");

    OrderedSimulator<double> ordered(scene, Ordering::Random, nullptr, factory);
    const std::string msg = while_stepping(ordered, gate, [&] { ordered.step(); });
    EXPECT_NE(msg.find("one thread at a time"), std::string::npos) << msg;
    EXPECT_EQ(ordered.step_index(), 1);
    // Calls one after the other are fine.
    ordered.step();
    EXPECT_EQ(ordered.step_index(), 2);
}
