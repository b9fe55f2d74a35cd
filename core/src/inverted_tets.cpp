#include "edgefem/core/inverted_tets.hpp"

namespace edgefem {

template <class S>
index_t count_inverted_tets(const Mesh& mesh, const S* u) {
    index_t n = 0;
    for (index_t t = 0; t < mesh.num_tets(); ++t) {
        double x[4][3];
        for (int k = 0; k < 4; ++k) {
            const index_t v = mesh.tets[4 * std::size_t(t) + k];
            for (int r = 0; r < 3; ++r) x[k][r] = mesh.X[3 * std::size_t(v) + r] + double(u[3 * std::size_t(v) + r]);
        }
        n += signed_volume(x[0], x[1], x[2], x[3]) <= 0;
    }
    return n;
}

template index_t count_inverted_tets<double>(const Mesh&, const double*);
template index_t count_inverted_tets<float>(const Mesh&, const float*);

}  // namespace edgefem
