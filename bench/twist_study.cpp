// Why the second-order implicit integrators gain less over backward Euler
// on `edgefem accuracy`'s twisted bar than on its cantilever
// (docs/dynamics.md, "The twisted bar").
//
// The scene is the harness's twist (box 10x2x2, 1 cm cells, Y = 1e5 Pa,
// nu = 0.3, 1000 kg/m^3, clamped at x = min, no damping, no gravity),
// released at rest from a twist theta(x) = theta_max f(x / L), f(s) = s
// (the harness's linear twist) or f(s) = sin(pi s / 2) (the shape of the
// first torsional mode of a clamped-free bar). For each it prints:
//  * an independent reference: velocity Verlet at dt 2.5 us and 5 us,
//    its own error estimated from the two (|u(2.5) - u(5)| / 3), and the
//    harness's reference (Newmark by Newton at 20 and 40 us,
//    Richardson-extrapolated) measured against it;
//  * the sensitivity of the trajectory: the same Verlet run from a state
//    perturbed by 1e-9 of the twist, the largest relative difference over
//    the sample times divided by 1e-9 (a chaotic motion amplifies it by
//    many orders of magnitude);
//  * backward Euler, Newmark (trapezoidal), generalized-alpha (0.8) and
//    BDF2, all by Newton, at dt = 1, 0.5, 0.25, 0.125 ms: the error (the
//    harness's: max over 10 sample times of |u - u_ref| / max |u_ref|),
//    the observed order against the next larger dt, the step halvings used,
//    and the ratio to backward Euler at the same dt;
//  * the error of Newmark and backward Euler at 1 ms at each sample time;
//  * the linearised bar's vibration modes (K at rest, the lumped M, dense
//    generalised eigenproblem on the free dofs): the lowest frequencies,
//    the released shape's share in frequency bands, and the error each
//    integrator would make on the linearised bar, mode by mode (each
//    integrator's scalar recurrence, lab/linear_modes.hpp: exact for a
//    linear undamped system), in total and from the modes above a
//    frequency. In the linear regime (about 1 degree) that prediction
//    equals the measured error and says which modes make it; at larger
//    twists the rotation's second-order part (cos theta - 1, which strains
//    nothing) projects onto the stiffest modes and the prediction no longer
//    applies (at 9 degrees it puts 5 % of |u0| above 300 Hz, at 0.9 0.9 %).
//    `modes-only` prints this part alone (instantly).
//
// usage: edgefem_twist_study [DEGREES [linear|mode [SECONDS [modes-only]]]]
//        (default 90 linear 0.5)
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "edgefem/core/error.hpp"
#include "edgefem/core/make_box.hpp"
#include "edgefem/core/simulator.hpp"
#include "edgefem/parallel/cpu_backend.hpp"
#include "lab/linear_modes.hpp"

using namespace edgefem;

namespace {

constexpr int kSamples = 10;

struct Setup {
    Scene scene;
    std::vector<double> u0;
    double span = 0.5;
};

Setup make_setup(double degrees, bool mode_shape, double span) {
    Setup s;
    s.span = span;
    s.scene.mesh = make_box(10, 2, 2, 0.01);
    s.scene.materials = Material{1e5, 0.3, 1000};
    s.scene.count_inverted_tets = false;
    s.scene.solver.newton_tolerance = 1e-10;
    s.scene.solver.max_step_halvings = 3;
    const Mesh& m = s.scene.mesh;
    double x0 = 1e300, x1 = -1e300;
    for (index_t v = 0; v < m.num_vertices(); ++v) {
        x0 = std::min(x0, m.X[3 * v]);
        x1 = std::max(x1, m.X[3 * v]);
    }
    for (index_t v = 0; v < m.num_vertices(); ++v)
        if (m.X[3 * v] <= x0 + 1e-9) s.scene.fixed.push_back(v);
    s.u0.assign(m.X.size(), 0.0);
    for (index_t v = 0; v < m.num_vertices(); ++v) {
        const double r = (m.X[3 * v] - x0) / (x1 - x0);
        const double th = degrees * M_PI / 180 * (mode_shape ? std::sin(0.5 * M_PI * r) : r);
        const double y = m.X[3 * v + 1], z = m.X[3 * v + 2];
        s.u0[3 * v + 1] = std::cos(th) * y - std::sin(th) * z - y;
        s.u0[3 * v + 2] = std::sin(th) * y + std::cos(th) * z - z;
    }
    return s;
}

struct Run {
    std::vector<std::vector<double>> u;  // at the sample times
    long halvings = 0;
    double wall_s = 0;
    std::string failure;
};

Run simulate(const Setup& st, Integrator integ, double dt, const std::vector<double>* u0 = nullptr) {
    Run r;
    Scene s = st.scene;
    s.integrator = integ;
    s.dt = dt;
    const auto t0 = std::chrono::steady_clock::now();
    try {
        Simulator<double> sim(std::move(s), nullptr, cpu_operator_factory<double>());
        const std::vector<double>& init = u0 ? *u0 : st.u0;
        std::copy(init.begin(), init.end(), sim.displacement().begin());
        const long total = std::lround(st.span / dt);
        long steps = 0;
        for (int k = 1; k <= kSamples; ++k) {
            const long until = std::lround(double(total) * k / kSamples);
            for (; steps < until; ++steps) r.halvings += sim.step().halvings;
            r.u.emplace_back(sim.displacement().begin(), sim.displacement().end());
        }
    } catch (const Error& e) {
        r.failure = e.what();
    }
    r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return r;
}

double norm(const std::vector<double>& a) {
    double s = 0;
    for (double x : a) s += x * x;
    return std::sqrt(s);
}

double distance(const std::vector<double>& a, const std::vector<double>& b) {
    double s = 0;
    for (std::size_t i = 0; i < a.size(); ++i) s += (a[i] - b[i]) * (a[i] - b[i]);
    return std::sqrt(s);
}

// Per sample time |u - ref| / max_t |ref|.
std::vector<double> errors(const std::vector<std::vector<double>>& u, const std::vector<std::vector<double>>& ref) {
    double scale = 0;
    for (const auto& r : ref) scale = std::max(scale, norm(r));
    std::vector<double> e;
    for (std::size_t k = 0; k < ref.size(); ++k) e.push_back(distance(u[k], ref[k]) / scale);
    return e;
}

double max_of(const std::vector<double>& e) {
    double m = 0;
    for (double x : e) m = std::max(m, x);
    return m;
}

std::vector<std::vector<double>> extrapolate(const Run& fine, const Run& coarse) {
    std::vector<std::vector<double>> out = fine.u;
    for (std::size_t k = 0; k < out.size(); ++k)
        for (std::size_t i = 0; i < out[k].size(); ++i) out[k][i] = (4 * fine.u[k][i] - coarse.u[k][i]) / 3;
    return out;
}

void print_modes(const Setup& st) {
    const lab::LinearModes md = lab::linear_modes(st.scene);
    const auto n = md.omega.size();
    constexpr double two_pi = 2 * M_PI;
    std::printf("\nlinearised modes (K at rest, lumped M, %ld free dofs): lowest frequencies (Hz):", long(n));
    for (Eigen::Index i = 0; i < std::min<Eigen::Index>(n, 12); ++i) std::printf(" %.1f", md.omega[i] / two_pi);
    std::printf("; highest %.0f\n", md.omega[n - 1] / two_pi);
    const Eigen::VectorXd q = lab::modal_coordinates(md, st.u0);
    const double u0_norm = norm(lab::modal_displacement(md, q, st.u0.size()));
    const double bands[] = {0, 30, 100, 300, 1000, 1e9};
    std::printf("the released shape by band: | band (Hz) | modes | share of |u0| | share of the elastic energy |\n");
    double energy = 0;
    for (Eigen::Index i = 0; i < n; ++i) energy += 0.5 * md.omega[i] * md.omega[i] * q[i] * q[i];
    for (int b = 0; b < 5; ++b) {
        Eigen::VectorXd part = Eigen::VectorXd::Zero(n);
        double e = 0;
        int count = 0;
        for (Eigen::Index i = 0; i < n; ++i) {
            const double fi = md.omega[i] / two_pi;
            if (fi < bands[b] || fi >= bands[b + 1]) continue;
            part[i] = q[i];
            e += 0.5 * md.omega[i] * md.omega[i] * q[i] * q[i];
            ++count;
        }
        std::printf("| %g-%g | %d | %.3g | %.3g |\n", bands[b], bands[b + 1], count,
                    norm(lab::modal_displacement(md, part, st.u0.size())) / u0_norm, e / energy);
    }
    // u(t) = sum phi_i q_i x_i(t): the exact motion at the sample times, and
    // per integrator and dt each mode's error q_i (x_i - cos(omega_i t)) there
    auto displacement_norm = [&](const Eigen::VectorXd& c) { return norm(lab::modal_displacement(md, c, st.u0.size())); };
    double scale = 0;
    for (int k = 1; k <= kSamples; ++k)
        scale = std::max(scale, displacement_norm(q.cwiseProduct((md.omega * (st.span * k / kSamples)).array().cos().matrix())));
    const double cutoffs[] = {0, 30, 100, 300};
    std::printf("the linearised bar's error (max over the %d sample times / max |u|), from the modes above a frequency:\n"
                "| integrator | dt (ms) | all modes | above 30 Hz | above 100 Hz | above 300 Hz |\n|---|---:|---:|---:|---:|---:|\n",
                kSamples);
    for (Integrator integ : {Integrator::Implicit, Integrator::Newmark, Integrator::GeneralizedAlpha, Integrator::Bdf2})
        for (double dt : {1e-3, 5e-4, 2.5e-4, 1.25e-4}) {
            const long steps = std::lround(st.span / dt);
            Eigen::MatrixXd error(n, kSamples);
            for (Eigen::Index i = 0; i < n; ++i) {
                const std::vector<double> x =
                    lab::mode_history(integ, st.scene.integrator_parameters, md.omega[i], dt, steps);
                const std::vector<double> exact = lab::exact_mode_history(md.omega[i], dt, steps);
                for (int k = 1; k <= kSamples; ++k) {
                    const auto at = std::size_t(steps * k / kSamples);
                    error(i, k - 1) = q[i] * (x[at] - exact[at]);
                }
            }
            std::printf("| %s | %g |", to_string(integ), dt * 1e3);
            for (double cut : cutoffs) {
                double worst = 0;
                for (int k = 0; k < kSamples; ++k) {
                    Eigen::VectorXd c = error.col(k);
                    for (Eigen::Index i = 0; i < n; ++i)
                        if (md.omega[i] / two_pi < cut) c[i] = 0;
                    worst = std::max(worst, displacement_norm(c) / scale);
                }
                std::printf(" %.3g |", worst);
            }
            std::printf("\n");
        }
}

}  // namespace

int main(int argc, char** argv) {
    const double degrees = argc > 1 ? std::atof(argv[1]) : 90;
    const std::string shape = argc > 2 ? argv[2] : "linear";
    const double span = argc > 3 ? std::atof(argv[3]) : 0.5;
    const bool modes_only = argc > 4 && std::string(argv[4]) == "modes-only";
    if (!(degrees > 0 && degrees <= 360) || (shape != "linear" && shape != "mode") || !(span > 0 && span <= 10) ||
        (argc > 4 && !modes_only) || argc > 5) {
        std::fprintf(stderr,
                     "usage: edgefem_twist_study [DEGREES in (0, 360] [linear|mode [SECONDS in (0, 10] [modes-only]]]]\n");
        return 2;
    }
    const Setup st = make_setup(degrees, shape == "mode", span);
    std::printf("twisted bar released from %g degrees (%s profile), %g s, %d sample times\n", degrees, shape.c_str(), span,
                kSamples);
    print_modes(st);
    if (modes_only) return 0;

    const Run ref = simulate(st, Integrator::Verlet, 2.5e-6), ref2 = simulate(st, Integrator::Verlet, 5e-6);
    if (!ref.failure.empty() || !ref2.failure.empty()) {
        std::fprintf(stderr, "reference failed: %s%s\n", ref.failure.c_str(), ref2.failure.c_str());
        return 3;
    }
    const auto uref = extrapolate(ref, ref2);
    std::printf("reference: verlet at 2.5 us and 5 us, extrapolated (%.1f s); its error estimate |u(2.5) - u(5)| / 3: "
                "%.3g\n",
                ref.wall_s + ref2.wall_s, max_of(errors(ref.u, ref2.u)) / 3);
    const Run h1 = simulate(st, Integrator::Newmark, 2e-5), h2 = simulate(st, Integrator::Newmark, 4e-5);
    if (h1.failure.empty() && h2.failure.empty())
        std::printf("the harness's reference (newmark 20 & 40 us, extrapolated): error %.3g against it; plain 20 us: "
                    "%.3g; its own estimate |u(20) - u(40)| / 3: %.3g\n",
                    max_of(errors(extrapolate(h1, h2), uref)), max_of(errors(h1.u, uref)),
                    max_of(errors(h1.u, h2.u)) / 3);
    std::vector<double> perturbed = st.u0;
    for (std::size_t i = 0; i < perturbed.size(); ++i) perturbed[i] *= 1 + 1e-9;
    const Run p = simulate(st, Integrator::Verlet, 5e-6, &perturbed);
    if (p.failure.empty()) {
        const auto e = errors(p.u, ref2.u);
        std::printf("sensitivity: a 1e-9 relative change of the initial twist changes the trajectory by");
        for (double x : e) std::printf(" %.2g", x / 1e-9);
        std::printf(" x 1e-9 at the sample times\n");
    }

    std::printf("\n| integrator | dt (ms) | error | order | halvings | / backward Euler | wall s |\n|---|---:|---:|---:|---:|---:|---:|\n");
    const std::vector<double> dts = {1e-3, 5e-4, 2.5e-4, 1.25e-4};
    std::vector<double> be(dts.size(), NAN);
    std::vector<std::vector<double>> at_1ms;
    for (Integrator integ : {Integrator::Implicit, Integrator::Newmark, Integrator::GeneralizedAlpha, Integrator::Bdf2}) {
        double previous = NAN;
        for (std::size_t j = 0; j < dts.size(); ++j) {
            const Run r = simulate(st, integ, dts[j]);
            if (!r.failure.empty()) {
                std::printf("| %s | %g | failed: %s | | | | |\n", to_string(integ), dts[j] * 1e3, r.failure.c_str());
                previous = NAN;
                continue;
            }
            const auto e = errors(r.u, uref);
            const double err = max_of(e);
            if (integ == Integrator::Implicit) be[j] = err;
            if (j == 0 && (integ == Integrator::Implicit || integ == Integrator::Newmark)) at_1ms.push_back(e);
            char order[16] = "";
            if (std::isfinite(previous)) std::snprintf(order, sizeof order, "%.2f", std::log2(previous / err));
            std::printf("| %s | %g | %.3g | %s | %ld | %.3f | %.2f |\n", to_string(integ), dts[j] * 1e3, err, order,
                        r.halvings, err / be[j], r.wall_s);
            std::fflush(stdout);
            previous = err;
        }
    }
    if (at_1ms.size() == 2) {
        std::printf("\nerror at the sample times, dt = 1 ms:\n| t (s) | backward Euler | newmark | ratio |\n|---:|---:|---:|---:|\n");
        for (int k = 0; k < kSamples; ++k)
            std::printf("| %.3g | %.3g | %.3g | %.3f |\n", span * (k + 1) / kSamples, at_1ms[0][k], at_1ms[1][k],
                        at_1ms[1][k] / at_1ms[0][k]);
    }
}
