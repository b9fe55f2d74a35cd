#include "solvers/system_solver.hpp"

namespace edgefem::sim {

template <class S>
std::unique_ptr<SystemSolver<S>> make_system_solver(const SimState<S>& state) {
    switch (state.scene.solver.linear_solver) {
        case LinearSolver::CG: return make_cg_solver(state);
        case LinearSolver::Direct: return make_direct_solver(state);
    }
    throw InvalidArgument("solver.linear_solver: unknown value");
}

template std::unique_ptr<SystemSolver<double>> make_system_solver(const SimState<double>&);
template std::unique_ptr<SystemSolver<float>> make_system_solver(const SimState<float>&);

}  // namespace edgefem::sim
