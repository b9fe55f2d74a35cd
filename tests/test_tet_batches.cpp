// The per-tet model's lane batches (TetModel::batches): every tet in exactly
// one lane with its own data, padding lanes inert, and the batched loops
// against the one-tet kernels they replace for built-in scalars.
#include <gtest/gtest.h>

#include "lab/deformations.hpp"
#include "models.hpp"
#include "test_meshes.hpp"

using namespace edgefem;
using test::rel_diff;

namespace {

template <class S>
void check_layout(const BatchedTetModel<S>& m, const std::string& name) {
    ASSERT_EQ(index_t(m.batches.size()), m.num_batches()) << name;
    std::vector<int> seen(m.num_tets(), 0);
    for (index_t b = 0; b < m.num_batches(); ++b)
        for (int l = 0; l < kTetBatchLanes; ++l) {
            const TetBatch<S>& bt = m.batches[b];
            const index_t t = m.batch_tet(b, l);
            const bool pad = t >= m.num_tets();
            if (!pad) ++seen[t];
            const TetData<S> d = pad ? TetData<S>{} : m.data[t];
            for (int i = 0; i < 4; ++i) EXPECT_EQ(bt.v[i][l], pad ? 0 : m.tet[t][i]) << name;
            for (int i = 0; i < 3; ++i)
                for (int c = 0; c < 3; ++c) EXPECT_EQ(bt.Dinv[i][c][l], d.Dinv[i][c]) << name;
            EXPECT_EQ(bt.vol_lambda[l], d.vol_lambda) << name;
            EXPECT_EQ(bt.vol_mu[l], d.vol_mu) << name;
        }
    EXPECT_TRUE(std::all_of(seen.begin(), seen.end(), [](int n) { return n == 1; })) << name;
}

// The batched serial loops against kernel::tet_force / tet_stiffness per tet.
template <class S>
void check_against_per_tet(const test::NamedMesh& nm, double tol) {
    const BatchedTetModel<S> m = make_batched_tet_model<S>(nm.mesh, Material{1e5, 0.3, 1000});
    check_layout(m, nm.name);
    const auto u = test::cast<S>(deformation_displacement(nm.mesh, Deformation::Twist));
    std::vector<S> f(u.size()), f0(u.size(), S(0));
    TetStiffness<S> K;
    const double W = tet_forces_stiffness<true>(m, u.data(), f.data(), K);
    double W0 = 0;
    std::vector<S> K0(90 * std::size_t(m.num_tets()));
    for (index_t t = 0; t < m.num_tets(); ++t) {
        W0 += double(kernel::tet_force(m, t, u.data(), f0.data()));
        kernel::tet_stiffness(m, t, u.data(), &K0[90 * std::size_t(t)]);
    }
    EXPECT_NEAR(W, W0, tol * std::abs(W0)) << nm.name;
    EXPECT_LE(rel_diff(f, f0), tol) << nm.name;
    EXPECT_LE(rel_diff(K.K, K0), tol) << nm.name;
    std::vector<S> f1(u.size());
    EXPECT_EQ(tet_forces<false>(m, u.data(), f1.data()), 0.0);
    EXPECT_EQ(f1, f) << nm.name;  // the energy changes nothing else
}

}  // namespace

TEST(TetBatches, MatchPerTetKernelsDouble) {
    for (const auto& nm : test::test_meshes(300000)) check_against_per_tet<double>(nm, 1e-13);
}

TEST(TetBatches, MatchPerTetKernelsFloat) {
    for (const auto& nm : test::test_meshes(300000)) check_against_per_tet<float>(nm, 1e-5);
}
