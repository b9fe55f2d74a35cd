#include "integrators/newton.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "simulator/messages.hpp"

namespace edgefem::sim {

template <class S>
void Newton<S>::solve(const Inertia* scheme, const ElasticOperator<S>* K0) {
    const Scene& scene = s_.scene;
    const VectorKernels<S>& k = s_.kernels;
    const std::size_t n = s_.n();
    StepStats& stats = s_.stats;
    S* const u = s_.u.data();
    double* const x = s_.x.data();
    const bool dynamic = scheme != nullptr;
    const double c_i = dynamic ? scheme->c_i : 0.0, c_d = dynamic ? scheme->c_d : 0.0;
    const double* const u0 = dynamic ? scheme->ud : nullptr;
    const double* const upred = dynamic ? scheme->upred : nullptr;
    const double c_m = c_i + scene.rayleigh_alpha * c_d;
    const double c_b = scene.rayleigh_beta * c_d;
    const auto& sv = scene.solver;
    BackendVector<double> R = s_.template vector<double>(n), du = s_.template vector<double>(n),
                          trial = s_.template vector<double>(n), K0d = s_.template vector<double>(n),
                          inertia = s_.template vector<double>(n);

    // Potential, its magnitude (sum of the terms' sizes: its round-off
    // is ~1e-14 of that) and the residual at the current u (u, f updated).
    auto evaluate = [&](double& phi, double& scale, double& mag) {
        const double W = s_.forces(true);
        W_ = W;
        phi = W;
        mag = std::abs(W);
        d_.resize(n);
        k.newton_increment(d_.data(), u, dynamic ? u0 : nullptr, n);
        if (c_b != 0) s_.multiply(*K0, d_.data(), K0d.data());
        // R and the inertia terms, and the sums of h.u, |h u|, the kinetic
        // terms and their sizes.
        const std::array<double, 4> sums =
            k.newton_residual({R.data(), inertia.data(), s_.f.data(), u, s_.h.data(), s_.mass.data(), upred,
                               d_.data(), K0d.data(), s_.free_dof.data(), dynamic, c_i, c_d, scene.rayleigh_alpha, c_b},
                              n);
        phi += sums[2] - sums[0];
        mag += sums[1] + sums[3];
        scale = k.scaled_norm_state(s_.f.data(), n) + k.scaled_norm(s_.h.data(), n) + k.scaled_norm(inertia.data(), n);
    };
    auto norm = [&](const BackendVector<double>& a) { return k.scaled_norm(a.data(), n); };
    // du.R: its sign from the scaled sum (the value may underflow).
    auto slope_of = [&](bool& descent) {
        const Scaled sl = k.scaled_dot(x, R.data(), n);
        descent = sl.mant < 0;
        return sl.value();
    };

    // The residual cannot fall below the round-off of S: a float model
    // is converged at ~1e-5 whatever the scene asks.
    const double tolerance = std::max(sv.newton_tolerance, 100 * double(std::numeric_limits<S>::epsilon()));
    // Forces near the smallest normal number of S (a body whose motion
    // has decayed to ~1e-300 m) have no relative precision left: a
    // residual below that is zero.
    const double underflow = std::sqrt(double(n)) * double(std::numeric_limits<S>::min());
    // Round-off floor. Each force component sums per-edge terms that can
    // be far larger than their sum (stiff materials, slivers, a
    // compressed body), so round-off leaves a residual that can lie
    // above the tolerance. Newton stagnating there is converged:
    //  (b) the relative residual is at most sqrt(eps) and two iterations
    //      in a row did not halve the best one (near a solution a Newton
    //      step gains orders of magnitude: what it cannot reduce is
    //      noise), or the line search cannot reduce it either;
    //  (c) the Newton step is below the resolution of u itself
    //      (|du| <= 8 eps |u|) and the residual did not halve, or the
    //      line search cannot reduce it: no iteration can change the
    //      state any more. (At equilibrium under no load the net forces
    //      vanish while their terms do not: the relative residual there
    //      can be large and is still noise.)
    // docs/scenes.md, "Solver settings".
    const double eps = double(std::numeric_limits<S>::epsilon());
    const double floor_tolerance = std::sqrt(eps);
    double best = INFINITY;
    int stalled = 0;
    auto at_floor = [&] {
        if (stats.residual > floor_tolerance) return false;
        stats.newton_round_off = true;
        return true;
    };
    double phi = 0, scale = 0, mag = 0;
    evaluate(phi, scale, mag);
    for (int it = 0;; ++it) {
        const double rn = norm(R);
        stats.residual = scale > 0 ? rn / scale : rn;
        if (!std::isfinite(rn))
            throw StepFailure{"step " + std::to_string(s_.step + 1) + ": non-finite residual in Newton", -1};
        if (s_.newton_observer) s_.newton_observer(stats.residual);
        if (rn <= tolerance * scale || rn <= underflow) return;
        stalled = stats.residual > 0.5 * best ? stalled + 1 : 0;
        best = std::min(best, stats.residual);
        if (stalled >= 2 && at_floor()) return;
        if (it == sv.newton_max_iterations)
            throw StepFailure{"step " + std::to_string(s_.step + 1) + ": Newton did not converge in " +
                                  std::to_string(sv.newton_max_iterations) + " iterations (relative residual " +
                                  sci(stats.residual) + ")",
                              -1};
        ++stats.newton_iterations;
        // Solve (c_m M + K + c_b K0) du = -R, du = 0 on constrained dofs.
        k.newton_rhs(s_.b.data(), x, R.data(), n);
        const double eta = std::min(1e-2, std::max(1e-12, rn / std::max(scale, 1e-300)));
        solve_.solve(c_m, 1.0, c_b, K0, eta, sv.definite_stiffness);
        bool descent = false, newton_direction = true;
        double slope = slope_of(descent);
        if (!descent || !std::isfinite(slope)) {  // not a descent direction: use the definite K
            if (scene.method == Method::Edge) {
                k.fill(x, n, 0.0);
                solve_.solve_once(c_m, 1.0, c_b, K0, eta, true);
                slope = slope_of(descent);
            }
            if (!descent) {  // last resort: scaled gradient
                newton_direction = false;
                k.scaled_gradient(x, R.data(), s_.mass.data(), std::max(c_m, 1.0), n);
                slope = slope_of(descent);
            }
        }
        k.copy(du.data(), x, n);
        k.from_state(trial.data(), u, n);
        const bool below_resolution = newton_direction && norm(du) <= 8 * eps * norm(trial);
        if (below_resolution && stalled >= 1) {  // (c)
            stats.newton_round_off = true;
            return;
        }
        // Backtracking line search: Armijo on the potential while it can
        // resolve the decrease asked for; below ~1e4 x its round-off (near
        // the solution, or at tiny steps) the potential's differences are
        // noise and the residual norm is the merit instead (du is a
        // descent direction for it too).
        double step_len = 1, phi_new = 0, scale_new = 0, mag_new = 0;
        for (int ls = 0;; ++ls) {
            k.line_search_point(u, trial.data(), du.data(), step_len, n);
            evaluate(phi_new, scale_new, mag_new);
            if (std::isfinite(phi_new)) {
                const double decrease = -1e-4 * step_len * slope;
                if (decrease > 1e-10 * mag) {
                    if (phi_new <= phi - decrease) break;
                } else if (norm(R) <= (1 - 1e-4 * step_len) * rn) {
                    break;
                }
            }
            if (ls == 40) {
                k.to_state(u, trial.data(), n);
                evaluate(phi, scale, mag);  // back to the iterate (and its f, W)
                if (at_floor()) return;     // (b)
                if (below_resolution) {     // (c)
                    stats.newton_round_off = true;
                    return;
                }
                throw StepFailure{"step " + std::to_string(s_.step + 1) +
                                      ": line search failed: neither the potential nor the residual decreases "
                                      "along the Newton direction (Newton iteration " + std::to_string(it + 1) +
                                      ", relative residual " + sci(stats.residual) + ", directional slope " +
                                      sci(slope) + ")",
                                  -1};
            }
            step_len *= 0.5;
        }
        phi = phi_new;
        scale = scale_new;
        mag = mag_new;
    }
}

template class Newton<double>;
template class Newton<float>;

}  // namespace edgefem::sim
