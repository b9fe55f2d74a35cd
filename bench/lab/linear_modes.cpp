#include "lab/linear_modes.hpp"

#include <array>
#include <cmath>
#include <string>

#include "edgefem/core/coefficients.hpp"
#include "edgefem/core/error.hpp"
#include "edgefem/core/reference_operator.hpp"

namespace edgefem::lab {

LinearModes linear_modes(const Scene& scene) {
    scene.validate();
    // what the recurrences do not model: a free, unloaded vibration only
    // (Rayleigh damping is: alpha M + beta K is diagonal in the modes)
    if (!scene.prescribed.empty()) throw InvalidArgument("linear_modes: prescribed vertices are not a free vibration");
    if (scene.gravity != std::array<double, 3>{0, 0, 0} || !scene.load.empty() || !scene.surface_loads.empty())
        throw InvalidArgument("linear_modes: loads (gravity, load, surface_loads) are not modelled");
    const Mesh& mesh = scene.mesh;
    std::vector<char> fixed(std::size_t(mesh.num_vertices()), 0);
    for (index_t v : scene.fixed) fixed[std::size_t(v)] = 1;
    LinearModes md;
    for (std::size_t i = 0; i < mesh.X.size(); ++i)
        if (!fixed[i / 3]) md.dof.push_back(i);
    const auto n = Eigen::Index(md.dof.size());
    if (n > 3000) throw InvalidArgument("linear_modes: " + std::to_string(n) + " free dofs (dense: at most 3,000)");
    // the scene's model (edge FE or SN) through the reference back-end's
    // edge loops (the per-tet method's K is edge FE's)
    auto op = make_reference_operator<double>(mesh, scene.materials, scene.model, Method::Edge);
    std::vector<double> zero(mesh.X.size(), 0.0), y(mesh.X.size());
    op->forces(zero.data(), y.data(), false);
    op->build_stiffness(false);
    const std::vector<double> mass = lumped_mass(mesh, scene.materials);
    md.mass.resize(n);
    for (Eigen::Index a = 0; a < n; ++a) md.mass[a] = mass[md.dof[std::size_t(a)] / 3];
    // M^-1/2 K M^-1/2, a column per product K e_b
    Eigen::MatrixXd A(n, n);
    std::vector<double> e(mesh.X.size(), 0.0);
    for (Eigen::Index b = 0; b < n; ++b) {
        e[md.dof[std::size_t(b)]] = 1;
        op->multiply(e.data(), y.data());
        e[md.dof[std::size_t(b)]] = 0;
        for (Eigen::Index a = 0; a < n; ++a) A(a, b) = y[md.dof[std::size_t(a)]] / std::sqrt(md.mass[a] * md.mass[b]);
    }
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es((A + A.transpose()) / 2);
    md.omega = es.eigenvalues().cwiseMax(0.0).cwiseSqrt();
    md.phi = md.mass.cwiseSqrt().cwiseInverse().asDiagonal() * es.eigenvectors();
    return md;
}

namespace {

void check_size(const LinearModes& modes, std::size_t size, const char* what) {
    if (!modes.dof.empty() && size <= modes.dof.back())
        throw InvalidArgument(std::string(what) + ": " + std::to_string(size) + " entries, the modes need " +
                              std::to_string(modes.dof.back() + 1));
}

}  // namespace

Eigen::VectorXd modal_coordinates(const LinearModes& modes, const std::vector<double>& u) {
    check_size(modes, u.size(), "modal_coordinates: u");
    Eigen::VectorXd mu(modes.mass.size());
    for (Eigen::Index a = 0; a < mu.size(); ++a) mu[a] = modes.mass[a] * u[modes.dof[std::size_t(a)]];
    return modes.phi.transpose() * mu;
}

std::vector<double> modal_displacement(const LinearModes& modes, const Eigen::VectorXd& q, std::size_t size) {
    check_size(modes, size, "modal_displacement: size");
    if (q.size() != modes.phi.cols())
        throw InvalidArgument("modal_displacement: " + std::to_string(q.size()) + " modal coordinates, the modes are " +
                              std::to_string(modes.phi.cols()));
    const Eigen::VectorXd free = modes.phi * q;
    std::vector<double> u(size, 0.0);
    for (Eigen::Index a = 0; a < free.size(); ++a) u[modes.dof[std::size_t(a)]] = free[a];
    return u;
}

namespace {

// The Newmark family with alpha_m, alpha_f (generalized-alpha; 0, 0:
// Newmark) and the mode's damping c = alpha + beta omega^2:
// (1 - am) a' + am a + (1 - af) (c v' + w2 x') + af (c v + w2 x) = 0,
// x' = x + T v + T^2 ((1/2 - beta) a + beta a'), v' = v + T ((1 - gamma) a + gamma a').
std::vector<double> newmark_family(double w2, double c, double T, long steps, double beta, double gamma, double am,
                                   double af) {
    std::vector<double> x{1.0};
    double u = 1, v = 0, a = -w2;  // the balance's acceleration at rest: -c v - w2 u
    for (long k = 0; k < steps; ++k) {
        const double pred = u + T * v + T * T * (0.5 - beta) * a, vpred = v + T * (1 - gamma) * a;
        const double an = -(am * a + (1 - af) * (c * vpred + w2 * pred) + af * (c * v + w2 * u)) /
                          ((1 - am) + (1 - af) * (c * gamma * T + w2 * beta * T * T));
        u = pred + beta * T * T * an;
        v = vpred + gamma * T * an;
        a = an;
        x.push_back(u);
    }
    return x;
}

}  // namespace

std::vector<double> mode_history(Integrator integrator, const IntegratorParameters& parameters, double omega,
                                 double dt, long steps, double alpha, double beta) {
    if (integrator == Integrator::Verlet && (alpha != 0 || beta != 0))
        throw InvalidArgument("mode_history: verlet takes no damping");
    const double w2 = omega * omega, T = dt, c = alpha + beta * w2;
    switch (integrator) {
    case Integrator::Newmark:
    case Integrator::NewmarkLinear:
        return newmark_family(w2, c, T, steps, parameters.newmark_beta, parameters.newmark_gamma, 0, 0);
    case Integrator::GeneralizedAlpha:
    case Integrator::GeneralizedAlphaLinear: {
        const double rho = parameters.rho_inf;
        const double am = (2 * rho - 1) / (rho + 1), af = rho / (rho + 1);
        return newmark_family(w2, c, T, steps, 0.25 * (1 - am + af) * (1 - am + af), 0.5 - am + af, am, af);
    }
    default:
        break;
    }
    std::vector<double> x{1.0};
    double u = 1, v = 0, u1 = 0, v1 = 0;
    for (long k = 0; k < steps; ++k) {
        double un = 0, vn = 0;
        switch (integrator) {
        case Integrator::Explicit:  // symplectic Euler: alpha implicit, beta K v at the step's start
            vn = (v - T * (w2 * u + beta * w2 * v)) / (1 + T * alpha);
            un = u + T * vn;
            break;
        case Integrator::Verlet:
            un = u + T * v - 0.5 * T * T * w2 * u;
            vn = v - 0.5 * T * w2 * (u + un);
            break;
        case Integrator::Bdf2:
        case Integrator::Bdf2Linear:
            if (k > 0) {  // x' = X + h v',  v' = V + h a',  a' = -c v' - w2 x'  (h = 2T/3)
                const double h = 2 * T / 3, X = (4 * u - u1) / 3, V = (4 * v - v1) / 3;
                vn = (V - h * w2 * X) / (1 + h * c + h * h * w2);
                un = X + h * vn;
                break;
            }
            [[fallthrough]];
        default:  // backward Euler (Implicit, SemiImplicit): v' = v + T a', x' = x + T v'
            vn = (v - T * w2 * u) / (1 + T * c + T * T * w2);
            un = u + T * vn;
            break;
        }
        u1 = u;
        v1 = v;
        u = un;
        v = vn;
        x.push_back(u);
    }
    return x;
}

std::vector<double> exact_mode_history(double omega, double dt, long steps) {
    std::vector<double> x;
    for (long k = 0; k <= steps; ++k) x.push_back(std::cos(omega * double(k) * dt));
    return x;
}

}  // namespace edgefem::lab
