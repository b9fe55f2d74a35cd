#include "edgefem/core/coefficients.hpp"

#include <Eigen/Dense>

#include "edgefem/core/error.hpp"

namespace edgefem {

TetGradients tet_gradients(const Mesh& mesh, index_t t) {
    const index_t* v = &mesh.tets[4 * static_cast<std::size_t>(t)];
    Eigen::Matrix3d Dm;
    for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r) Dm(r, c) = mesh.X[3 * v[c + 1] + r] - mesh.X[3 * v[0] + r];
    // Rows of Dm^-1 are grad phi_1..3.
    const Eigen::Matrix3d inv = Dm.inverse();
    TetGradients g;
    g.volume = Dm.determinant() / 6.0;
    for (int r = 0; r < 3; ++r) {
        g.a[0][r] = 0;
        for (int i = 1; i < 4; ++i) {
            g.a[i][r] = inv(i - 1, r);
            g.a[0][r] -= inv(i - 1, r);
        }
    }
    return g;
}

void tet_edge_form(const TetGradients& g, double lambda, double mu, double A[6][6]) {
    double G[4][4];  // Gram matrix a_i . a_j
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) G[i][j] = g.a[i][0] * g.a[j][0] + g.a[i][1] * g.a[j][1] + g.a[i][2] * g.a[j][2];
    for (int e = 0; e < 6; ++e)
        for (int f = 0; f < 6; ++f) {
            const int i = kTetEdge[e][0], j = kTetEdge[e][1], k = kTetEdge[f][0], l = kTetEdge[f][1];
            // lambda/2 c_e c_f + mu tr(S_e S_f), c_e = a_i.a_j.
            A[e][f] = g.volume * (0.5 * lambda * G[i][j] * G[k][l] + 0.5 * mu * (G[i][k] * G[j][l] + G[i][l] * G[j][k]));
        }
}

Coefficients compute_coefficients(const Mesh& mesh, const Topology& topo, const Materials& materials) {
    materials.validate();
    Coefficients c;
    const index_t ne = topo.num_edges();
    c.rest_edge.resize(3 * static_cast<std::size_t>(ne));
    c.H.resize(ne);
    for (index_t e = 0; e < ne; ++e) {
        double h = 0;
        for (int r = 0; r < 3; ++r) {
            const double d = mesh.X[3 * topo.edges[e][0] + r] - mesh.X[3 * topo.edges[e][1] + r];
            c.rest_edge[3 * e + r] = d;
            h += d * d;
        }
        c.H[e] = h;
    }
    c.LE.assign(ne, 0.0);
    c.LP.assign(topo.num_tseps(), 0.0);
    c.tet_volume.resize(topo.num_tets);
    for (index_t t = 0; t < topo.num_tets; ++t) {
        const Material& m = materials.of(mesh.tet_region(t));
        const TetGradients g = tet_gradients(mesh, t);
        c.tet_volume[t] = g.volume;
        double A[6][6];
        tet_edge_form(g, m.lambda(), m.mu(), A);
        const auto& te = topo.tet_edges[t];
        for (int k = 0; k < 6; ++k) c.LE[te[k]] += A[k][k];
        for (int k = 0; k < 15; ++k) {
            const int e = kTetEdgePair[k][0], f = kTetEdgePair[k][1];
            const index_t p = topo.find_tsep(te[e], te[f]);
            if (p < 0) throw Error("internal: TSEP of " + mesh.describe_tet(t) + " missing");
            c.LP[p] += A[e][f];
        }
    }
    return c;
}

std::vector<double> lumped_mass(const Mesh& mesh, const Materials& materials) {
    std::vector<double> m(mesh.num_vertices(), 0.0);
    for (index_t t = 0; t < mesh.num_tets(); ++t) {
        const index_t* v = &mesh.tets[4 * static_cast<std::size_t>(t)];
        const double vol = signed_volume(&mesh.X[3 * v[0]], &mesh.X[3 * v[1]], &mesh.X[3 * v[2]], &mesh.X[3 * v[3]]);
        const double share = materials.of(mesh.tet_region(t)).density * vol / 4;
        for (int k = 0; k < 4; ++k) m[v[k]] += share;
    }
    return m;
}

}  // namespace edgefem
