// Variable-step BDF2 on the shared implicit step (implicit_step.hpp): with
// the previous step's u_1, v_1 and size T_1 (the history), w = T / T_1,
//   v' = (a0 u' + a1 u + a2 u_1) / T,  a' = (a0 v' + a1 v + a2 v_1) / T,
//   a0 = (1 + 2 w) / (1 + w), a1 = -(1 + w), a2 = w^2 / (1 + w),
// so c_d = a0 / T, ud = -(a1 u + a2 u_1) / a0, c_i = c_d^2, upred = ud -
// (a1 v + a2 v_1) / (a0 c_d) (w = 1: the constant-step 3/2, -2, 1/2).
// Second order, strongly damped high frequencies. The first step, one
// after the application wrote u or v, and one whose ratio w exceeds 2.4
// (past BDF2's zero-stability bound 1 + sqrt 2) are backward Euler steps.
#include "integrators/implicit_step.hpp"
#include "integrators/time_integrator.hpp"

namespace edgefem::sim {

namespace {

template <class S>
class Bdf2 final : public TimeIntegrator<S> {
public:
    Bdf2(SimState<S>& state, TangentSolve<S>& solve, bool linear) : s_(state), step_(state, solve, linear) {}

    std::optional<double> step(double T) override {
        const std::size_t n = s_.n();
        step_.begin(T);
        const double w = s_.history.dt > 0 ? T / s_.history.dt : 0;
        const bool bdf2 = w > 0 && w <= 2.4 && s_.history_current();
        double* const u1 = s_.history_vector(0);
        double* const v1 = s_.history_vector(1);
        double c_i = 1 / (T * T), c_d = 1 / T;
        if (bdf2) {
            const double a0 = (1 + 2 * w) / (1 + w), a1 = -(1 + w), a2 = w * w / (1 + w);
            c_d = a0 / T;
            c_i = c_d * c_d;
            s_.kernels.history_predict(step_.upred.data(), step_.ud.data(), s_.u.data(), s_.v.data(), u1, v1,
                                       {-a1 / a0, -a1 / (a0 * c_d), -a2 / a0, -a2 / (a0 * c_d)},
                                       {-a1 / a0, 0, -a2 / a0, 0}, n);
        } else {  // backward Euler
            s_.kernels.history_predict(step_.upred.data(), step_.ud.data(), s_.u.data(), s_.v.data(), nullptr,
                                       nullptr, {1, T, 0, 0}, {1, 0, 0, 0}, n);
        }
        // The correction u' - upred is T^2 a' / a0^2 (a' the BDF2
        // acceleration); the linearised solve starts from upred improved
        // along the last step's change of velocity v - v_1, the shape of a.
        const double* direction = nullptr;
        s_.kernels.from_state(u1, s_.u.data(), n);
        if (bdf2 && step_.warm()) {
            step_.direction.resize(n);
            s_.kernels.velocity_change(step_.direction.data(), v1, s_.v.data(), s_.free_dof.data(), n);
            direction = step_.direction.data();
        } else {
            s_.kernels.from_state(v1, s_.v.data(), n);
        }
        const std::optional<double> W = step_.solve(c_i, c_d, direction);
        step_.finish(c_d, nullptr, 0);
        s_.history_done(T);
        return W;
    }

private:
    SimState<S>& s_;
    ImplicitStep<S> step_;
};

}  // namespace

template <class S>
std::unique_ptr<TimeIntegrator<S>> make_bdf2(SimState<S>& state, TangentSolve<S>& solve, bool linear) {
    return std::make_unique<Bdf2<S>>(state, solve, linear);
}

template std::unique_ptr<TimeIntegrator<double>> make_bdf2(SimState<double>&, TangentSolve<double>&, bool);
template std::unique_ptr<TimeIntegrator<float>> make_bdf2(SimState<float>&, TangentSolve<float>&, bool);

}  // namespace edgefem::sim
