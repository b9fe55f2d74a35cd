#include "edgefem/core/inverted_tets.hpp"

namespace edgefem {

template <class S>
void deformed_positions(const Mesh& mesh, const S* u, double* x, index_t v0, index_t v1) {
    for (std::size_t i = 3 * std::size_t(v0); i < 3 * std::size_t(v1); ++i) x[i] = mesh.X[i] + double(u[i]);
}

index_t count_inverted_in(const Mesh& mesh, const double* x, index_t t0, index_t t1) {
    index_t n = 0;
    const index_t* T = mesh.tets.data();
    for (index_t t = t0; t < t1; ++t) {
        const index_t* v = &T[4 * std::size_t(t)];
        n += signed_volume(&x[3 * std::size_t(v[0])], &x[3 * std::size_t(v[1])], &x[3 * std::size_t(v[2])],
                           &x[3 * std::size_t(v[3])]) <= 0;
    }
    return n;
}

template <class S>
index_t count_inverted_tets(const Mesh& mesh, const S* u, std::vector<double>& x) {
    x.resize(mesh.X.size());
    deformed_positions(mesh, u, x.data(), 0, mesh.num_vertices());
    return count_inverted_in(mesh, x.data(), 0, mesh.num_tets());
}

template <class S>
index_t count_inverted_tets(const Mesh& mesh, const S* u) {
    std::vector<double> x;
    return count_inverted_tets(mesh, u, x);
}

template index_t count_inverted_tets<double>(const Mesh&, const double*, std::vector<double>&);
template index_t count_inverted_tets<float>(const Mesh&, const float*, std::vector<double>&);
template index_t count_inverted_tets<double>(const Mesh&, const double*);
template index_t count_inverted_tets<float>(const Mesh&, const float*);
template void deformed_positions<double>(const Mesh&, const double*, double*, index_t, index_t);
template void deformed_positions<float>(const Mesh&, const float*, double*, index_t, index_t);

}  // namespace edgefem
