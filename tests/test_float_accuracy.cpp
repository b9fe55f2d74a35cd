// Float kernels against double at small strain: computing zeta as
// d.(2r + d) from the displacement keeps float within 1e-5 of double from
// strain 1e-1 down to 1e-4, slivers included, where |p~|^2 - H would not.
#include <gtest/gtest.h>

#include "edgefem/core/make_box.hpp"
#include "models.hpp"
#include "test_meshes.hpp"

using namespace edgefem;

namespace {

// u = strain * B (X - c), B a fixed mix of stretch and shear with |B| ~ 1.
std::vector<double> strained(const Mesh& mesh, double strain) {
    static constexpr double B[3][3] = {{0.8, 0.3, -0.2}, {0.1, -0.5, 0.4}, {-0.3, 0.2, 0.6}};
    std::vector<double> u(mesh.X.size());
    for (index_t v = 0; v < mesh.num_vertices(); ++v)
        for (int r = 0; r < 3; ++r)
            u[3 * v + r] = strain * (B[r][0] * mesh.X[3 * v] + B[r][1] * mesh.X[3 * v + 1] + B[r][2] * mesh.X[3 * v + 2]);
    return u;
}

// A box whose interior vertices are pushed towards one another's planes to
// make flat (sliver) tets, still positively oriented.
Mesh sliver_box() {
    Mesh mesh = make_box(4, 4, 4);
    for (index_t v = 0; v < mesh.num_vertices(); ++v) {
        double* X = &mesh.X[3 * v];
        const int i = int(std::lround(X[0] / 0.01 + 2)), j = int(std::lround(X[1] / 0.01 + 2)),
                  k = int(std::lround(X[2] / 0.01 + 2));
        if (i > 0 && i < 4 && j > 0 && j < 4 && k > 0 && k < 4) X[2] += ((i + j) % 2 ? 0.0042 : -0.0042);
    }
    return mesh;
}

template <ModelKind Kind, class S>
std::vector<double> edge_force(const EdgeModel<S>& m, const std::vector<double>& u) {
    const auto us = test::cast<S>(u);
    std::vector<S> f(u.size());
    EdgeState<S> st;
    edge_forces<Kind, false>(m, us.data(), f.data(), st);
    return test::cast<double>(f);
}

}  // namespace

TEST(FloatAccuracy, WithinOneE5OfDoubleFromStrain1e1To1e4) {
    auto meshes = test::test_meshes(300000);
    meshes.push_back({"sliver-box", sliver_box()});
    for (const auto& [name, mesh] : meshes) {
        const auto md = test::make_models<double>(mesh);
        const auto mf = test::make_models<float>(mesh);
        for (double strain : {1e-1, 1e-2, 1e-3, 1e-4}) {
            SCOPED_TRACE(name + " strain " + std::to_string(strain));
            const auto u = strained(mesh, strain);
            EXPECT_LE(test::rel_diff(edge_force<ModelKind::FE>(mf.edge, u), edge_force<ModelKind::FE>(md.edge, u)), 1e-5);
            EXPECT_LE(test::rel_diff(edge_force<ModelKind::SN>(mf.edge, u), edge_force<ModelKind::SN>(md.edge, u)), 1e-5);
            std::vector<float> ff(u.size());
            std::vector<double> fd(u.size());
            const auto uf = test::cast<float>(u);
            tet_forces<false>(mf.tet, uf.data(), ff.data());
            tet_forces<false>(md.tet, u.data(), fd.data());
            EXPECT_LE(test::rel_diff(ff, fd), 1e-5);
        }
    }
}

// The test above has teeth: the naive zeta = |p~|^2 - H in float, from
// float positions, is off by far more than 1e-5 at strain 1e-4.
TEST(FloatAccuracy, NaiveZetaWouldFail) {
    const Mesh mesh = make_box(10, 5, 4);
    const auto md = test::make_models<double>(mesh);
    const auto u = strained(mesh, 1e-4);
    double worst = 0, scale = 0;
    for (index_t e = 0; e < md.topo.num_edges(); ++e) {
        const index_t a = md.topo.edges[e][0], b = md.topo.edges[e][1];
        double exact = 0;
        float p2 = 0, H = 0;
        for (int r = 0; r < 3; ++r) {
            const double d = u[3 * a + r] - u[3 * b + r];
            exact += d * (2 * md.coef.rest_edge[3 * e + r] + d);
            const float pf = float(mesh.X[3 * a + r] + u[3 * a + r]) - float(mesh.X[3 * b + r] + u[3 * b + r]);
            const float rf = float(mesh.X[3 * a + r]) - float(mesh.X[3 * b + r]);
            p2 += pf * pf;
            H += rf * rf;
        }
        worst = std::max(worst, std::abs(double(p2 - H) - exact));
        scale = std::max(scale, std::abs(exact));
    }
    EXPECT_GT(worst / scale, 1e-3);
}
