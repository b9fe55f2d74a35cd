#include "integrators/static_solve.hpp"

#include <algorithm>

#include "simulator/messages.hpp"

namespace edgefem::sim {

template <class S>
StaticResult solve_static(SimState<S>& s, TangentSolve<S>& solve, const StaticProgressFn& progress) {
    s.kernels.fill_state(s.v.data(), s.n(), S(0));
    if (s.con_vertex.empty())
        throw InvalidArgument("static equilibrium needs fixed or prescribed vertices (else it is singular)");
    s.stats = StepStats{};
    StaticResult result;
    s.update_load(s.time);
    Newton<S> newton(s, solve);
    // The increment halves on a failure, at most 12 times over the whole
    // solve. (A budget of 12 per load step, with increments that never
    // grow back, was tried: past a buckling point it ran for minutes on
    // a 96-tet bar, thousands of tiny increments each failing anew.)
    double done = 0, inc = 1.0 / s.scene.solver.load_steps;
    int halvings = 0;
    BackendVector<S> u_save = s.template vector<S>(0);
    StaticProgress now;
    // Newton reports its residuals through the state while this solve runs.
    struct Observer {
        SimState<S>& s;
        ~Observer() { s.newton_observer = nullptr; }
    } observer{s};
    if (progress)
        s.newton_observer = [&](double residual) {
            now.newton_iterations = s.stats.newton_iterations;
            now.residual = residual;
            progress(now);
        };
    while (done < 1 - 1e-15) {
        const double load = std::min(1.0, done + inc);
        ++now.load_step;
        now.load_fraction = load;
        s.copy_state(u_save, s.u);
        s.external(load);
        s.hold_constraints(load);
        try {
            newton.solve(nullptr, nullptr);
        } catch (const StepFailure& failure) {
            s.copy_state(s.u, u_save);
            if (++halvings > 12)
                throw SimulationError("static solve: load fraction " + fmt_load(done) + " -> " + fmt_load(load) + ": " +
                                          failure.message + " even with load increment " + sci(inc) +
                                          " (after 12 halvings)",
                                      s.step, failure.vertex);
            inc /= 2;
            continue;
        }
        done = load;
        ++result.load_steps;
    }
    // The targets are reached: later steps hold them there instead of
    // restarting the ramp from time 0 (which pulled the prescribed
    // vertices back to rest at 100x their speed).
    s.ramp_floor = 1;
    result.newton_iterations = s.stats.newton_iterations;
    result.residual = s.stats.residual;
    result.converged = true;
    if (s.scene.count_inverted_tets) s.stats.inverted_tets = s.op->inverted_tets(s.u.data());
    s.check_finite(s.step);
    return result;
}

template StaticResult solve_static(SimState<double>&, TangentSolve<double>&, const StaticProgressFn&);
template StaticResult solve_static(SimState<float>&, TangentSolve<float>&, const StaticProgressFn&);

}  // namespace edgefem::sim
