#include "solvers/tangent_solve.hpp"

#include "simulator/timing.hpp"

namespace edgefem::sim {

template <class S>
TangentSolve<S>::TangentSolve(SimState<S>& state) : s_(state), system_(state), solver_(make_system_solver(state)) {}

template <class S>
CgResult TangentSolve<S>::solve(double c_m, double c_k, double c_b, const ElasticOperator<S>* K0, double tolerance,
                                bool definite, Stiffness stiffness, int fixed_iterations, const double* direction) {
    CgResult res = solve_once(c_m, c_k, c_b, K0, tolerance, definite, stiffness, fixed_iterations, direction);
    if (res.negative_curvature && !definite && s_.scene.method == Method::Edge) {
        s_.stats.negative_curvature = true;
        const int its = res.iterations;
        res = solve_once(c_m, c_k, c_b, K0, tolerance, true, Stiffness::Build, fixed_iterations, direction);
        res.iterations += its;
    }
    return res;
}

template <class S>
CgResult TangentSolve<S>::solve_once(double c_m, double c_k, double c_b, const ElasticOperator<S>* K0,
                                     double tolerance, bool definite, Stiffness stiffness, int fixed_iterations,
                                     const double* direction) {
    auto t0 = Clock::now();
    const int refreshes = solver_->refreshes();
    const bool reuse = stiffness == Stiffness::Reuse && solver_->reusable();
    system_.set(c_m, c_k, c_b, K0, definite);
    if (!reuse) {
        if (stiffness != Stiffness::Built) s_.op->build_stiffness(definite);
        if (s_.scene.solver.stiffness_interval > 1) lagged_.record(s_, system_);
        const int analyses = solver_->analyses();
        solver_->setup(system_);
        s_.stats.symbolic_analyses += solver_->analyses() - analyses;
    }
    s_.stats.stiffness_ms += ms_since(t0);
    t0 = Clock::now();
    const CgResult res = solver_->solve(system_, s_.b, s_.x, tolerance, fixed_iterations, direction);
    s_.stats.solve_ms += ms_since(t0);
    s_.stats.solver_iterations += res.iterations;
    s_.stats.preconditioner_refreshes += solver_->refreshes() - refreshes;  // set-up and solve (auto switches in it)
    return res;
}

template <class S>
void TangentSolve<S>::save(CheckpointWriter& w) const {
    solver_->save(w);
    lagged_.save(w);
}

// The solver's set-up first (the AMG rebuilds K at its points), the lagged
// K last: it is the one the next step may reuse.
template <class S>
void TangentSolve<S>::load(CheckpointReader& r) {
    solver_->load(r, system_);
    lagged_.load(r, s_.n());
    if (!lagged_.valid) return;
    std::unique_ptr<ElasticOperator<S>> k0;
    lagged_.rebuild(s_, system_, k0);
}

template class TangentSolve<double>;
template class TangentSolve<float>;

}  // namespace edgefem::sim
