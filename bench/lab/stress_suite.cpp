// The stability stress suite: see stress_suite.hpp.
#include "lab/stress_suite.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <random>
#include <span>
#include <sstream>

#include "edgefem/core/make_box.hpp"
#include "edgefem/core/material.hpp"
#include "edgefem/core/mesh_quality.hpp"
#include "edgefem/core/simulator.hpp"
#include "edgefem/parallel/cpu_backend.hpp"

namespace edgefem {

const char* to_string(StressVerdict v) {
    switch (v) {
        case StressVerdict::Pass: return "pass";
        case StressVerdict::CleanFailure: return "failed cleanly";
        case StressVerdict::Reported: return "reported";
        default: return "FAIL";
    }
}

const char* to_string(StressExpectation e) {
    switch (e) {
        case StressExpectation::Pass: return "pass";
        case StressExpectation::Fail: return "fail";
        default: return "either";
    }
}

namespace {

constexpr double kAlpha = 10;  // mass-proportional damping (1/s)
constexpr int kHalvings = 3;   // solver.max_step_halvings: a failed step is retried as halves

struct Stage {
    std::vector<Prescribed> targets;
    double duration = 0;   // s
    double ramp = 0;       // s over which the targets are reached (0: in one step)
};

struct Case {
    std::string group, name;
    Scene base;  // mesh, material, fixed, damping (integrator and dt set per run)
    std::vector<double> u0, v0;
    std::vector<Stage> stages;
    bool recovery_required = true;
    bool large_deformation = false;  // explicit: the rest-shape CFL estimate is optimistic
    double dt = 0;                   // 0: the integrator's default
    double size = 0;                 // longest bounding-box side
    double dt_cfl = 0;
};

double bbox_size(const Mesh& m) {
    double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
    for (index_t v = 0; v < m.num_vertices(); ++v)
        for (int r = 0; r < 3; ++r) {
            lo[r] = std::min(lo[r], m.X[3 * v + r]);
            hi[r] = std::max(hi[r], m.X[3 * v + r]);
        }
    return std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
}

double coord_min(const Mesh& m, int r) {
    double lo = 1e300;
    for (index_t v = 0; v < m.num_vertices(); ++v) lo = std::min(lo, m.X[3 * v + r]);
    return lo;
}
double coord_max(const Mesh& m, int r) {
    double hi = -1e300;
    for (index_t v = 0; v < m.num_vertices(); ++v) hi = std::max(hi, m.X[3 * v + r]);
    return hi;
}

std::vector<index_t> select(const Mesh& m, int axis, double value, double tol = 1e-9) {
    std::vector<index_t> out;
    for (index_t v = 0; v < m.num_vertices(); ++v)
        if (std::abs(m.X[3 * v + axis] - value) <= tol) out.push_back(v);
    return out;
}

// Smallest altitude of any tet over the P-wave speed: the explicit step's
// stability scale for lumped masses (an estimate, not a bound).
double cfl_estimate(const Mesh& m, const Material& mat) {
    const double E = mat.young, nu = mat.poisson;
    const double lambda = E * nu / ((1 + nu) * (1 - 2 * nu)), mu = E / (2 * (1 + nu));
    const double cp = std::sqrt((lambda + 2 * mu) / mat.density);
    double hmin = 1e300;
    for (index_t t = 0; t < m.num_tets(); ++t) {
        const double* x[4];
        for (int k = 0; k < 4; ++k) x[k] = &m.X[3 * std::size_t(m.tets[4 * t + k])];
        const double vol = std::abs(signed_volume(x[0], x[1], x[2], x[3]));
        for (int k = 0; k < 4; ++k) {  // face opposite vertex k
            const double* a = x[(k + 1) % 4];
            const double* b = x[(k + 2) % 4];
            const double* c = x[(k + 3) % 4];
            const double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
            const double e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
            const double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                                 e1[0] * e2[1] - e1[1] * e2[0]};
            const double area = 0.5 * std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
            hmin = std::min(hmin, 3 * vol / area);
        }
    }
    return hmin / cp;
}

Scene base_scene(Mesh mesh, const Material& mat) {
    Scene s;
    s.mesh = std::move(mesh);
    s.materials = mat;
    s.rayleigh_alpha = kAlpha;
    s.count_inverted_tets = true;
    s.solver.max_step_halvings = kHalvings;
    // The guard asked for the suite's own bound: with the default 10, a run
    // whose halved steps hold it just under 10x went on without an error
    // and was then judged silent garbage by the 2x rule below.
    s.solver.max_energy_growth = kEnergyGrowthFactor;
    return s;
}

Case finish(Case c) {
    c.size = bbox_size(c.base.mesh);
    c.dt_cfl = cfl_estimate(c.base.mesh, c.base.materials.fallback);
    if (c.base.rayleigh_beta > 0) {  // stiffness damping: 2 (sqrt(1 + xi^2) - xi) / omega_max, xi = beta omega_max / 2
        const double xi = c.base.rayleigh_beta / c.dt_cfl;
        c.dt_cfl *= std::sqrt(1 + xi * xi) - xi;
    }
    return c;
}

// A 6 x 2 x 2 cm bar clamped at x = min, released from a bend: u_z = 0.2 L s^2.
Case bent_bar(const std::string& group, const std::string& name, const Material& mat, double dt = 0) {
    Case c;
    c.group = group;
    c.name = name;
    c.dt = dt;
    c.base = base_scene(make_box(6, 2, 2, 0.01), mat);
    const Mesh& m = c.base.mesh;
    const double x0 = coord_min(m, 0), L = coord_max(m, 0) - x0;
    c.base.fixed = select(m, 0, x0);
    c.u0.assign(m.X.size(), 0.0);
    for (index_t v = 0; v < m.num_vertices(); ++v) {
        const double s = (m.X[3 * v] - x0) / L;
        c.u0[3 * v + 2] = 0.2 * L * s * s;
    }
    return finish(std::move(c));
}

Material default_material() { return Material{1e5, 0.3, 1000}; }

std::string sci(double x) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", x);
    return buf;
}

std::vector<Case> make_cases(bool quick) {
    std::vector<Case> cases;
    // Time steps (all integrators at the same dt).
    const std::vector<std::pair<double, std::string>> dts =
        quick ? std::vector<std::pair<double, std::string>>{{1e-3, "1e-3"}, {1.0 / 30, "1/30"}}
              : std::vector<std::pair<double, std::string>>{{1e-4, "1e-4"}, {1e-3, "1e-3"}, {1e-2, "1e-2"}, {1.0 / 30, "1/30"}};
    for (const auto& [dt, label] : dts) cases.push_back(bent_bar("dt", "dt=" + label, default_material(), dt));
    // Young's modulus.
    for (double Y : quick ? std::vector<double>{1e9} : std::vector<double>{1e3, 1e5, 1e7, 1e9})
        cases.push_back(bent_bar("young", "young=" + sci(Y), Material{Y, 0.3, 1000}));
    // Poisson ratio.
    for (double nu : quick ? std::vector<double>{0.499} : std::vector<double>{0.0, 0.3, 0.45, 0.499})
        cases.push_back(bent_bar("poisson", "poisson=" + sci(nu), Material{1e5, nu, 1000}));

    // A 3 cm cube, bottom clamped, top face pushed down to 20% of the height
    // over 0.5 s, held 0.5 s, released.
    {
        Case c;
        c.group = "compress";
        c.name = "compress-20%";
        c.base = base_scene(make_box(3, 3, 3, 0.01), default_material());
        const Mesh& m = c.base.mesh;
        const double z0 = coord_min(m, 2), z1 = coord_max(m, 2);
        c.base.fixed = select(m, 2, z0);
        Stage st;
        for (index_t v : select(m, 2, z1))
            st.targets.push_back({v, {m.X[3 * v], m.X[3 * v + 1], z0 + 0.2 * (z1 - z0)}});
        st.duration = 1.0;
        st.ramp = 0.5;
        c.stages.push_back(st);
        c.recovery_required = false;  // StVK softens under strong compression: it may stay inverted
        c.large_deformation = true;
        cases.push_back(finish(c));
        // The same with stiffness damping (beta = 1e-3 s, not with verlet):
        // the driven face drags the body through the damping, which the
        // energy guard counts as supplied work, and the explicit step builds
        // K and is stable only below about 2 / (beta omega_max^2).
        if (!quick) {
            c.group = "damping";
            c.name = "compress-20%-beta";
            c.base.rayleigh_beta = 1e-3;
            cases.push_back(finish(std::move(c)));
        }
    }
    // The bar's free-end corner vertex pushed through the opposite face of
    // one of its tets (mirrored across that face at 1.5x its distance).
    {
        Case c = bent_bar("invert", "vertex-through-face", default_material());
        const Mesh& m = c.base.mesh;
        c.u0.assign(m.X.size(), 0.0);
        const double x1 = coord_max(m, 0), y1 = coord_max(m, 1), z1 = coord_max(m, 2);
        index_t corner = -1;
        for (index_t v = 0; v < m.num_vertices(); ++v)
            if (std::abs(m.X[3 * v] - x1) < 1e-9 && std::abs(m.X[3 * v + 1] - y1) < 1e-9 &&
                std::abs(m.X[3 * v + 2] - z1) < 1e-9)
                corner = v;
        for (index_t t = 0; t < m.num_tets() && corner >= 0; ++t) {
            int k = -1;
            for (int j = 0; j < 4; ++j)
                if (m.tets[4 * t + j] == corner) k = j;
            if (k < 0) continue;
            const double* p = &m.X[3 * std::size_t(corner)];
            const double* a = &m.X[3 * std::size_t(m.tets[4 * t + (k + 1) % 4])];
            const double* b = &m.X[3 * std::size_t(m.tets[4 * t + (k + 2) % 4])];
            const double* cc = &m.X[3 * std::size_t(m.tets[4 * t + (k + 3) % 4])];
            const double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
            const double e2[3] = {cc[0] - a[0], cc[1] - a[1], cc[2] - a[2]};
            double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
            const double nn = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
            for (double& x : n) x /= nn;
            const double dist = (p[0] - a[0]) * n[0] + (p[1] - a[1]) * n[1] + (p[2] - a[2]) * n[2];
            for (int r = 0; r < 3; ++r) c.u0[3 * std::size_t(corner) + r] = -2.5 * dist * n[r];
            break;
        }
        c.recovery_required = false;  // StVK has inverted equilibria
        c.large_deformation = true;
        cases.push_back(std::move(c));
    }
    // Random noise on displacement (0.1 cell) and velocity (0.1 m/s) of every free vertex.
    {
        Case c = bent_bar("noise", "random-state", default_material());
        std::mt19937_64 rng(20260611);
        std::uniform_real_distribution<double> uni(-1.0, 1.0);
        c.v0.assign(c.u0.size(), 0.0);
        std::vector<char> fixed(c.base.mesh.num_vertices(), 0);
        for (index_t v : c.base.fixed) fixed[v] = 1;
        for (std::size_t i = 0; i < c.u0.size(); ++i) {
            c.u0[i] = fixed[i / 3] ? 0.0 : 0.1 * 0.01 * uni(rng);
            c.v0[i] = fixed[i / 3] ? 0.0 : 0.1 * uni(rng);
        }
        cases.push_back(std::move(c));
    }
    // Sliver tets: the interior vertices of a 4 x 4 x 4 cube moved (greedily,
    // orientation kept) to make the smallest tets as flat as possible; then a
    // 20% shear released, bottom clamped.
    {
        Mesh m = make_box(4, 4, 4, 0.01);
        const double lo = coord_min(m, 0), hi = coord_max(m, 0);
        std::vector<std::vector<index_t>> vt(m.num_vertices());
        for (index_t t = 0; t < m.num_tets(); ++t)
            for (int k = 0; k < 4; ++k) vt[m.tets[4 * t + k]].push_back(t);
        auto vol = [&](index_t t) {
            return signed_volume(&m.X[3 * std::size_t(m.tets[4 * t])], &m.X[3 * std::size_t(m.tets[4 * t + 1])],
                                 &m.X[3 * std::size_t(m.tets[4 * t + 2])], &m.X[3 * std::size_t(m.tets[4 * t + 3])]);
        };
        const double v_ref = 1e-6 / 6, v_floor = 2e-3 * v_ref;
        std::mt19937_64 rng(7);
        std::uniform_real_distribution<double> uni(-0.45, 0.45);
        for (index_t v = 0; v < m.num_vertices(); ++v) {
            bool interior = true;
            for (int r = 0; r < 3; ++r) interior = interior && m.X[3 * v + r] > lo + 1e-9 && m.X[3 * v + r] < hi - 1e-9;
            if (!interior) continue;
            const std::array<double, 3> x0 = {m.X[3 * v], m.X[3 * v + 1], m.X[3 * v + 2]};
            std::array<double, 3> best = x0;
            double best_min = 1e300;
            for (int trial = 0; trial < 200; ++trial) {
                for (int r = 0; r < 3; ++r) m.X[3 * v + r] = x0[r] + 0.01 * uni(rng);
                double vmin = 1e300;
                for (index_t t : vt[v]) vmin = std::min(vmin, vol(t));
                if (vmin > v_floor && vmin < best_min) {
                    best_min = vmin;
                    best = {m.X[3 * v], m.X[3 * v + 1], m.X[3 * v + 2]};
                }
            }
            for (int r = 0; r < 3; ++r) m.X[3 * v + r] = best[r];
        }
        Case c;
        c.group = "sliver";
        {
            const MeshQuality q = mesh_quality(m);
            char buf[64];
            std::snprintf(buf, sizeof buf, "sliver(min dih %.1fdeg)", q.min_dihedral_deg);
            c.name = buf;
        }
        c.base = base_scene(std::move(m), default_material());
        const Mesh& mm = c.base.mesh;
        const double z0 = coord_min(mm, 2);
        c.base.fixed = select(mm, 2, z0);
        c.u0.assign(mm.X.size(), 0.0);
        for (index_t v = 0; v < mm.num_vertices(); ++v) c.u0[3 * v] = 0.2 * (mm.X[3 * v + 2] - z0);
        cases.push_back(finish(std::move(c)));
    }
    // An 8 x 2 x 2 cm bar clamped at x = min, its x = max face turned by 180
    // degrees about the bar's axis over 0.5 s (90 stages of 2 degrees, each
    // reached in one step and held), then released.
    {
        Case c;
        c.group = "twist";
        c.name = "twist-180";
        c.base = base_scene(make_box(8, 2, 2, 0.01), default_material());
        const Mesh& m = c.base.mesh;
        c.base.fixed = select(m, 0, coord_min(m, 0));
        const auto end = select(m, 0, coord_max(m, 0));
        const int stages = 90;
        for (int k = 1; k <= stages; ++k) {
            const double th = M_PI * k / stages, cs = std::cos(th), sn = std::sin(th);
            Stage st;
            for (index_t v : end) {
                const double y = m.X[3 * v + 1], z = m.X[3 * v + 2];
                st.targets.push_back({v, {m.X[3 * v], cs * y - sn * z, sn * y + cs * z}});
            }
            st.duration = 0.5 / stages;
            c.stages.push_back(st);
        }
        c.large_deformation = true;
        cases.push_back(finish(std::move(c)));
    }
    return cases;
}

StressExpectation expectation(const Case& c, Integrator integ, double dt) {
    // The trapezoidal rule has no numerical damping: on stiff nonlinear
    // cases at large steps it may go unstable, which the energy guard must
    // catch (a clean failure).
    if (integ == Integrator::Newmark || integ == Integrator::NewmarkLinear) return StressExpectation::Either;
    if (!is_explicit(integ)) return StressExpectation::Pass;
    if (dt >= 4 * c.dt_cfl) return StressExpectation::Fail;
    if (dt <= 0.5 * c.dt_cfl && !c.large_deformation) return StressExpectation::Pass;
    return StressExpectation::Either;
}

double max_rel_displacement(std::span<const double> u, double size) {
    double m = 0;
    for (std::size_t v = 0; v < u.size() / 3; ++v)
        m = std::max(m, std::sqrt(u[3 * v] * u[3 * v] + u[3 * v + 1] * u[3 * v + 1] + u[3 * v + 2] * u[3 * v + 2]));
    return m / size;
}

StressResult run_case(const Case& c, Integrator integ, double seconds) {
    StressResult r;
    r.group = c.group;
    r.name = c.name;
    r.integrator = to_string(integ);
    r.dt = c.dt > 0 ? c.dt : (is_explicit(integ) ? 1e-4 : 1e-3);
    r.seconds = seconds;
    r.expected = expectation(c, integ, r.dt);
    r.recovery_required = c.recovery_required;
    r.dt_cfl = c.dt_cfl;
    r.recovery = std::nan("");
    const auto t0 = std::chrono::steady_clock::now();
    const long total = std::max<long>(1, std::lround(seconds / r.dt));
    std::vector<double> u = c.u0.empty() ? std::vector<double>(c.base.mesh.X.size(), 0.0) : c.u0;
    std::vector<double> v = c.v0.empty() ? std::vector<double>(u.size(), 0.0) : c.v0;
    bool energy_exceeded = false;
    std::string garbage;
    auto make = [&](const Stage* st) {
        Scene s = c.base;
        s.integrator = integ;
        s.dt = r.dt;
        if (st) {
            s.prescribed = st->targets;
            s.prescribed_steps = std::max<int>(1, int(std::lround(st->ramp / r.dt)));
        }
        auto sim = std::make_unique<Simulator<double>>(std::move(s), nullptr, cpu_operator_factory<double>());
        std::copy(u.begin(), u.end(), sim->displacement().begin());
        std::copy(v.begin(), v.end(), sim->velocity().begin());
        return sim;
    };
    auto note = [&](const StepStats& st) {
        r.max_inverted = std::max(r.max_inverted, st.inverted_tets);
        r.final_inverted = st.inverted_tets;
        if (is_linearised(integ) && st.residual > c.base.solver.cg_tolerance) ++r.unconverged_solves;
        r.halvings += st.halvings;
    };
    auto save = [&](Simulator<double>& sim) {
        std::copy(sim.displacement().begin(), sim.displacement().end(), u.begin());
        std::copy(sim.velocity().begin(), sim.velocity().end(), v.begin());
    };
    try {
        // Driven phase.
        for (const Stage& st : c.stages) {
            if (r.steps >= total) break;
            auto sim = make(&st);
            const long n = std::min(total - r.steps, std::max<long>(1, std::lround(st.duration / r.dt)));
            for (long k = 0; k < n; ++k) {
                try {
                    sim->step();
                } catch (const SimulationError& e) {
                    // The step number is the stage's: report the run's.
                    throw SimulationError(std::string(e.what()) + " (run step " + std::to_string(r.steps + 1) + ")",
                                          r.steps + 1, e.vertex());
                }
                ++r.steps;
                note(sim->last_stats());
            }
            save(*sim);
        }
        // Free phase.
        auto sim = make(nullptr);
        const double E0 = std::max(sim->energies().total(), 1e-300);
        const long left = total - r.steps;
        const long every = 1;  // every step: sampling misses transient spikes
        for (long k = 0; k < left; ++k) {
            sim->step();
            ++r.steps;
            note(sim->last_stats());
            if ((k + 1) % every == 0 || k + 1 == left) {
                const double E = sim->energies().total();
                // Keep stepping: the verdict is silent garbage only if the
                // run then ends without a SimulationError.
                if (!std::isfinite(E)) {
                    if (garbage.empty())
                        garbage = "non-finite energy (state still finite) from step " + std::to_string(r.steps);
                    r.energy_growth = HUGE_VAL;
                    energy_exceeded = true;
                    continue;
                }
                r.energy_growth = std::max(r.energy_growth, E / E0);
                if (E > kEnergyGrowthFactor * E0) energy_exceeded = true;
            }
        }
        save(*sim);
        r.simulated = r.steps * r.dt;
        r.recovery = max_rel_displacement(u, c.size);
        if (!garbage.empty()) {
            r.verdict = StressVerdict::Fail;
            r.reason = "silent garbage: " + garbage + ", and no error by the end";
        } else if (energy_exceeded) {
            r.verdict = StressVerdict::Fail;
            char buf[160];
            std::snprintf(buf, sizeof buf, "silent garbage: energy grew to %.3g x its value at release without an error",
                          r.energy_growth);
            r.reason = buf;
        } else if (c.recovery_required && !(r.recovery <= kRecoveryTolerance)) {
            r.verdict = r.final_inverted > 0 ? StressVerdict::Reported : StressVerdict::Fail;
            char buf[240];
            std::snprintf(buf, sizeof buf, "did not recover: max |u| = %.3g of the body size (tolerance %.0e)",
                          r.recovery, kRecoveryTolerance);
            r.reason = buf;
            if (r.final_inverted > 0)
                r.reason += ", settled with tets inverted (StepStats::inverted_tets reports them): " +
                            std::to_string(r.final_inverted) + " at the end";
        } else {
            r.verdict = StressVerdict::Pass;
            char buf[200];
            std::snprintf(buf, sizeof buf, "finite; energy <= %.3g x release; %s max |u| = %.2g of size", r.energy_growth,
                          c.recovery_required ? "recovered," : "(recovery not required)", r.recovery);
            r.reason = buf;
        }
    } catch (const SimulationError& e) {
        r.verdict = StressVerdict::CleanFailure;
        r.simulated = r.steps * r.dt;
        r.reason = std::string("failed cleanly with error: ") + e.what();
        if (!garbage.empty()) {
            r.reason += " (before it: " + garbage + ")";
        } else if (energy_exceeded) {
            char buf[120];
            std::snprintf(buf, sizeof buf, " (energy had grown to %.3g x release before)", r.energy_growth);
            r.reason += buf;
        }
    } catch (const std::exception& e) {
        r.verdict = StressVerdict::Fail;
        r.simulated = r.steps * r.dt;
        r.reason = std::string("unexpected exception (not a SimulationError): ") + e.what();
    }
    r.unexpected = (r.verdict == StressVerdict::Pass && r.expected == StressExpectation::Fail) ||
                   ((r.verdict == StressVerdict::CleanFailure || r.verdict == StressVerdict::Reported) &&
                    r.expected == StressExpectation::Pass);
    r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return r;
}

std::string json_escape(const std::string& s) {
    std::string o;
    for (char ch : s) {
        if (ch == '"' || ch == '\\') {
            o += '\\';
            o += ch;
        } else if (static_cast<unsigned char>(ch) < 0x20) {
            o += ' ';
        } else {
            o += ch;
        }
    }
    return o;
}

std::string num(double x) {
    if (!std::isfinite(x)) return "null";
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.9g", x);
    return buf;
}

}  // namespace

std::vector<StressResult> run_stress_suite(const StressOptions& opts) {
    std::vector<StressResult> out;
    const double seconds = opts.quick ? opts.quick_seconds : opts.seconds;
    for (const Case& c : make_cases(opts.quick))
        for (const auto& [name, integ] : integrator_names()) {
            if (integ == Integrator::Verlet && c.base.rayleigh_beta > 0) continue;  // verlet takes no beta
            const std::string key = c.group + " " + c.name + " " + to_string(integ);
            if (!opts.filter.empty() && key.find(opts.filter) == std::string::npos) continue;
            out.push_back(run_case(c, integ, seconds));
            if (opts.on_result) opts.on_result(out.back());
        }
    return out;
}

std::string format_stress_table(const std::vector<StressResult>& results) {
    std::ostringstream os;
    char buf[512];
    std::snprintf(buf, sizeof buf, "%-22s %-24s %-8s %-7s %-16s %7s %9s %6s %5s %6s %8s  %s\n", "case", "integrator", "dt",
                  "expect", "verdict", "sim_s", "E_growth", "cg_unc", "halv", "inv", "wall_s", "reason");
    os << buf;
    int pass = 0, clean = 0, reported = 0, fail = 0, unexpected = 0;
    for (const auto& r : results) {
        std::string verdict = to_string(r.verdict);
        if (r.unexpected) verdict += "(!)";
        std::snprintf(buf, sizeof buf, "%-22s %-24s %-8.3g %-7s %-16s %7.3f %9.3g %6ld %5ld %6ld %8.2f  %s\n",
                      r.name.c_str(), r.integrator.c_str(), r.dt, to_string(r.expected), verdict.c_str(), r.simulated,
                      r.energy_growth, r.unconverged_solves, r.halvings, long(r.max_inverted), r.wall_s, r.reason.c_str());
        os << buf;
        pass += r.verdict == StressVerdict::Pass;
        clean += r.verdict == StressVerdict::CleanFailure;
        reported += r.verdict == StressVerdict::Reported;
        fail += r.verdict == StressVerdict::Fail;
        unexpected += r.unexpected;
    }
    std::snprintf(buf, sizeof buf,
                  "summary: %zu runs: %d pass, %d failed cleanly, %d reported (not recovered, tets inverted at the "
                  "end), %d FAIL (silent garbage or no recovery); %d against expectation (marked (!))\n",
                  results.size(), pass, clean, reported, fail, unexpected);
    os << buf;
    return os.str();
}

std::string stress_results_json(const std::vector<StressResult>& results) {
    std::ostringstream os;
    os << "[\n";
    for (std::size_t i = 0; i < results.size(); ++i) {
        const auto& r = results[i];
        os << "  {\"group\": \"" << json_escape(r.group) << "\", \"name\": \"" << json_escape(r.name)
           << "\", \"integrator\": \"" << r.integrator << "\", \"dt\": " << num(r.dt) << ", \"seconds\": " << num(r.seconds)
           << ", \"simulated\": " << num(r.simulated) << ", \"steps\": " << r.steps << ", \"expected\": \""
           << to_string(r.expected) << "\", \"verdict\": \"" << to_string(r.verdict)
           << "\", \"unexpected\": " << (r.unexpected ? "true" : "false") << ", \"reason\": \"" << json_escape(r.reason)
           << "\", \"recovery_required\": " << (r.recovery_required ? "true" : "false")
           << ", \"recovery\": " << num(r.recovery) << ", \"energy_growth\": " << num(r.energy_growth)
           << ", \"max_inverted\": " << r.max_inverted << ", \"final_inverted\": " << r.final_inverted
           << ", \"unconverged_solves\": " << r.unconverged_solves
           << ", \"halvings\": " << r.halvings << ", \"dt_cfl\": " << num(r.dt_cfl)
           << ", \"wall_s\": " << num(r.wall_s) << "}" << (i + 1 < results.size() ? "," : "") << "\n";
    }
    os << "]\n";
    return os.str();
}

}  // namespace edgefem
