#include "simulator/energy_guard.hpp"

#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "simulator/instability_advice.hpp"
#include "simulator/messages.hpp"

namespace edgefem::sim {

namespace {
constexpr double kPartialRunaway = 1000;  // a fixed CG budget's bound on the energy growth (see check())
}  // namespace

template <class S>
EnergySample EnergyGuard<S>::sample(double W) const {
    const std::array<double, 3> s =
        s_.kernels.energy_sums(s_.u.data(), s_.v.data(), s_.fext_now(), s_.mass.data(), s_.scene.gravity, s_.n());
    return {s[0], W, s[1], s[2]};
}

template <class S>
EnergySample EnergyGuard<S>::start(double t_end, bool moved) {
    const bool same = evaluated_valid_ && s_.kernels.count_differences(s_.u.data(), u_evaluated_.data(), s_.n()) == 0;
    const double W = same ? W_evaluated_ : s_.forces(true);
    s_.forces_current = true;
    EnergySample e = sample(W);
    if (moved) constrained(e, s_.u.data(), s_.ramp(t_end));
    return e;
}

// The constrained vertices' part of e, and f's work on their move from
// u_from to their targets at `fraction` (f: the forces at the state e is of).
template <class S>
void EnergyGuard<S>::constrained(EnergySample& e, const S* u_from, double fraction) const {
    const std::array<double, 4> c =
        s_.kernels.constrained_sums(s_.u.data(), s_.v.data(), s_.fext_now(), s_.f.data(), u_from, s_.mass.data(),
                                    s_.scene.gravity, s_.constraints(), fraction);
    e.c_kinetic = c[0];
    e.c_gravity = c[1];
    e.c_load = c[2];
    e.c_work = c[3];
}

// The work moving constraints did on the free vertices through stiffness
// damping over a step of size T: the damping force on the free dofs holds
// -beta K_fc v_c, which drags the body along with them (a source: while
// the free vertices lag, it is first order in their velocity and outgrows
// what damping dissipates among them, beta v_f.K_ff v_f, which is not
// credited). Counted as -T beta v_f . K v_c at the step's new velocity (v
// split into its free part v_f and its constrained part v_c), K the
// operator's last built one: the step's damping tangent or near it. Without
// it, trapezoidal steps of a driven beam with beta = 1e-3 s failed in their
// third step with 9-12x gains while their trajectory was within 0.35-0.6 %
// of the reference (docs/dynamics.md, "Target (b)").
template <class S>
double EnergyGuard<S>::damping_drag(double T) {
    const std::size_t n = s_.n();
    const VectorKernels<S>& k = s_.kernels;
    v_free_.resize(n);
    v_con_.resize(n);
    kv_.resize(n);
    k.fill(v_con_.data(), n, 0.0);
    k.velocity_change(v_free_.data(), v_con_.data(), s_.v.data(), s_.free_dof.data(), n);  // v_f; v_con_ = v
    k.axpby(v_con_.data(), -1.0, v_free_.data(), 1.0, n);                                  // v_c
    s_.multiply(*s_.op, v_con_.data(), kv_.data());
    return -T * s_.scene.rayleigh_beta * k.scaled_dot(v_free_.data(), kv_.data(), n).value();
}

template <class S>
bool EnergyGuard<S>::constraints_move(double t_end) const {
    const double tol = 8 * double(std::numeric_limits<S>::epsilon());
    return s_.kernels.constraints_move(s_.u.data(), s_.constraints(), s_.ramp(t_end), tol);
}

// The step's gain is its energy change net of the external work (f_ext is
// constant over the step: f_ext.du) and of what mass damping removed, as the
// integrator counts it (TimeIntegrator::damping_account: 2 T alpha x the new
// kinetic energy for the Euler steps, alpha du . M v_d for Newmark), so it
// is the integrator's own energy error: damping does not hide an injection.
// Gains accumulate from their lowest level (a one-sided CUSUM: dissipation
// is no credit for later injection)
// and may not exceed (max_energy_growth - 1) x the largest kinetic +
// elastic energy the body has had net of such gains, plus the sums'
// round-off.
template <class S>
void EnergyGuard<S>::check(double T, const EnergySample& start, const S* u0, const S* v0, double W_end,
                           bool constraints_moved, const DampingAccount& account) {
    const Scene& scene = s_.scene;
    StepStats& stats = s_.stats;
    s_.copy_state(u_evaluated_, s_.u);
    W_evaluated_ = W_end;
    evaluated_valid_ = true;
    EnergySample end = sample(W_end);
    if (constraints_moved) constrained(end, u0, s_.ramp(s_.time + T));
    // The reference is net of the gains counted so far: the start's own
    // kinetic + elastic energy includes them, and with it a steady
    // growth of 1.2-3x per step raised its own bound and was never
    // caught (a bent beam, explicit just past the stable dt, reached
    // 460x its release energy with every step passing).
    double scale = std::max(energy_scale_, start.kinetic + start.elastic - energy_excess_);
    double excess = energy_excess_;
    {
        const double alpha = scene.rayleigh_alpha;
        const double damping = alpha == 0 || !account.from_displacement
                                   ? 2 * T * alpha * (end.kinetic - end.c_kinetic)
                                   : alpha * s_.kernels.damping_work(s_.u.data(), u0, s_.v.data(), v0, s_.mass.data(),
                                                                     account.w_new, account.w_old, s_.n());
        // Moving constraints: the free vertices' energy (the constrained
        // ones' kinetic, gravity and load terms left out), less the
        // constraints' work on the body, the trapezoidal rule's
        // (f_c(start) + f_c(end)) / 2 . du_c, and with beta their drag
        // through stiffness damping. Fixed: the c_ terms are 0.
        const double free_start = start.total() - start.c_kinetic - start.c_gravity;
        const double free_end = end.total() - end.c_kinetic - end.c_gravity;
        double work = 0.5 * (start.c_work + end.c_work);
        if (constraints_moved && scene.rayleigh_beta > 0) work += damping_drag(T);
        const double gain =
            (free_end - free_start) - ((end.load - end.c_load) - (start.load - start.c_load)) - work + damping;
        const double noise = 256 * double(std::numeric_limits<S>::epsilon()) * (start.magnitude() + end.magnitude());
        excess += gain;
        // The step's end counts too, net of the gains: from rest (nothing
        // seen yet) a conservative scheme's first step gains a Newton
        // tolerance's worth (1e-12 of the motion's energy), which failed
        // against a reference of 0 J; an injected gain is subtracted, so
        // it does not raise its own bound.
        scale = std::max(scale, end.kinetic + end.elastic - std::max(excess, 0.0));
        const double limit = scene.solver.max_energy_growth;
        stats.energy_growth = 1 + std::max(excess, 0.0) / std::max(scale, 1e-300);
        // A fixed CG budget is a deliberate partial solve, which is not
        // dissipative: measured, failed only past kPartialRunaway x the
        // largest energy seen, where it has blown up (2 AMG iterations per
        // step on a shaken 2592-tet beam reached 1e17 m).
        const bool partial = is_linearised(scene.integrator) && scene.solver.cg_fixed_iterations > 0 &&
                             scene.solver.linear_solver == LinearSolver::CG;
        const double allowed = partial ? std::max(limit, kPartialRunaway) : limit;
        if (!std::isfinite(excess)) {
            // State finite but its energy not (|u| ~ 1e300 under a huge
            // load): say so rather than print a NaN ratio.
            const index_t vertex = s_.fastest_vertex();
            double umax = 0;
            std::vector<S> scratch;
            for (const S x : s_.u.read_host(scratch)) umax = std::max(umax, std::abs(double(x)));
            throw StepFailure{"step " + std::to_string(s_.step + 1) +
                                  ": the energy is no longer finite (displacements up to " + sci(umax) +
                                  " m): the state left the range of floating point; fastest vertex " +
                                  std::to_string(vertex) + " (check the loads, the units and dt)",
                              vertex};
        }
        if (!(excess <= (allowed - 1) * scale + noise)) {
            const index_t vertex = s_.fastest_vertex();
            char ratio[48], lim[96];
            std::snprintf(ratio, sizeof ratio, "+%.3g x", excess / std::max(scale, 1e-300));
            if (partial)
                std::snprintf(lim, sizeof lim, "%g (with solver.cg_fixed_iterations: %g)", limit, allowed);
            else
                std::snprintf(lim, sizeof lim, "%g", limit);
            // From rest (no kinetic or elastic energy yet) a ratio means
            // nothing (it printed +6e288 x): give the gain itself.
            const bool from_rest = !(excess < 1e12 * scale);
            throw StepFailure{"step " + std::to_string(s_.step + 1) + ": energy grew without a source: " +
                                  (from_rest ? "a gain of " + sci(excess) +
                                                   " J net of the external work, by a body that had no kinetic or "
                                                   "elastic energy to speak of (" + sci(scale) + " J)"
                                             : std::string(ratio) +
                                                   " the largest kinetic + elastic energy seen (a gain of " +
                                                   sci(excess) +
                                                   " J net of the external work since its lowest level; largest " +
                                                   sci(scale) + " J)") +
                                  ", over solver.max_energy_growth = " + lim + "; fastest vertex " +
                                  std::to_string(vertex) + " (" + instability_advice(scene.integrator) + ")",
                              vertex};
        }
        excess = std::max(0.0, excess);
    }
    energy_excess_ = excess;
    energy_scale_ = std::max(scale, end.kinetic + end.elastic - excess);
}

template class EnergyGuard<double>;
template class EnergyGuard<float>;

}  // namespace edgefem::sim
