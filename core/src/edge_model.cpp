#include "edgefem/core/edge_model.hpp"

namespace edgefem {

template <class S>
double EdgeModel<S>::bytes_per_tet(bool with_stiffness) const {
    const double bytes = edge.size() * sizeof(edge[0]) + rest.size() * sizeof(S) + LE.size() * sizeof(S) +
                         tsep.size() * sizeof(tsep[0]) + LP.size() * sizeof(S) +
                         (with_stiffness ? target.size() * sizeof(target[0]) : 0);
    return num_tets > 0 ? bytes / num_tets : 0.0;
}

template <class S>
EdgeModel<S> make_edge_model(const Topology& topo, const Coefficients& coef) {
    EdgeModel<S> m;
    m.num_vertices = topo.num_vertices;
    m.num_tets = topo.num_tets;
    m.edge = topo.edges;
    m.rest.assign(coef.rest_edge.begin(), coef.rest_edge.end());
    m.LE.assign(coef.LE.begin(), coef.LE.end());
    m.tsep = topo.tseps;
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
