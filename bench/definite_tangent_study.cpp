// What the definite tangent (g clamped at zero inside K) costs in accuracy
// and buys in robustness. For each scene, semi-implicit steps with the plain
// and the definite K, CG to 1e-6 (capped at 500 iterations), against a
// reference: backward Euler solved by Newton at dt / 10. Prints a table.
//
// usage: edgefem_definite_tangent_study
#include <cmath>
#include <cstdio>
#include <functional>
#include <string>

#include "edgefem/core/make_box.hpp"
#include "edgefem/core/simulator.hpp"

using namespace edgefem;

namespace {

struct Case {
    std::string name;
    std::function<Scene()> make;
};

Scene cantilever() {
    Scene s;
    s.mesh = make_box(16, 4, 4, 0.005);
    s.materials = Material{2e4, 0.3, 1000};
    s.gravity = {0, 0, -9.81};
    for (index_t v = 0; v < s.mesh.num_vertices(); ++v)
        if (s.mesh.X[3 * v] < -0.04 + 1e-9) s.fixed.push_back(v);
    s.dt = 4e-3;
    s.steps = 100;
    return s;
}

// A cube squashed to 30% of its height over 40 steps by its top face, then held.
Scene squash() {
    Scene s;
    s.mesh = make_box(5, 5, 5, 0.01);
    s.materials = Material{1e5, 0.3, 1000};
    for (index_t v = 0; v < s.mesh.num_vertices(); ++v) {
        const double* X = &s.mesh.X[3 * v];
        if (X[2] < -0.025 + 1e-9) s.fixed.push_back(v);
        if (X[2] > 0.025 - 1e-9) s.prescribed.push_back({v, {X[0], X[1], X[2] - 0.7 * 0.05}});
    }
    s.prescribed_steps = 40;
    s.dt = 2e-3;
    s.steps = 80;
    return s;
}

struct Run {
    double mean_iterations = 0;
    int negative_curvature_steps = 0;
    int unconverged_steps = 0;
    std::string failure;
    std::vector<double> u;
};

Run run(Scene s, bool definite) {
    s.solver.definite_stiffness = definite;
    s.solver.cg_tolerance = 1e-6;
    s.solver.cg_max_iterations = 500;
    Run r;
    try {
        Simulator<double> sim(s);
        for (int k = 0; k < s.steps; ++k) {
            const StepStats& st = sim.step();
            r.mean_iterations += st.solver_iterations;
            r.negative_curvature_steps += st.negative_curvature;
            r.unconverged_steps += st.residual > 1e-6;
        }
        r.mean_iterations /= s.steps;
        r.u.assign(sim.displacement().begin(), sim.displacement().end());
    } catch (const Error& e) {
        r.failure = e.what();
    }
    return r;
}

std::vector<double> reference(Scene s) {
    const int sub = 10;
    s.integrator = Integrator::Implicit;
    s.solver.newton_tolerance = 1e-10;
    s.solver.linear_solver = LinearSolver::Direct;
    s.prescribed_steps *= sub;
    s.dt /= sub;
    Simulator<double> sim(s);
    for (int k = 0; k < s.steps * sub; ++k) sim.step();
    return {sim.displacement().begin(), sim.displacement().end()};
}

double rel_error(const std::vector<double>& a, const std::vector<double>& ref) {
    double d = 0, n = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
        d += (a[i] - ref[i]) * (a[i] - ref[i]);
        n += ref[i] * ref[i];
    }
    return std::sqrt(d / n);
}

}  // namespace

int main() {
    std::printf("| scene | K | mean CG iterations | steps with negative curvature | steps not converged | L2 error vs reference |\n");
    std::printf("|---|---|---:|---:|---:|---:|\n");
    for (const Case& c : {Case{"cantilever 16x4x4, dt 4 ms, 100 steps", cantilever},
                          Case{"cube squashed to 30%, dt 2 ms, 80 steps", squash}}) {
        const auto ref = reference(c.make());
        for (bool definite : {false, true}) {
            const Run r = run(c.make(), definite);
            if (!r.failure.empty()) {
                std::printf("| %s | %s | failed: %s | | | |\n", c.name.c_str(), definite ? "definite" : "plain", r.failure.c_str());
                continue;
            }
            std::printf("| %s | %s | %.1f | %d | %d | %.3e |\n", c.name.c_str(), definite ? "definite" : "plain",
                        r.mean_iterations, r.negative_curvature_steps, r.unconverged_steps, rel_error(r.u, ref));
        }
    }
}
