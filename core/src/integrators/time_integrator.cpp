#include "integrators/time_integrator.hpp"

namespace edgefem::sim {

template <class S>
std::unique_ptr<TimeIntegrator<S>> make_time_integrator(SimState<S>& state, TangentSolve<S>& solve) {
    switch (state.scene.integrator) {
        case Integrator::Explicit: return make_explicit_euler(state);
        case Integrator::SemiImplicit: return make_semi_implicit_euler(state, solve);
        case Integrator::Implicit: return make_implicit_euler(state, solve);
        case Integrator::Newmark: return make_newmark(state, solve, false);
        case Integrator::NewmarkLinear: return make_newmark(state, solve, true);
        case Integrator::GeneralizedAlpha: return make_generalized_alpha(state, solve, false);
        case Integrator::GeneralizedAlphaLinear: return make_generalized_alpha(state, solve, true);
        case Integrator::Bdf2: return make_bdf2(state, solve, false);
        case Integrator::Bdf2Linear: return make_bdf2(state, solve, true);
        case Integrator::Verlet: return make_velocity_verlet(state);
    }
    throw InvalidArgument("integrator: unknown value");
}

template std::unique_ptr<TimeIntegrator<double>> make_time_integrator(SimState<double>&, TangentSolve<double>&);
template std::unique_ptr<TimeIntegrator<float>> make_time_integrator(SimState<float>&, TangentSolve<float>&);

}  // namespace edgefem::sim
