// Newmark-beta (beta, gamma; 1/4, 1/2 by default: the trapezoidal rule,
// second order, no numerical damping) and, with alpha_m and alpha_f, the
// generalized-alpha family (generalized_alpha.cpp) on the shared implicit
// step (implicit_step.hpp). With a the history's acceleration:
//   upred = u + T v + T^2 (1/2 - beta) a,  vpred = v + T (1 - gamma) a,
//   a' = (u' - upred) / (beta T^2),  v' = vpred + gamma T a',
// and the balance (1 - alpha_m) M a' + alpha_m M a + (1 - alpha_f) (D v' +
// F(u')) + alpha_f (D v + F(u)) = h, divided by 1 - alpha_f: c_i = (1 -
// alpha_m) / ((1 - alpha_f) beta T^2), c_d = gamma / (beta T), ud = upred -
// vpred / c_d, and the load h + (alpha_f (h - D v - F(u)) - alpha_m M a) /
// (1 - alpha_f). The first step (and one after the application wrote u or
// v) starts from the acceleration of the balance at u, v.
#include "integrators/implicit_step.hpp"
#include "integrators/time_integrator.hpp"

namespace edgefem::sim {

namespace {

template <class S>
class NewmarkFamily final : public TimeIntegrator<S> {
public:
    NewmarkFamily(SimState<S>& state, TangentSolve<S>& solve, NewmarkCoefficients c, bool linear)
        : s_(state), c_(c), step_(state, solve, linear) {}

    // Newmark: the balance holds at both ends and v' - v = T ((1 - gamma) a
    // + gamma a'), so the step's damping impulse is -T D ((1 - gamma) v +
    // gamma v') (with the trapezoidal rule's du = T (v + v') / 2, the exact
    // work alpha |du|_M^2 / T). The default account credited it with
    // damping a mode whose velocity flips every step at alpha T |v'|^2, which
    // the trapezoidal rule barely damps: a spurious gain (1.64x on a kicked
    // bar). Generalized-alpha keeps the default: counted at its balance's
    // velocity (1 - alpha_f) v' + alpha_f v, the guard's halvings no longer
    // brought its linearised form to rest on the stress suite's
    // near-incompressible bar, where it is unstable at 1 ms
    // (docs/lab/2026-11-27-integrators-stress.md, "Finding 2, again").
    DampingAccount damping_account() const override {
        if (c_.alpha_m == 0 && c_.alpha_f == 0) return {true, c_.gamma, 1 - c_.gamma};
        return {};
    }

    std::optional<double> step(double T) override {
        const Scene& scene = s_.scene;
        const std::size_t n = s_.n();
        step_.begin(T);
        const bool current = s_.history_current();
        double* const a = s_.history_vector(0);
        const double* const K0v = step_.damping_product();
        auto load = [&](double* out, double c_h, double c_r, double c_a, bool per_mass) {
            s_.kernels.dynamic_load({out, s_.h.data(), s_.f.data(), s_.v.data(), a, K0v, s_.mass.data(),
                                     s_.free_dof.data(), scene.rayleigh_alpha, scene.rayleigh_beta, c_h, c_r, c_a,
                                     per_mass},
                                    n);
        };
        if (!current) load(a, 0, 1, 0, true);  // M a = h - D v - F(u)
        const double beta = c_.beta, gamma = c_.gamma, am = c_.alpha_m, af = c_.alpha_f;
        const double c_i = (1 - am) / ((1 - af) * beta * T * T), c_d = gamma / (beta * T);
        const double pa = T * T * (0.5 - beta);
        s_.kernels.history_predict(step_.upred.data(), step_.ud.data(), s_.u.data(), s_.v.data(), a, nullptr,
                                   {1, T, pa, 0}, {1, T - 1 / c_d, pa - T * (1 - gamma) / c_d, 0}, n);
        if (am != 0 || af != 0) load(s_.h.data(), 1, af / (1 - af), -am / (1 - af), false);
        // The correction u' - upred is beta T^2 a', and a' is near a (the
        // last step's, or the balance's at u, v): the linearised solve
        // starts from upred improved along a.
        const double* direction = nullptr;
        if (step_.warm()) {
            step_.direction.resize(n);
            s_.kernels.free_part(step_.direction.data(), a, s_.free_dof.data(), n);
            direction = step_.direction.data();
        }
        const std::optional<double> W = step_.solve(c_i, c_d, direction);
        step_.finish(c_d, a, 1 / (beta * T * T));
        s_.history_done(T);
        return W;
    }

private:
    SimState<S>& s_;
    NewmarkCoefficients c_;
    ImplicitStep<S> step_;
};

}  // namespace

template <class S>
std::unique_ptr<TimeIntegrator<S>> make_newmark_family(SimState<S>& state, TangentSolve<S>& solve,
                                                       NewmarkCoefficients c, bool linear) {
    return std::make_unique<NewmarkFamily<S>>(state, solve, c, linear);
}

template <class S>
std::unique_ptr<TimeIntegrator<S>> make_newmark(SimState<S>& state, TangentSolve<S>& solve, bool linear) {
    const IntegratorParameters& p = state.scene.integrator_parameters;
    return make_newmark_family(state, solve, {p.newmark_beta, p.newmark_gamma, 0.0, 0.0}, linear);
}

template std::unique_ptr<TimeIntegrator<double>> make_newmark_family(SimState<double>&, TangentSolve<double>&,
                                                                     NewmarkCoefficients, bool);
template std::unique_ptr<TimeIntegrator<float>> make_newmark_family(SimState<float>&, TangentSolve<float>&,
                                                                    NewmarkCoefficients, bool);
template std::unique_ptr<TimeIntegrator<double>> make_newmark(SimState<double>&, TangentSolve<double>&, bool);
template std::unique_ptr<TimeIntegrator<float>> make_newmark(SimState<float>&, TangentSolve<float>&, bool);

}  // namespace edgefem::sim
