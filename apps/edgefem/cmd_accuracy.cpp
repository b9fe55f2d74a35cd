// `edgefem accuracy`: run time against error on standard dynamic scenes.
//
// Scenes (no damping but in the three damped ones, so energy drift is
// purely numerical there):
//  cantilever  box 12x3x3 (0.12 m, 648 tets), Y = 2e5, nu = 0.35, clamped at
//              x = min, released from rest under gravity -z;
//  twist       box 10x2x2 (0.1 m, 240 tets), Y = 1e5, nu = 0.3, clamped at
//              x = min, released from a 90-degree twist (linear in x) at rest;
//  bunny       bunny-4k (a generated box of the same size without
//              ../shared/meshes), Y = 5e4, nu = 0.4, the lowest 5% of its
//              height fixed, released from rest under gravity -y;
//  slender     box 48x3x3 of 5 mm cells (0.24 x 0.015 m, 2592 tets), Y = 1e7,
//              nu = 0.45 (stiff rubber), clamped at x = min, released from
//              rest under gravity -z;
//  press       bunny-4k as above, Y = 5e4, nu = 0.49 (nearly
//              incompressible, like soft tissue), the lowest 5 % fixed, the
//              highest 10 % pressed down by 10 % of the height as by a flat
//              tool, smoothly (s(t) = (1 - cos(pi t / 0.3 s)) / 2, keyframes
//              every 10 ms), then held; no gravity;
//  shake       box 48x3x3 of 5 mm cells (2592 tets), Y = 1e6, nu = 0.45,
//              its x = min face moved 20 mm in z in 0.1 s (the same smooth
//              curve) and held: it swings freely after; no gravity;
//  shake-fine  the same beam of 2.5 mm cells (96x6x6, 20,736 tets): the
//              explicit stable step halves, the motion does not change;
//  shake-finer and of 1.25 mm cells (192x12x12, 165,888 tets), only by
//              --scene (about 30 min), against a velocity Verlet reference;
//  shake-rubber shake's beam with nu = 0.49, only by --scene (1 min);
//  shake-damped, bunny-damped, cantilever-damped  shake, the bunny and
//              the cantilever with Rayleigh stiffness damping beta = 1e-3 s
//              (not in --quick): the explicit step builds K for it and is
//              stable only far below its undamped step.
// The stiff ones (slender to shake-rubber) are where the explicit stable
// step is far below the step the motion needs: a fine, thin or nearly
// incompressible body, whose fastest (pressure) wave crosses a cell in
// microseconds, moved slowly or bending in a few Hz. They separate three
// cases: released at once (slender), the second bending mode swings with a
// few % of the amplitude and a step too long for it cannot follow; driven
// slowly (press), the motion is nearly static and first-order backward
// Euler at a long step is as accurate as anything; shaken and then free
// (shake), the first mode swings undamped: the case the implicit
// second-order integrators are for.
//
// Each scene has a reference trajectory: the trapezoidal rule (Newmark beta
// = 1/4, gamma = 1/2, second order) solved by Newton (relative tolerance
// 1e-10) at a small dt_ref and at 2 dt_ref, double, edge FE, combined by
// Richardson extrapolation ((4 u(dt_ref) - u(2 dt_ref)) / 3 cancels the
// leading error term), cached on disk under --cache keyed by an FNV-1a hash
// of everything that defines it. |u(dt_ref) - u(2 dt_ref)| / 3 (the plain
// dt_ref run's own error, estimated from the two steps; the extrapolation's
// is smaller) is printed as ref_error: a row whose error is not at least
// 10 x ref_error says the reference cannot resolve it. Each
// configuration (integrator, dt, CG tolerance or fixed iterations or the direct solve, float or
// double, FE or SN, definite K, edge or per-tet) is run over the same span
// and compared at the sample times:
//  error      max over sample times of |u - u_ref|_2 / max_t |u_ref(t)|_2
//  drift      (E(T) - E(0)) / max_t (kinetic + elastic), E the total energy
//             (kinetic + elastic + gravity potential)
//  wall_per_s wall-clock seconds per simulated second (1 thread).
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>

#include "edgefem/parallel/cpu_backend.hpp"
#include "edgefem/core/error.hpp"
#include "edgefem/core/make_box.hpp"
#include "lab/named_mesh.hpp"
#include "edgefem/core/simulator.hpp"
#include "edgefem/core/validate_mesh.hpp"
#include "option_checks.hpp"
#include "evidence_commands.hpp"

namespace edgefem::cli {

namespace {

using Clock = std::chrono::steady_clock;

struct AccScene {
    std::string name, mesh_origin;
    Scene scene;                 // integrator / dt / solver set per configuration
    std::vector<double> u0;      // initial displacement (empty: rest)
    double duration = 0;         // simulated seconds
    int samples = 0;             // sample times duration * k / samples, k = 1..samples: every 50 ms
    double dt_ref = 0;
    // The reference's integrator: the trapezoidal rule by Newton, or
    // velocity Verlet (second order too) where its stable step is below
    // dt_ref anyway and a Newton step costs hundreds of explicit ones.
    Integrator ref_integrator = Integrator::Newmark;
    bool costly = false;  // explicit steps of ms: only the configurations the targets compare (costly_configs)
    std::vector<double> explicit_dts;  // the stiff scenes' explicit and Verlet steps
};

struct Config {
    std::string label;
    Integrator integrator = Integrator::SemiImplicit;
    double dt = 1e-3;
    double cg_tol = 1e-6;
    int cg_fixed = 0;
    bool single = false;
    ModelKind model = ModelKind::FE;
    bool definite = false;
    Method method = Method::Edge;
    bool direct = false;  // solver.linear = direct (CHOLMOD) instead of CG
};

struct Trajectory {
    std::vector<std::vector<double>> u;  // at the sample times
    std::vector<Energies> energy;        // at t = 0 and the sample times
    double wall_s = 0;
    double cg_mean = 0;
    long steps = 0;
    long halvings = 0;  // step halvings used (solver.max_step_halvings = 3)
    bool failed = false;
    std::string message;
};

double coord(const Mesh& m, int axis, bool max) {
    double v = max ? -1e300 : 1e300;
    for (index_t i = 0; i < m.num_vertices(); ++i) v = max ? std::max(v, m.X[3 * i + axis]) : std::min(v, m.X[3 * i + axis]);
    return v;
}

std::vector<index_t> below(const Mesh& m, int axis, double limit) {
    std::vector<index_t> out;
    for (index_t i = 0; i < m.num_vertices(); ++i)
        if (m.X[3 * i + axis] <= limit) out.push_back(i);
    return out;
}

std::vector<AccScene> make_scenes(bool quick, const std::string& mesh_folder, const std::string& only) {
    std::vector<AccScene> out;
    const double span = quick ? 0.5 : 1.0;
    // Clamped at x = min, released from rest under gravity -z (explicit_dts
    // empty: the standard configurations).
    auto clamped_under_gravity = [&](const char* name, const char* origin, Mesh mesh, Material mat, double dt_ref,
                                     std::vector<double> explicit_dts) {
        AccScene d;
        d.name = name;
        d.mesh_origin = origin;
        d.scene.mesh = std::move(mesh);
        d.scene.materials = mat;
        d.scene.gravity = {0, 0, -9.81};
        d.scene.fixed = below(d.scene.mesh, 0, coord(d.scene.mesh, 0, false) + 1e-9);
        d.duration = 0.5 * span;
        d.samples = int(10 * span);
        d.dt_ref = dt_ref;
        d.explicit_dts = std::move(explicit_dts);
        out.push_back(std::move(d));
    };
    if (only.empty() || only == "cantilever")
        clamped_under_gravity("cantilever", "box 12x3x3", make_box(12, 3, 3, 0.01), Material{2e5, 0.35, 1000}, 2e-5, {});
    if (only.empty() || only == "twist") {
        AccScene b;
        b.name = "twist";
        b.mesh_origin = "box 10x2x2";
        b.scene.mesh = make_box(10, 2, 2, 0.01);
        b.scene.materials = Material{1e5, 0.3, 1000};
        const Mesh& m = b.scene.mesh;
        const double x0 = coord(m, 0, false), L = coord(m, 0, true) - x0;
        b.scene.fixed = below(m, 0, x0 + 1e-9);
        b.u0.assign(m.X.size(), 0.0);
        for (index_t v = 0; v < m.num_vertices(); ++v) {
            const double th = 0.5 * M_PI * (m.X[3 * v] - x0) / L, y = m.X[3 * v + 1], z = m.X[3 * v + 2];
            b.u0[3 * v + 1] = std::cos(th) * y - std::sin(th) * z - y;
            b.u0[3 * v + 2] = std::sin(th) * y + std::cos(th) * z - z;
        }
        b.duration = 0.5 * span;
        b.samples = int(10 * span);
        b.dt_ref = 2e-5;
        out.push_back(std::move(b));
    }
    // bunny-4k standing on the lowest 5 % of its height (y).
    auto standing_bunny = [&](const char* name, Material mat) {
        AccScene d;
        d.name = name;
        Mesh m = load_named_mesh(mesh_folder, "bunny-4k", &d.mesh_origin);
        validate_mesh(m);
        d.scene.mesh = std::move(m);
        d.scene.materials = mat;
        const double y0 = coord(d.scene.mesh, 1, false), y1 = coord(d.scene.mesh, 1, true);
        d.scene.fixed = below(d.scene.mesh, 1, y0 + 0.05 * (y1 - y0));
        return d;
    };
    if (only.empty() || only == "bunny") {
        AccScene c = standing_bunny("bunny", Material{5e4, 0.4, 1000});
        c.scene.gravity = {0, -9.81, 0};
        c.duration = 0.3 * span;
        c.samples = int(6 * span);
        c.dt_ref = 5e-5;
        out.push_back(std::move(c));
    }
    if (only.empty() || only == "slender")
        clamped_under_gravity("slender", "box 48x3x3, 5 mm", make_box(48, 3, 3, 0.005), Material{1e7, 0.45, 1000}, 1e-4,
                              {1e-5, 1.25e-5, 2e-5});
    // Driven smoothly from rest by prescribed vertices: the fraction
    // (1 - cos(pi t / T)) / 2 of their displacement up to T, then 1
    // (keyframes every T / 30).
    auto smooth_drive = [&](AccScene& d, const std::vector<index_t>& moved, std::array<double, 3> by, double T) {
        for (index_t v : moved)
            d.scene.prescribed.push_back({v, {d.scene.mesh.X[3 * v] + by[0], d.scene.mesh.X[3 * v + 1] + by[1],
                                              d.scene.mesh.X[3 * v + 2] + by[2]}});
        for (int k = 0; k <= 30; ++k)
            d.scene.prescribed_keyframes.push_back({T * k / 30.0, 0.5 * (1 - std::cos(M_PI * k / 30.0))});
        d.duration = 0.5 * span;
        d.samples = int(10 * span);
        d.dt_ref = 1e-4;
    };
    if (only.empty() || only == "press") {
        AccScene d = standing_bunny("press", Material{5e4, 0.49, 1000});
        const double y0 = coord(d.scene.mesh, 1, false), y1 = coord(d.scene.mesh, 1, true);
        std::vector<index_t> top;
        for (index_t v = 0; v < d.scene.mesh.num_vertices(); ++v)
            if (d.scene.mesh.X[3 * v + 1] >= y1 - 0.1 * (y1 - y0)) top.push_back(v);
        smooth_drive(d, top, {0, -0.1 * (y1 - y0), 0}, 0.3);
        d.explicit_dts = {1e-5, 1.25e-5, 2e-5};
        out.push_back(std::move(d));
    }
    // Swinging freely after a shake: the clamped face (x = min) moved 20 mm
    // in z in 0.1 s, smoothly, then held; no gravity. A smooth 0.1 s move
    // sets the first bending mode swinging and the second hardly at all, so
    // the motion is slow next to the explicit step.
    auto shaken_beam = [&](const char* name, const char* origin, int refine, std::vector<double> explicit_dts,
                           double poisson = 0.45) {
        AccScene d;
        d.name = name;
        d.mesh_origin = origin;
        d.scene.mesh = make_box(48 * refine, 3 * refine, 3 * refine, 0.005 / refine);
        d.scene.materials = Material{1e6, poisson, 1000};
        const std::vector<index_t> face = below(d.scene.mesh, 0, coord(d.scene.mesh, 0, false) + 1e-9);
        smooth_drive(d, face, {0, 0, 0.02}, 0.1);
        d.explicit_dts = std::move(explicit_dts);
        out.push_back(std::move(d));
    };
    if (only.empty() || only == "shake") shaken_beam("shake", "box 48x3x3, 5 mm", 1, {2.5e-5, 4e-5, 5e-5});
    // The same beam nearly incompressible (nu = 0.49, as rubber is modelled):
    // the pressure wave 2.1x faster, the explicit stable step 2.1x shorter
    // (2e-5 stable, 2.5e-5 not), the bending motion hardly changed. Only by
    // --scene: it showed that this does not favour the implicit steps
    // (docs/lab/2026-11-28-shake-rubber.md).
    if (only == "shake-rubber")
        shaken_beam("shake-rubber", "box 48x3x3, 5 mm", 1, {1.25e-5, 2e-5, 2.5e-5}, 0.49);
    // The same beam of 2.5 mm cells: the explicit stable step halves (its
    // limit lies between 25 and 28 us), the motion and the step it needs
    // stay.
    if (only.empty() || only == "shake-fine")
        shaken_beam("shake-fine", "box 96x6x6, 2.5 mm", 2, {1.25e-5, 2e-5, 2.5e-5});
    // And of 1.25 mm cells (165,888 tets; explicit stable up to 12.5-14 us):
    // not in --quick or the full run, only by --scene (~30 min).
    if (only == "shake-finer") {
        if (quick) throw Error("accuracy: --scene shake-finer has no --quick run (its explicit rows take minutes each)");
        shaken_beam("shake-finer", "box 192x12x12, 1.25 mm", 4, {1e-5, 1.25e-5});
        out.back().ref_integrator = Integrator::Verlet;
        out.back().dt_ref = 5e-6;
        out.back().costly = true;
    }
    // Damped: Rayleigh stiffness damping beta = 1e-3 s (damping.beta), which
    // damps a mode of angular frequency omega at beta omega / 2 of critical:
    // lightly the slow bending that is the motion, heavily what a shake or
    // release sets ringing above it. The explicit step builds and applies K
    // for it and is stable only below about 2 / (beta omega_max^2)
    // (integrators/explicit_euler.cpp): about 1.25 us on shake's beam, whose
    // undamped explicit step is 50 us; Verlet takes no beta. Not in --quick.
    if ((only.empty() && !quick) || only == "shake-damped") {
        shaken_beam("shake-damped", "box 48x3x3, 5 mm", 1, {1e-6, 1.25e-6, 2e-6});
        out.back().scene.rayleigh_beta = 1e-3;
    }
    if ((only.empty() && !quick) || only == "bunny-damped") {
        AccScene c = standing_bunny("bunny-damped", Material{5e4, 0.4, 1000});
        c.scene.gravity = {0, -9.81, 0};
        c.scene.rayleigh_beta = 1e-3;
        c.duration = 0.3 * span;
        c.samples = int(6 * span);
        c.dt_ref = 5e-5;
        c.explicit_dts = {2.5e-5, 3.125e-5, 4e-5};
        out.push_back(std::move(c));
    }
    if ((only.empty() && !quick) || only == "cantilever-damped") {
        clamped_under_gravity("cantilever-damped", "box 12x3x3", make_box(12, 3, 3, 0.01), Material{2e5, 0.35, 1000},
                              2e-5, {5e-5, 6.25e-5, 8e-5});
        out.back().scene.rayleigh_beta = 1e-3;
    }
    for (auto& s : out) {
        s.scene.count_inverted_tets = false;
        s.scene.rayleigh_alpha = 0;
    }
    return out;
}

void label(std::vector<Config>& cs) {
    for (auto& c : cs) {
        std::ostringstream os;
        os << to_string(c.integrator) << " dt=" << c.dt;
        if (!is_explicit(c.integrator)) {
            if (c.cg_fixed)
                os << " cg=" << c.cg_fixed << "it";
            else if (c.cg_tol != 1e-6)
                os << " cg=" << c.cg_tol;
        }
        if (c.single) os << " float";
        if (c.model == ModelKind::SN) os << " SN";
        if (c.definite) os << " definite";
        if (c.method == Method::Tet) os << " per-tet";
        if (c.direct) os << " direct";
        c.label = os.str();
    }
}

// The stiff scenes: explicit and Verlet (not with stiffness damping) around
// their stability limit (AccScene::explicit_dts), the first-order implicit ones from 0.25 to 25 ms, the
// second-order implicit ones from 2 to 50 ms. Every step divides the 50 ms
// between samples (make_configs checks it).
std::vector<Config> stiff_configs(const std::vector<double>& explicit_dts, bool quick, bool verlet) {
    std::vector<Config> cs;
    auto add = [&](Integrator in, double dt) {
        Config c;
        c.integrator = in;
        c.dt = dt;
        cs.push_back(c);
    };
    for (Integrator in : {Integrator::Explicit, Integrator::Verlet})
        if (in == Integrator::Explicit || verlet)
            for (double dt : quick ? std::vector<double>{explicit_dts.front()} : explicit_dts) add(in, dt);
    for (double dt : quick ? std::vector<double>{1e-3} : std::vector<double>{2.5e-4, 5e-4, 1e-3, 5e-3, 25e-3})
        add(Integrator::SemiImplicit, dt);
    if (!quick) add(Integrator::Implicit, 1e-3);
    for (Integrator in : {Integrator::NewmarkLinear, Integrator::GeneralizedAlphaLinear, Integrator::Bdf2Linear})
        for (double dt : quick ? std::vector<double>{5e-3}
                               : std::vector<double>{2e-3, 2.5e-3, 3.125e-3, 5e-3, 10e-3, 25e-3, 50e-3})
            add(in, dt);
    // A loose CG tolerance: the linearised step is one Newton iteration, so
    // a solve to 1e-6 buys accuracy the step's own error (0.1-1 %) hides;
    // under AMG, that is, for block-Jacobi's 1e-2 leaves the smooth part of
    // the error (docs/dynamics.md, "Target (b)").
    for (Integrator in : {Integrator::SemiImplicit, Integrator::NewmarkLinear, Integrator::GeneralizedAlphaLinear})
        for (double dt : quick ? std::vector<double>{5e-3}
                               : in == Integrator::SemiImplicit ? std::vector<double>{2.5e-4, 5e-4, 1e-3}
                                                                : std::vector<double>{2e-3, 2.5e-3, 3.125e-3, 5e-3}) {
            add(in, dt);
            cs.back().cg_tol = 1e-2;
        }
    if (!quick)
        for (double dt : {5e-3, 10e-3}) add(Integrator::Newmark, dt);
    label(cs);
    return cs;
}

std::vector<Config> scene_configs(const AccScene& sc, bool quick);

// A scene whose explicit step costs milliseconds: explicit and Verlet at
// their steps, the first-order implicit one and the cheapest second-order
// ones (a loose CG tolerance, from stiff_configs' rows) around 1 % error.
std::vector<Config> costly_configs(const std::vector<double>& explicit_dts) {
    std::vector<Config> cs;
    auto add = [&](Integrator in, double dt, double tol) {
        Config c;
        c.integrator = in;
        c.dt = dt;
        c.cg_tol = tol;
        cs.push_back(c);
    };
    for (double dt : explicit_dts) add(Integrator::Explicit, dt, 1e-6);
    add(Integrator::Verlet, explicit_dts.back(), 1e-6);
    for (double dt : {2.5e-4, 1e-3}) add(Integrator::SemiImplicit, dt, 1e-2);
    for (Integrator in : {Integrator::NewmarkLinear, Integrator::GeneralizedAlphaLinear})
        for (double dt : {1.5625e-3, 2e-3, 3.125e-3}) add(in, dt, 1e-2);
    add(Integrator::GeneralizedAlphaLinear, 2e-3, 1e-6);
    label(cs);
    return cs;
}

// Every configuration's dt divides the time between samples: a sample taken
// at the step nearest its time, dt / 2 away, would add an error of the
// order of v dt / 2 to every integrator alike (first order).
std::vector<Config> make_configs(const AccScene& sc, bool quick) {
    std::vector<Config> cs = scene_configs(sc, quick);
    const double every = sc.duration / sc.samples;
    for (const Config& c : cs) {
        const double n = every / c.dt;
        if (std::abs(n - std::round(n)) > 1e-9 * n)
            throw Error("accuracy: " + sc.name + ": " + c.label + " does not divide the " + std::to_string(every) +
                        " s between samples");
    }
    return cs;
}

std::vector<Config> scene_configs(const AccScene& sc, bool quick) {
    if (sc.costly) return costly_configs(sc.explicit_dts);
    if (!sc.explicit_dts.empty()) return stiff_configs(sc.explicit_dts, quick, sc.scene.rayleigh_beta == 0);
    std::vector<Config> cs;
    auto add = [&](Config c) { cs.push_back(c); };
    // Explicit near and below its stability limit.
    for (double dt : {5e-5, 1e-4, 2e-4}) {
        if (quick && dt != 1e-4) continue;
        Config c;
        c.integrator = Integrator::Explicit;
        c.dt = dt;
        add(c);
    }
    // The first-order implicit ones from 0.1 ms: how far they are from 1 %
    // error (docs/dynamics.md, the targets).
    for (double dt : quick ? std::vector<double>{1e-3, 5e-3} : std::vector<double>{1e-4, 5e-4, 1e-3, 2e-3, 5e-3, 1e-2}) {
        Config c;
        c.dt = dt;
        add(c);
    }
    for (double dt : quick ? std::vector<double>{1e-3, 5e-3} : std::vector<double>{1e-4, 5e-4, 1e-3, 2e-3, 5e-3, 1e-2}) {
        Config c;
        c.integrator = Integrator::Implicit;
        c.dt = dt;
        add(c);
    }
    // The second-order integrators: explicit velocity Verlet at the
    // explicit steps, the implicit ones (Newton and linearised) at 0.5-5 ms.
    for (double dt : {5e-5, 1e-4, 2e-4}) {
        if (quick && dt != 1e-4) continue;
        Config c;
        c.integrator = Integrator::Verlet;
        c.dt = dt;
        add(c);
    }
    for (Integrator integ : {Integrator::Newmark, Integrator::NewmarkLinear, Integrator::GeneralizedAlpha,
                             Integrator::GeneralizedAlphaLinear, Integrator::Bdf2, Integrator::Bdf2Linear})
        for (double dt : quick ? std::vector<double>{1e-3} : std::vector<double>{5e-4, 1e-3, 2e-3, 5e-3}) {
            Config c;
            c.integrator = integ;
            c.dt = dt;
            add(c);
        }
    if (!quick)  // the real-time form with the assembled direct solve instead of CG
        for (double dt : {1e-3, 2e-3}) {
            Config c;
            c.integrator = Integrator::NewmarkLinear;
            c.dt = dt;
            c.direct = true;
            add(c);
        }
    // One factor at a time around semi-implicit, dt = 2 ms, CG 1e-6, double, FE, edge.
    Config base;
    base.dt = 2e-3;
    if (!quick) {
        for (double tol : {1e-2, 1e-4, 1e-8}) {
            Config c = base;
            c.cg_tol = tol;
            add(c);
        }
        for (int it : {5, 20}) {
            Config c = base;
            c.cg_fixed = it;
            add(c);
        }
    } else {
        Config c = base;
        c.cg_fixed = 20;
        add(c);
    }
    {
        Config c = base;
        c.single = true;
        add(c);
    }
    {
        Config c = base;
        c.model = ModelKind::SN;
        add(c);
    }
    {
        Config c = base;
        c.definite = true;
        add(c);
    }
    {
        Config c = base;
        c.method = Method::Tet;
        add(c);
    }
    if (!quick) {  // the same factors with the implicit integrator
        Config c = base;
        c.integrator = Integrator::Implicit;
        c.single = true;
        add(c);
        c.single = false;
        c.model = ModelKind::SN;
        add(c);
        c.model = ModelKind::FE;
        c.method = Method::Tet;
        add(c);
    }
    label(cs);
    return cs;
}

Scene configured(const AccScene& sc, const Config& c) {
    Scene s = sc.scene;
    s.integrator = c.integrator;
    s.dt = c.dt;
    s.model = c.model;
    s.method = c.method;
    s.solver.cg_tolerance = c.cg_tol;
    s.solver.cg_fixed_iterations = c.cg_fixed;
    s.solver.definite_stiffness = c.definite;
    if (c.direct) s.solver.linear_solver = LinearSolver::Direct;
    s.solver.newton_tolerance = 1e-10;
    s.solver.max_step_halvings = 3;
    return s;
}

template <class S>
Trajectory simulate(const AccScene& sc, const Config& c) {
    Trajectory tr;
    const auto t0 = Clock::now();
    try {
        Simulator<S> sim(configured(sc, c), nullptr, cpu_operator_factory<S>());
        if (!sc.u0.empty()) std::copy(sc.u0.begin(), sc.u0.end(), sim.displacement().begin());
        tr.energy.push_back(sim.energies());
        const long total = std::lround(sc.duration / c.dt);
        long cg = 0;
        for (int k = 1; k <= sc.samples; ++k) {
            const long until = std::lround(double(total) * k / sc.samples);
            while (tr.steps < until) {
                const StepStats& st = sim.step();
                cg += st.solver_iterations;
                tr.halvings += st.halvings;
                ++tr.steps;
            }
            const auto u = sim.displacement();
            tr.u.emplace_back(u.begin(), u.end());
            tr.energy.push_back(sim.energies());
        }
        tr.cg_mean = tr.steps ? double(cg) / double(tr.steps) : 0;
    } catch (const SimulationError& e) {
        tr.failed = true;
        tr.message = e.what();
    }
    tr.wall_s = std::chrono::duration<double>(Clock::now() - t0).count();
    return tr;
}

// ---- Reference cache --------------------------------------------------------

std::uint64_t fnv1a(const void* data, std::size_t n, std::uint64_t h = 1469598103934665603ull) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < n; ++i) {
        h ^= p[i];
        h *= 1099511628211ull;
    }
    return h;
}

std::uint64_t scene_hash(const AccScene& sc, const Config& ref) {
    const Scene s = configured(sc, ref);
    std::uint64_t h = fnv1a(s.mesh.X.data(), s.mesh.X.size() * sizeof(double));
    h = fnv1a(s.mesh.tets.data(), s.mesh.tets.size() * sizeof(index_t), h);
    h = fnv1a(s.fixed.data(), s.fixed.size() * sizeof(index_t), h);
    h = fnv1a(sc.u0.data(), sc.u0.size() * sizeof(double), h);
    for (const Prescribed& p : s.prescribed) {  // field by field: the struct has padding
        h = fnv1a(&p.vertex, sizeof p.vertex, h);
        h = fnv1a(p.target.data(), sizeof p.target, h);
    }
    h = fnv1a(s.prescribed_keyframes.data(), s.prescribed_keyframes.size() * sizeof(Keyframe), h);
    const Material& m = s.materials.fallback;
    const double nums[] = {m.young, m.poisson, m.density, s.gravity[0], s.gravity[1], s.gravity[2], sc.duration,
                           double(sc.samples), ref.dt, s.solver.newton_tolerance, s.solver.cg_tolerance,
                           ref.integrator == Integrator::Newmark ? 4.0 /*format: newmark*/ : 100.0 + double(int(ref.integrator))};
    h = fnv1a(nums, sizeof nums, h);
    // Damping only where there is some: the undamped scenes keep the keys
    // their cached references were made under.
    if (s.rayleigh_alpha != 0 || s.rayleigh_beta != 0) {
        const double damping[] = {s.rayleigh_alpha, s.rayleigh_beta};
        h = fnv1a(damping, sizeof damping, h);
    }
    return h;
}

bool load_reference(const std::string& path, std::size_t n, int samples, Trajectory& tr) {
    std::ifstream in(path, std::ios::binary);
    if (!in) return false;
    tr.u.assign(samples, std::vector<double>(n));
    tr.energy.assign(samples + 1, Energies{});
    for (auto& u : tr.u) in.read(reinterpret_cast<char*>(u.data()), std::streamsize(n * sizeof(double)));
    for (auto& e : tr.energy) {
        double v[3];
        in.read(reinterpret_cast<char*>(v), sizeof v);
        e = {v[0], v[1], v[2]};
    }
    in.read(reinterpret_cast<char*>(&tr.wall_s), sizeof(double));
    return bool(in);
}

void save_reference(const std::string& path, const Trajectory& tr) {
    std::ofstream out(path + ".tmp", std::ios::binary);
    for (const auto& u : tr.u) out.write(reinterpret_cast<const char*>(u.data()), std::streamsize(u.size() * sizeof(double)));
    for (const auto& e : tr.energy) {
        const double v[3] = {e.kinetic, e.elastic, e.gravity};
        out.write(reinterpret_cast<const char*>(v), sizeof v);
    }
    out.write(reinterpret_cast<const char*>(&tr.wall_s), sizeof(double));
    out.close();
    if (!out) throw Error("cannot write the reference cache " + path);
    std::filesystem::rename(path + ".tmp", path);
}

double norm(const std::vector<double>& a) {
    double s = 0;
    for (double x : a) s += x * x;
    return std::sqrt(s);
}

double drift(const std::vector<Energies>& e) {
    double scale = 0;
    for (const auto& x : e) scale = std::max(scale, x.kinetic + x.elastic);
    return scale > 0 ? (e.back().total() - e.front().total()) / scale : 0;
}

std::string jnum(double x) {
    if (!std::isfinite(x)) return "null";
    char b[40];
    std::snprintf(b, sizeof b, "%.6g", x);
    return b;
}

std::string jstr(const std::string& s) {
    std::string o = "\"";
    for (char ch : s) {
        if (ch == '"' || ch == '\\') o += '\\';
        o += (static_cast<unsigned char>(ch) < 0x20) ? ' ' : ch;
    }
    return o + "\"";
}

std::string default_cache_dir() {
    std::error_code ec;
    const auto exe = std::filesystem::read_symlink("/proc/self/exe", ec);
    if (!ec) return (exe.parent_path().parent_path() / "accuracy-cache").string();
    return "accuracy-cache";
}

std::string default_mesh_dir() {
    std::error_code ec;
    const auto exe = std::filesystem::read_symlink("/proc/self/exe", ec);
    if (!ec) {
        const auto d = exe.parent_path().parent_path().parent_path().parent_path() / "shared" / "meshes";
        if (std::filesystem::exists(d)) return d.string();
    }
    return "../shared/meshes";
}

}  // namespace

void add_accuracy_command(CLI::App& app) {
    struct Options {
        bool quick = false;
        std::string cache, json, scene, mesh_dir;
    };
    auto opts = std::make_shared<Options>();
    CLI::App* cmd = app.add_subcommand("accuracy", "Run time against error on standard scenes (reference: trapezoidal Newmark by Newton, small dt, two steps compared)");
    cmd->add_flag("--quick", opts->quick, "Half the simulated span and fewer configurations");
    cmd->add_option("--cache", opts->cache, "Folder for the cached reference trajectories (default: build/accuracy-cache)")
        ->check(non_empty_path());
    cmd->add_option("--json", opts->json, "Write the results as JSON to this file")->check(non_empty_path());
    cmd->add_option("--scene", opts->scene, "Only this scene")->check(CLI::IsMember({"cantilever", "twist", "bunny", "slender", "press", "shake", "shake-rubber", "shake-fine", "shake-finer", "shake-damped", "bunny-damped", "cantilever-damped"}));
    cmd->add_option("--mesh-dir", opts->mesh_dir,
                    "Folder with bunny-4k.node/.ele (default: $EDGEFEM_MESH_DIR, else ../shared/meshes next to the repository)")
        ->check(non_empty_path());
    // Its own footer: the main one (inherited otherwise) describes MESH,
    // which this command does not take.
    cmd->footer(
        "Errors print one line 'edgefem: error: ...' to stderr. Exit codes: 0 ok, 2 bad input,\n"
        "3 simulation failed (a reference trajectory failed; a configuration that fails is a row 'failed cleanly').");
    cmd->callback([opts] {
        // Before the runs, not after them: a typo in the path would lose them.
        if (!opts->json.empty()) check_writable("--json", opts->json);
        const std::string cache = opts->cache.empty() ? default_cache_dir() : opts->cache;
        std::filesystem::create_directories(cache);
        const std::string mesh_folder = opts->mesh_dir.empty() ? mesh_dir(default_mesh_dir()) : opts->mesh_dir;
        std::ostringstream js;
        js << "{\"quick\": " << (opts->quick ? "true" : "false") << ", \"scenes\": [";
        bool first_scene = true;
        for (const AccScene& sc : make_scenes(opts->quick, mesh_folder, opts->scene)) {
            Config ref;
            ref.integrator = sc.ref_integrator;
            ref.dt = sc.dt_ref;
            char hex[20];
            std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(scene_hash(sc, ref)));
            const std::string path = cache + "/" + sc.name + "-" + hex + ".ref";
            Config ref2 = ref;
            ref2.dt = 2 * sc.dt_ref;
            const std::string path2 = cache + "/" + sc.name + "-" + hex + "-2dt.ref";
            Trajectory rt, rt2;
            const bool cached = load_reference(path, sc.scene.mesh.X.size(), sc.samples, rt) &&
                                load_reference(path2, sc.scene.mesh.X.size(), sc.samples, rt2);
            if (!cached) {
                std::fprintf(stderr, "accuracy: %s: computing the reference (%s, dt %g and %g, %g s)...\n",
                             sc.name.c_str(), to_string(sc.ref_integrator), sc.dt_ref, 2 * sc.dt_ref, sc.duration);
                rt = simulate<double>(sc, ref);
                if (rt.failed) throw SimulationError("reference for " + sc.name + ": " + rt.message, 0);
                rt2 = simulate<double>(sc, ref2);
                if (rt2.failed) throw SimulationError("reference for " + sc.name + " (2 dt): " + rt2.message, 0);
                save_reference(path, rt);
                save_reference(path2, rt2);
            }
            const double ref_drift = drift(rt.energy), ref_wall = rt.wall_s + rt2.wall_s;
            double uref_max = 0, floor = 0;
            for (int k = 0; k < sc.samples; ++k) {
                double d2 = 0;
                for (std::size_t i = 0; i < rt.u[k].size(); ++i) {
                    const double a = rt.u[k][i], b = rt2.u[k][i];
                    d2 += (a - b) * (a - b);
                    rt.u[k][i] = (4 * a - b) / 3;  // Richardson extrapolation (second order)
                }
                uref_max = std::max(uref_max, norm(rt.u[k]));
                floor = std::max(floor, std::sqrt(d2) / 3);
            }
            floor /= uref_max;
            std::printf("scene %s (%s, %d tets): %g s simulated, reference %s dt %g & %g extrapolated (%s, %.1f s), "
                        "ref_error %.3g, reference drift %.3g\n",
                        sc.name.c_str(), sc.mesh_origin.c_str(), sc.scene.mesh.num_tets(), sc.duration,
                        to_string(sc.ref_integrator), sc.dt_ref,
                        2 * sc.dt_ref, cached ? "cached" : "computed", ref_wall, floor, ref_drift);
            std::printf("  %-44s %12s %10s %10s %8s %6s\n", "configuration", "wall/sim_s", "error", "drift", "cg/step", "halv");
            if (!first_scene) js << ",";
            first_scene = false;
            js << "\n {\"name\": " << jstr(sc.name) << ", \"mesh\": " << jstr(sc.mesh_origin)
               << ", \"tets\": " << sc.scene.mesh.num_tets() << ", \"duration\": " << jnum(sc.duration)
               << ", \"samples\": " << sc.samples << ", \"dt_ref\": " << jnum(sc.dt_ref)
               << ", \"reference_integrator\": " << jstr(to_string(sc.ref_integrator))
               << ", \"reference_wall_s\": " << jnum(ref_wall) << ", \"reference_drift\": " << jnum(ref_drift)
               << ", \"reference_error\": " << jnum(floor)
               << ", \"reference_cache\": " << jstr(path) << ", \"configs\": [";
            bool first = true;
            for (const Config& c : make_configs(sc, opts->quick)) {
                const Trajectory t = c.single ? simulate<float>(sc, c) : simulate<double>(sc, c);
                double err = NAN, err_mean = NAN, dr = NAN;
                if (!t.failed) {
                    err = 0;
                    err_mean = 0;
                    for (int k = 0; k < sc.samples; ++k) {
                        std::vector<double> d(t.u[k].size());
                        for (std::size_t i = 0; i < d.size(); ++i) d[i] = t.u[k][i] - rt.u[k][i];
                        const double e = norm(d) / uref_max;
                        err = std::max(err, e);
                        err_mean += e / sc.samples;
                    }
                    dr = drift(t.energy);
                    std::printf("  %-44s %12.4g %10.3g %10.3g %8.1f %6ld%s\n", c.label.c_str(), t.wall_s / sc.duration, err,
                                dr, t.cg_mean, t.halvings,
                                err >= 10 * floor ? "" : "  (below 10x ref_error: the reference cannot resolve it)");
                } else {
                    std::printf("  %-44s %12.4g  failed cleanly with error: %s\n", c.label.c_str(), t.wall_s / sc.duration,
                                t.message.c_str());
                }
                std::fflush(stdout);
                if (!first) js << ",";
                first = false;
                js << "\n  {\"label\": " << jstr(c.label) << ", \"integrator\": " << jstr(to_string(c.integrator))
                   << ", \"dt\": " << jnum(c.dt) << ", \"cg_tolerance\": " << jnum(c.cg_tol)
                   << ", \"cg_fixed_iterations\": " << c.cg_fixed << ", \"precision\": " << jstr(c.single ? "float" : "double")
                   << ", \"model\": " << jstr(c.model == ModelKind::SN ? "sn" : "fe")
                   << ", \"definite\": " << (c.definite ? "true" : "false")
                   << ", \"method\": " << jstr(c.method == Method::Tet ? "tet" : "edge")
                   << ", \"linear\": " << jstr(c.direct ? "direct" : "cg") << ", \"halvings\": " << t.halvings
                   << ", \"wall_s\": " << jnum(t.wall_s) << ", \"wall_per_sim_s\": " << jnum(t.wall_s / sc.duration)
                   << ", \"error_max\": " << jnum(err) << ", \"error_mean\": " << jnum(err_mean)
                   << ", \"resolved\": " << (!t.failed && err >= 10 * floor ? "true" : "false")
                   << ", \"energy_drift\": " << jnum(dr) << ", \"cg_per_step\": " << jnum(t.cg_mean)
                   << ", \"failed\": " << (t.failed ? "true" : "false") << ", \"message\": " << jstr(t.message) << "}";
            }
            js << "\n ]}";
        }
        js << "\n]}\n";
        if (!opts->json.empty()) {
            std::ofstream out(opts->json);
            out << js.str();
            if (!out) throw Error("cannot write " + opts->json);
        }
    });
}

}  // namespace edgefem::cli
