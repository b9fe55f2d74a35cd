#include "lab/deformations.hpp"

#include <algorithm>
#include <cmath>
#include <random>

#include "edgefem/core/error.hpp"

namespace edgefem {

Deformation parse_deformation(const std::string& name) {
    if (name == "twist") return Deformation::Twist;
    if (name == "rotate") return Deformation::Rotate;
    if (name == "random") return Deformation::Random;
    if (name == "affine") return Deformation::Affine;
    throw InvalidArgument("unknown deformation '" + name + "' (expected twist, rotate, random or affine)");
}

std::vector<double> deformation_displacement(const Mesh& mesh, Deformation kind, double scale) {
    const index_t nv = mesh.num_vertices();
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (index_t v = 0; v < nv; ++v)
        for (int r = 0; r < 3; ++r) {
            lo[r] = std::min(lo[r], mesh.X[3 * v + r]);
            hi[r] = std::max(hi[r], mesh.X[3 * v + r]);
        }
    double c[3], extent = 0;
    for (int r = 0; r < 3; ++r) {
        c[r] = 0.5 * (lo[r] + hi[r]);
        extent = std::max(extent, hi[r] - lo[r]);
    }
    std::vector<double> u(3 * static_cast<std::size_t>(nv), 0.0);
    auto apply = [&](auto map) {
        for (index_t v = 0; v < nv; ++v) {
            const double* X = &mesh.X[3 * v];
            const double d[3] = {X[0] - c[0], X[1] - c[1], X[2] - c[2]};
            double y[3];
            map(d, y);
            for (int r = 0; r < 3; ++r) u[3 * v + r] = scale * (y[r] - d[r]);
        }
    };
    switch (kind) {
        case Deformation::Twist:
            apply([&](const double* d, double* y) {
                const double th = 1.5 * d[2] / extent, cs = std::cos(th), sn = std::sin(th);
                y[0] = cs * d[0] - sn * d[1];
                y[1] = sn * d[0] + cs * d[1];
                y[2] = 1.3 * d[2];
            });
            break;
        case Deformation::Rotate: {
            const double n = std::sqrt(14.0), k[3] = {1 / n, 2 / n, 3 / n}, th = 0.7;
            const double cs = std::cos(th), sn = std::sin(th);
            apply([&](const double* d, double* y) {  // Rodrigues
                const double kd = k[0] * d[0] + k[1] * d[1] + k[2] * d[2];
                const double kx[3] = {k[1] * d[2] - k[2] * d[1], k[2] * d[0] - k[0] * d[2], k[0] * d[1] - k[1] * d[0]};
                for (int r = 0; r < 3; ++r) y[r] = d[r] * cs + kx[r] * sn + k[r] * kd * (1 - cs);
            });
            break;
        }
        case Deformation::Random: {
            std::mt19937_64 rng(12345);
            std::uniform_real_distribution<double> dist(-0.05 * extent, 0.05 * extent);
            for (auto& x : u) x = scale * dist(rng);
            break;
        }
        case Deformation::Affine: {
            static constexpr double A[3][3] = {{1.1, 0.2, -0.1}, {0.05, 0.9, 0.15}, {-0.2, 0.1, 1.2}};
            apply([&](const double* d, double* y) {
                for (int r = 0; r < 3; ++r) y[r] = A[r][0] * d[0] + A[r][1] * d[1] + A[r][2] * d[2];
            });
            break;
        }
    }
    return u;
}

std::vector<double> positions_from_displacement(const Mesh& mesh, const std::vector<double>& u) {
    std::vector<double> x(mesh.X.size());
    for (std::size_t i = 0; i < x.size(); ++i) x[i] = mesh.X[i] + u[i];
    return x;
}

}  // namespace edgefem
