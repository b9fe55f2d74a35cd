#include "edgefem/core/tet_model.hpp"

#include "edgefem/core/coefficients.hpp"

namespace edgefem {

template <class S>
TetModel<S> make_tet_model(const Mesh& mesh, const Materials& materials) {
    materials.validate();
    TetModel<S> m;
    m.num_vertices = mesh.num_vertices();
    const index_t nt = mesh.num_tets();
    m.tet.resize(nt);
    m.data.resize(nt);
    m.volume.resize(nt);
    for (index_t t = 0; t < nt; ++t) {
        for (int k = 0; k < 4; ++k) m.tet[t][k] = mesh.tets[4 * std::size_t(t) + k];
        const TetGradients g = tet_gradients(mesh, t);
        const Material& mat = materials.of(mesh.tet_region(t));
        for (int i = 0; i < 3; ++i)
            for (int c = 0; c < 3; ++c) m.data[t].Dinv[i][c] = static_cast<S>(g.a[i + 1][c]);
        m.data[t].vol_lambda = static_cast<S>(g.volume * mat.lambda());
        m.data[t].vol_mu = static_cast<S>(g.volume * mat.mu());
        m.volume[t] = g.volume;
    }
    return m;
}

template TetModel<double> make_tet_model<double>(const Mesh&, const Materials&);
template TetModel<float> make_tet_model<float>(const Mesh&, const Materials&);

}  // namespace edgefem
