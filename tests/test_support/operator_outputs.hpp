// What an elastic operator gives at one configuration (forces, energy, K x
// with the plain and the definite K, diagonal blocks, inverted tets), read
// back in double from any back-end's memory, and the comparison the
// back-end tests make against the reference back-end.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "edgefem/core/backend_vector.hpp"
#include "edgefem/core/elastic_operator.hpp"
#include "edgefem/core/material.hpp"
#include "models.hpp"

namespace edgefem::test {

// E = 1e5, nu = 0.3, rho = 1000.
inline const Materials& backend_test_material() {
    static const Materials m(Material{1e5, 0.3, 1000});
    return m;
}

// A smooth direction for K x.
inline std::vector<double> direction(std::size_t n) {
    std::vector<double> x(n);
    for (std::size_t i = 0; i < n; ++i) x[i] = std::sin(0.37 * double(i) + 1.0);
    return x;
}

// v rounded to float and back: the input a float back-end actually sees. Its
// outputs are compared with the double reference's at this input, so that
// the comparison measures the back-end's arithmetic, not the rounding of u
// itself: on bunny-1m under the twist, rounding u to float alone moves the
// double reference's forces by 1.5e-5 of their largest entry (the
// displacements are ~100 edge lengths, and the edge vectors are their
// differences).
inline std::vector<double> rounded_to_float(const std::vector<double>& v) {
    std::vector<double> r(v.size());
    for (std::size_t i = 0; i < v.size(); ++i) r[i] = double(float(v[i]));
    return r;
}

// The models every back-end implements.
struct Case {
    ModelKind model;
    Method method;
    const char* name;
};
inline constexpr Case kCases[] = {{ModelKind::FE, Method::Edge, "edge-fe"},
                                  {ModelKind::SN, Method::Edge, "edge-sn"},
                                  {ModelKind::FE, Method::Tet, "tet"}};

struct Outputs {
    double energy = 0;       // forces()'s
    double energy_only = 0;  // energy()'s
    std::vector<double> f, Kx, Kx_definite, D;
    index_t inverted = 0;
};

// The operator's outputs at u, K x at x; `edge`: the definite K x too. The
// vectors live in `memory` (copied to and from the host around the calls).
template <class S>
Outputs evaluate(ElasticOperator<S>& op, const std::vector<double>& u_d, const std::vector<double>& x_d, bool edge,
                 const VectorMemory& memory = host_memory()) {
    const std::vector<S> uh(u_d.begin(), u_d.end()), xh(x_d.begin(), x_d.end());
    BackendVector<S> u(memory, uh.size()), x(memory, xh.size()), f(memory, uh.size()), y(memory, uh.size()),
        D(memory, 3 * uh.size());
    u.write(uh);
    x.write(xh);
    const auto get = [](const BackendVector<S>& v) {
        std::vector<S> h(v.size());
        v.read(h);
        return std::vector<double>(h.begin(), h.end());
    };
    Outputs o;
    o.energy = op.forces(u.data(), f.data(), true);
    op.build_stiffness(false);
    op.multiply(x.data(), y.data());
    op.diagonal_blocks(D.data());
    o.f = get(f);
    o.Kx = get(y);
    o.D = get(D);
    if (edge) {
        op.build_stiffness(true);
        op.multiply(x.data(), y.data());
        o.Kx_definite = get(y);
    }
    o.energy_only = op.energy(u.data());
    o.inverted = op.inverted_tets(u.data());
    return o;
}

// Each output within `tol` of the reference's, relative to its largest entry.
inline void expect_close(const Outputs& got, const Outputs& ref, double tol, const std::string& what) {
    EXPECT_LE(std::abs(got.energy - ref.energy), tol * std::abs(ref.energy)) << what << " energy";
    EXPECT_LE(std::abs(got.energy_only - ref.energy), tol * std::abs(ref.energy)) << what << " energy()";
    EXPECT_LE(rel_diff(got.f, ref.f), tol) << what << " forces";
    EXPECT_LE(rel_diff(got.Kx, ref.Kx), tol) << what << " K x";
    EXPECT_LE(rel_diff(got.D, ref.D), tol) << what << " diagonal blocks";
    if (!ref.Kx_definite.empty()) {
        EXPECT_LE(rel_diff(got.Kx_definite, ref.Kx_definite), tol) << what << " definite K x";
    }
    EXPECT_EQ(got.inverted, ref.inverted) << what << " inverted tets";
}

}  // namespace edgefem::test
