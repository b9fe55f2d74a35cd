// Every back-end against the reference back-end (make_reference_operator:
// plain loops over edgefem/physics/): the CPU back-end's serial loops and
// each of its variants on OpenMP, oneTBB and the pool at 1, 2 and 3 threads,
// both stiffness layouts, edge FE, edge SN and per-tet, double and float:
// forces, energy, K x (plain and definite K) and the diagonal blocks within
// 1e-12 (double) or 1e-5 (float, against the double reference at the
// float-rounded input: rounded_to_float) of the
// reference, relative to the largest entry, on generated boxes and the
// shared meshes up to 10k tets. Whole simulations (semi-implicit steps,
// an implicit step) on the CPU back-end within 1e-9 of the reference's.
// The reference itself: its edge FE forces within 1e-12 of its per-tet
// forces (two formulations of the same StVK energy).
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "lab/deformations.hpp"
#include "edgefem/core/make_box.hpp"
#include "edgefem/core/reference_operator.hpp"
#include "edgefem/core/simulator.hpp"
#include "edgefem/parallel/cpu_backend.hpp"
#include "edgefem/parallel/executors.hpp"
#include "executor_kinds.hpp"
#include "cantilever.hpp"
#include "operator_outputs.hpp"
#include "test_meshes.hpp"

using namespace edgefem;

namespace {

using test::direction;
using test::evaluate;
using test::expect_close;
using test::Outputs;
using test::rel_diff;

const Materials& material() { return test::backend_test_material(); }

struct Config {
    std::string name;
    CpuOptions options;
};

std::vector<Config> cpu_configs() {
    std::vector<Config> c;
    for (StiffnessLayout layout : {StiffnessLayout::TetLocal, StiffnessLayout::TsepList}) {
        const std::string l = std::string("/") + to_string(layout);
        c.push_back({"serial-loops" + l, {nullptr, Variant::Auto, layout}});
        for (ExecutorKind b : test::threaded_executor_kinds())
            for (int t : {1, 2, 3})
                for (Variant v : {Variant::Auto, Variant::Colour, Variant::Gather, Variant::Atomic, Variant::Private,
                                  Variant::Owner}) {
                    if (b != ExecutorKind::OpenMP && v != Variant::Auto && t != 2) continue;  // keep the matrix small
                    c.push_back({std::string(to_string(b)) + "-" + std::to_string(t) + "-" + to_string(v) + l,
                                 {make_executor(b, t), v, layout}});
                }
    }
    return c;
}

using test::Case;
using test::kCases;

}  // namespace

TEST(Backends, CpuOperatorsMatchTheReference) {
    const auto configs = cpu_configs();
    for (const auto& nm : test::test_meshes(10000)) {
        SCOPED_TRACE(nm.name);
        const std::vector<double> u = deformation_displacement(nm.mesh, Deformation::Twist);
        const std::vector<double> x = direction(u.size());
        for (const Case& c : kCases) {
            const bool edge = c.method == Method::Edge;
            const auto ref_op = make_reference_operator<double>(nm.mesh, material(), c.model, c.method);
            const Outputs ref = evaluate(*ref_op, u, x, edge);
            const Outputs ref_at_float = evaluate(*ref_op, test::rounded_to_float(u), test::rounded_to_float(x), edge);
            for (const Config& cfg : configs) {
                if (!edge && cfg.options.layout != StiffnessLayout::TetLocal) continue;  // no layout for per-tet
                const std::string what = std::string(c.name) + " " + cfg.name;
                auto op = make_cpu_operator<double>(nm.mesh, material(), c.model, c.method, cfg.options);
                expect_close(evaluate(*op, u, x, edge), ref, 1e-12, what);
            }
            // Float on the serial loops and the default threaded variant.
            for (const CpuOptions& o : {CpuOptions{}, CpuOptions{make_executor(ExecutorKind::OpenMP, 2)}}) {
                auto op = make_cpu_operator<float>(nm.mesh, material(), c.model, c.method, o);
                expect_close(evaluate(*op, u, x, edge), ref_at_float, 1e-5, std::string(c.name) + " float");
            }
        }
    }
}

TEST(Backends, ReferenceEdgeAndPerTetFormsAgree) {
    for (const auto& nm : test::test_meshes(10000)) {
        SCOPED_TRACE(nm.name);
        const std::vector<double> u = deformation_displacement(nm.mesh, Deformation::Twist);
        const std::vector<double> x = direction(u.size());
        auto edge = make_reference_operator<double>(nm.mesh, material(), ModelKind::FE, Method::Edge);
        auto tet = make_reference_operator<double>(nm.mesh, material(), ModelKind::FE, Method::Tet);
        const Outputs a = evaluate(*edge, u, x, false), b = evaluate(*tet, u, x, false);
        expect_close(a, b, 1e-12, "edge FE against per-tet");
    }
    EXPECT_THROW(make_reference_operator<double>(make_box(1, 1, 1), material(), ModelKind::SN, Method::Tet),
                 InvalidArgument);
    EXPECT_THROW(make_reference_operator<double>(make_box(1, 1, 1), material(), ModelKind::FE, Method::Tet)->build_stiffness(true),
                 InvalidArgument);
}

TEST(Backends, SimulationsMatchTheReference) {
    // 20 semi-implicit steps of a swinging cantilever (CG to 1e-10) and 3
    // implicit ones: the CPU back-end's trajectory within 1e-9 of the
    // reference back-end's.
    for (Integrator integ : {Integrator::SemiImplicit, Integrator::Implicit}) {
        Scene scene = test::cantilever_scene();
        scene.integrator = integ;
        scene.solver.cg_tolerance = 1e-10;
        const int steps = integ == Integrator::Implicit ? 3 : 20;
        Simulator<double> ref(scene);
        for (int k = 0; k < steps; ++k) ref.step();
        const std::vector<double> u_ref(ref.displacement().begin(), ref.displacement().end());
        for (const CpuOptions& o : {CpuOptions{}, CpuOptions{make_executor(ExecutorKind::Pool, 2)}}) {
            Simulator<double> sim(scene, o.executor, cpu_operator_factory<double>(o));
            for (int k = 0; k < steps; ++k) sim.step();
            const std::vector<double> u(sim.displacement().begin(), sim.displacement().end());
            EXPECT_LE(rel_diff(u, u_ref), 1e-9) << to_string(integ) << (o.executor ? " pool x2" : " serial loops");
        }
    }
}
