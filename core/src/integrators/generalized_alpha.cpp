// Generalized-alpha (Chung and Hulbert 1993) from its one parameter, the
// spectral radius at infinite frequency rho_inf in [0, 1]:
//   alpha_m = (2 rho - 1) / (rho + 1), alpha_f = rho / (rho + 1),
//   gamma = 1/2 - alpha_m + alpha_f, beta = (1 - alpha_m + alpha_f)^2 / 4:
// second order for every rho_inf, numerical damping of the high
// frequencies only; rho_inf = 1 is the trapezoidal rule. The step is the
// Newmark family's (newmark.cpp).
#include "integrators/time_integrator.hpp"

namespace edgefem::sim {

template <class S>
std::unique_ptr<TimeIntegrator<S>> make_generalized_alpha(SimState<S>& state, TangentSolve<S>& solve, bool linear) {
    const double rho = state.scene.integrator_parameters.rho_inf;
    const double am = (2 * rho - 1) / (rho + 1), af = rho / (rho + 1);
    const double gamma = 0.5 - am + af, beta = 0.25 * (1 - am + af) * (1 - am + af);
    return make_newmark_family(state, solve, {beta, gamma, am, af}, linear);
}

template std::unique_ptr<TimeIntegrator<double>> make_generalized_alpha(SimState<double>&, TangentSolve<double>&, bool);
template std::unique_ptr<TimeIntegrator<float>> make_generalized_alpha(SimState<float>&, TangentSolve<float>&, bool);

}  // namespace edgefem::sim
