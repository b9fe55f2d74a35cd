// Everything the kernels need for one mesh, built the way an application
// would, plus comparison helpers with explicit tolerances.
#pragma once

#include <cstring>

#include <algorithm>
#include <cmath>
#include <vector>

#include "edgefem/core/coefficients.hpp"
#include "cpu/edge_kernels.hpp"
#include "cpu/tet_kernels.hpp"
#include "edgefem/core/topology.hpp"

namespace edgefem::test {

template <class S>
struct Models {
    Topology topo;
    Coefficients coef;
    EdgeModel<S> edge;
    BatchedTetModel<S> tet;
};

template <class S>
Models<S> make_models(const Mesh& mesh, const Materials& mat = Material{1e5, 0.3, 1000}) {
    Models<S> m;
    m.topo = build_topology(mesh);
    m.coef = compute_coefficients(mesh, m.topo, mat);
    m.edge = make_edge_model<S>(m.topo, m.coef);
    m.tet = make_batched_tet_model<S>(mesh, mat);
    return m;
}

template <class S, class T>
std::vector<S> cast(const std::vector<T>& v) {
    return std::vector<S>(v.begin(), v.end());
}

inline double max_abs(const auto& v) {
    double m = 0;
    for (auto x : v) m = std::max(m, std::abs(double(x)));
    return m;
}

// max |a - b| / max |b|: a norm-wise relative difference that does not blow
// up on the near-zero entries of a force vector.
inline double rel_diff(const auto& a, const auto& b) {
    double d = 0;
    for (std::size_t i = 0; i < a.size(); ++i) d = std::max(d, std::abs(double(a[i]) - double(b[i])));
    const double s = max_abs(b);
    return s > 0 ? d / s : d;
}

// The same length and the same bits (no tolerance).
template <class T>
bool bitwise_equal(const std::vector<T>& a, const std::vector<T>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0;
}

inline double dot(const std::vector<double>& a, const std::vector<double>& b) {
    double s = 0;
    for (std::size_t i = 0; i < a.size(); ++i) s += a[i] * b[i];
    return s;
}

}  // namespace edgefem::test
