#include "solvers/preconditioner.hpp"

namespace edgefem::sim {

template <class S>
std::unique_ptr<Preconditioner<S>> make_preconditioner(const SimState<S>& state) {
    switch (state.scene.solver.preconditioner) {
        case PreconditionerKind::BlockJacobi: return make_block_jacobi(state);
        case PreconditionerKind::Amg: return make_amg(state);
        case PreconditionerKind::Auto: return make_auto_preconditioner(state);
    }
    throw InvalidArgument("solver.preconditioner: unknown value");
}

template std::unique_ptr<Preconditioner<double>> make_preconditioner(const SimState<double>&);
template std::unique_ptr<Preconditioner<float>> make_preconditioner(const SimState<float>&);

}  // namespace edgefem::sim
