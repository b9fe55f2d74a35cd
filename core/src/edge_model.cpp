#include "edgefem/core/edge_model.hpp"

namespace edgefem {

template <class S>
double EdgeModel<S>::bytes_per_tet(bool with_stiffness) const {
    const double bytes = edge.size() * sizeof(edge[0]) + edge_first.size() * sizeof(index_t) + rest.size() * sizeof(S) + LE.size() * sizeof(S) +
                         tsep_first.size() * sizeof(index_t) + tsep_other.size() * sizeof(index_t) + LP.size() * sizeof(S) +
                         (with_stiffness ? target.size() * sizeof(target[0]) : 0);
    return num_tets > 0 ? bytes / num_tets : 0.0;
}

template <class S>
EdgeModel<S> make_edge_model(const Topology& topo, const Coefficients& coef) {
    EdgeModel<S> m;
    m.num_vertices = topo.num_vertices;
    m.num_tets = topo.num_tets;
    m.edge = topo.edges;
    m.edge_first = topo.first_edge;
    m.rest.assign(coef.rest_edge.begin(), coef.rest_edge.end());
    m.LE.assign(coef.LE.begin(), coef.LE.end());
    m.tsep_first = topo.first_tsep;
    m.tsep_other.resize(topo.tseps.size());
    for (std::size_t p = 0; p < topo.tseps.size(); ++p) m.tsep_other[p] = topo.tseps[p][1];
    m.LP.assign(coef.LP.begin(), coef.LP.end());
    const index_t sink = topo.num_edges() << 1;
    m.target.resize(topo.tsep_targets.size());
    for (std::size_t p = 0; p < m.target.size(); ++p)
        for (int k = 0; k < 4; ++k) {
            const Target t = topo.tsep_targets[p][k];
            m.target[p][k] = (t == kDiagonalTarget) ? sink : t;
        }
    return m;
}

template struct EdgeModel<double>;
template struct EdgeModel<float>;
template EdgeModel<double> make_edge_model<double>(const Topology&, const Coefficients&);
template EdgeModel<float> make_edge_model<float>(const Topology&, const Coefficients&);

}  // namespace edgefem
