// The per-item formulas of core/include/edgefem/physics/ on their own:
// against long-double arithmetic, finite differences and each other, and
// instantiated on SIMD lanes (what the CPU back-end's batch kernels do)
// against the same formulas on scalars, lane by lane.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "edgefem/physics/edge_blocks.hpp"
#include "edgefem/physics/edge_force.hpp"
#include "edgefem/physics/edge_g.hpp"
#include "edgefem/physics/edge_stiffness.hpp"
#include "edgefem/physics/edge_strain.hpp"
#include "edgefem/physics/tet_local_form.hpp"
#include "edgefem/physics/tet_stvk.hpp"
#include "edgefem/physics/tsep_stiffness.hpp"

using namespace edgefem;

namespace {

typedef double V4 __attribute__((vector_size(32)));

std::mt19937_64& rng() {
    static std::mt19937_64 r(20261126);
    return r;
}
double uniform(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng()); }

// zeta and the force of a spring-network edge (own_g only) at ends x0, x1.
struct SpringEdge {
    double r[3], LE;
    void force(const double* d, double* f0) const {
        double q[3];
        const double z = physics::edge_strain(d[0], d[1], d[2], r[0], r[1], r[2], q[0], q[1], q[2]);
        const double g = physics::own_g(LE, z);
        for (int i = 0; i < 3; ++i) f0[i] = physics::edge_force(q[i], g);
    }
};

// One tet: rest gradients (Dm^-1 rows) from a random non-degenerate tet.
struct Tet {
    double Dinv[3][3], vl, vm;
    Tet() {
        double Dm[3][3];
        for (;;) {
            for (auto& row : Dm)
                for (double& x : row) x = uniform(-1, 1);
            Dm[0][0] += 1.5;
            Dm[1][1] += 1.5;
            Dm[2][2] += 1.5;
            const double det = Dm[0][0] * (Dm[1][1] * Dm[2][2] - Dm[1][2] * Dm[2][1]) -
                               Dm[0][1] * (Dm[1][0] * Dm[2][2] - Dm[1][2] * Dm[2][0]) +
                               Dm[0][2] * (Dm[1][0] * Dm[2][1] - Dm[1][1] * Dm[2][0]);
            if (std::abs(det) < 0.5) continue;
            // inverse by cofactors
            for (int i = 0; i < 3; ++i)
                for (int j = 0; j < 3; ++j) {
                    const int a = (j + 1) % 3, b = (j + 2) % 3, c = (i + 1) % 3, d = (i + 2) % 3;
                    Dinv[i][j] = (Dm[a][c] * Dm[b][d] - Dm[a][d] * Dm[b][c]) / det;
                }
            break;
        }
        vl = uniform(0.5, 2);
        vm = uniform(0.5, 2);
    }
    double energy(const double (&U)[4][3]) const {
        physics::TetDeformation<double> d;
        physics::tet_deformation<true, double>(U, Dinv, vl, vm, d);
        return d.energy;
    }
    void forces(const double (&U)[4][3], double (&f)[4][3]) const {
        physics::TetDeformation<double> d;
        physics::tet_deformation<false, double>(U, Dinv, vl, vm, d);
        physics::tet_forces(d, Dinv, f);
    }
};

void random_displacements(double (&U)[4][3], double scale) {
    for (auto& v : U)
        for (double& x : v) x = uniform(-scale, scale);
}

}  // namespace

TEST(Physics, EdgeStrainHasNoCancellation) {
    // zeta against |r + d|^2 - |r|^2 in long double: relative to |d| (|r| +
    // |p~|), the size of its terms, a few eps at every strain.
    for (double strain : {1e-1, 1e-4, 1e-8}) {
        double worst = 0;
        for (int k = 0; k < 1000; ++k) {
            const double r[3] = {uniform(-1, 1), uniform(-1, 1), uniform(-1, 1)};
            const double d[3] = {strain * uniform(-1, 1), strain * uniform(-1, 1), strain * uniform(-1, 1)};
            double q[3];
            const double z = physics::edge_strain(d[0], d[1], d[2], r[0], r[1], r[2], q[0], q[1], q[2]);
            // |r + d|^2 - |r|^2 = d . (2 r + d) exactly; in long double the
            // products and sums keep 11 more bits than double.
            long double exact = 0, size = 0, nd = 0, nr = 0, nq = 0;
            for (int i = 0; i < 3; ++i) {
                const long double qi = (long double)r[i] + d[i];
                exact += (long double)d[i] * (2 * (long double)r[i] + d[i]);
                nd += (long double)d[i] * d[i];
                nr += (long double)r[i] * r[i];
                nq += qi * qi;
                EXPECT_EQ(q[i], r[i] + d[i]);
            }
            size = std::sqrt(nd) * (std::sqrt(nr) + std::sqrt(nq));
            worst = std::max(worst, double(std::abs(z - exact) / size));
        }
        EXPECT_LT(worst, 8 * 2.2e-16) << "strain " << strain;
    }
}

TEST(Physics, EdgeStiffnessIsTheDerivativeOfTheEdgeForce) {
    // Spring network edge: K(E) = d f(V0) / d x(V1) (central differences),
    // i.e. -d f(V0) / d d with d = u(V0) - u(V1).
    for (int k = 0; k < 20; ++k) {
        SpringEdge e{{uniform(-1, 1), uniform(-1, 1), uniform(-1, 1)}, uniform(0.5, 2)};
        const double d[3] = {uniform(-0.3, 0.3), uniform(-0.3, 0.3), uniform(-0.3, 0.3)};
        double q[3];
        const double z = physics::edge_strain(d[0], d[1], d[2], e.r[0], e.r[1], e.r[2], q[0], q[1], q[2]);
        double K[9];
        physics::edge_stiffness(e.LE, physics::own_g(e.LE, z), q, K);
        for (int j = 0; j < 3; ++j) {
            const double h = 1e-6;
            double dp[3] = {d[0], d[1], d[2]}, dm[3] = {d[0], d[1], d[2]}, fp[3], fm[3];
            dp[j] -= h;  // x(V1) + h moves d by -h
            dm[j] += h;
            e.force(dp, fp);
            e.force(dm, fm);
            for (int i = 0; i < 3; ++i) EXPECT_NEAR(K[3 * i + j], (fp[i] - fm[i]) / (2 * h), 1e-7) << i << j;
        }
        // Definite: g < 0 clamped, so -g I drops out.
        physics::edge_stiffness(e.LE, physics::stiffness_g(-1.0, true), q, K);
        for (int i = 0; i < 3; ++i) EXPECT_EQ(K[4 * i], -2 * e.LE * q[i] * q[i]);
    }
}

TEST(Physics, PairBlockSignsFollowTheEndsOfTheEdges) {
    // Slot k = 2 i + j carries (-1)^(i + j).
    const double c = physics::pair_coefficient(0.75);
    EXPECT_EQ(c, 1.5);
    EXPECT_EQ(physics::slot_coefficient(c, 0), c);
    EXPECT_EQ(physics::slot_coefficient(c, 1), -c);
    EXPECT_EQ(physics::slot_coefficient(c, 2), -c);
    EXPECT_EQ(physics::slot_coefficient(c, 3), c);
    const double x[3] = {1, 2, 3}, y[3] = {-1, 0.5, 2};
    double blk[9] = {};
    physics::add_pair_block(c, x, y, blk);
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) EXPECT_EQ(blk[3 * i + j], c * x[i] * y[j]);
}

TEST(Physics, BlockProductsAreKTimesDAndItsTranspose) {
    const double K[9] = {1, 2, 3, 4, 5, 6, 7, 8, 9}, d[3] = {0.5, -1, 2};
    for (int i = 0; i < 3; ++i) {
        EXPECT_EQ(physics::row_times(K[3 * i], K[3 * i + 1], K[3 * i + 2], d[0], d[1], d[2]),
                  K[3 * i] * d[0] + K[3 * i + 1] * d[1] + K[3 * i + 2] * d[2]);
        EXPECT_EQ(physics::transpose_times(K[i], K[3 + i], K[6 + i], d[0], d[1], d[2]),
                  K[i] * d[0] + K[3 + i] * d[1] + K[6 + i] * d[2]);
    }
    double D0[9] = {}, D1[9] = {};
    physics::subtract_block(K, D0);
    physics::subtract_block_transposed(K, D1);
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            EXPECT_EQ(D0[3 * i + j], -K[3 * i + j]);
            EXPECT_EQ(D1[3 * i + j], -K[3 * j + i]);
        }
}

TEST(Physics, TetForcesAreTheEnergyGradient) {
    for (int k = 0; k < 10; ++k) {
        const Tet t;
        double U[4][3], f[4][3];
        random_displacements(U, 0.2);
        t.forces(U, f);
        double sum[3] = {0, 0, 0};
        for (int i = 0; i < 4; ++i)
            for (int r = 0; r < 3; ++r) {
                const double h = 1e-6, u0 = U[i][r];
                U[i][r] = u0 + h;
                const double ep = t.energy(U);
                U[i][r] = u0 - h;
                const double em = t.energy(U);
                U[i][r] = u0;
                EXPECT_NEAR(f[i][r], (ep - em) / (2 * h), 1e-6 * (1 + std::abs(f[i][r])));
                sum[r] += f[i][r];
            }
        for (double s : sum) EXPECT_NEAR(s, 0, 1e-12);  // translation invariance
    }
}

TEST(Physics, TetStiffnessIsTheForceDerivativeAndItsProduct) {
    for (int k = 0; k < 10; ++k) {
        const Tet t;
        double U[4][3], X[4][3];
        random_displacements(U, 0.2);
        random_displacements(X, 1.0);
        physics::TetDeformation<double> d;
        physics::tet_deformation<false, double>(U, t.Dinv, t.vl, t.vm, d);
        physics::TetStiffnessTerms<double> terms;
        physics::tet_stiffness_terms<double>(d, t.Dinv, t.vl, t.vm, terms);
        // Block (a, b) entry (r, c) = d f_a[r] / d u_b[c].
        for (int b = 0; b < 4; ++b)
            for (int c = 0; c < 3; ++c) {
                const double h = 1e-6, u0 = U[b][c];
                double fp[4][3], fm[4][3];
                U[b][c] = u0 + h;
                t.forces(U, fp);
                U[b][c] = u0 - h;
                t.forces(U, fm);
                U[b][c] = u0;
                for (int a = 0; a < 4; ++a)
                    for (int r = 0; r < 3; ++r) {
                        const double K = a <= b ? physics::tet_stiffness_entry(terms, a, b, r, c)
                                                : physics::tet_stiffness_entry(terms, b, a, c, r);
                        EXPECT_NEAR(K, (fp[a][r] - fm[a][r]) / (2 * h), 1e-6 * (1 + std::abs(K)));
                    }
            }
        // The matrix-free product equals the stored blocks times x.
        double y[4][3];
        physics::tet_stiffness_times<double>(d, X, t.Dinv, t.vl, t.vm, y);
        for (int a = 0; a < 4; ++a)
            for (int r = 0; r < 3; ++r) {
                double s = 0;
                for (int b = 0; b < 4; ++b)
                    for (int c = 0; c < 3; ++c)
                        s += (a <= b ? physics::tet_stiffness_entry(terms, a, b, r, c)
                                     : physics::tet_stiffness_entry(terms, b, a, c, r)) *
                             X[b][c];
                EXPECT_NEAR(y[a][r], s, 1e-12 * (1 + std::abs(s)));
            }
    }
}

// The batch kernels run the formulas on 4-lane vectors: every lane must get
// what the scalar instantiation gives for that lane's item, to the last bits
// (the compiler may fuse a multiply and an add into an FMA in one
// instantiation and not in the other: a few ulps of the terms' size).
namespace {
void expect_lane(double lane, double scalar, double size) {
    EXPECT_LE(std::abs(lane - scalar), 4 * 2.2e-16 * size) << lane << " vs " << scalar;
}
}  // namespace

TEST(Physics, LanesGiveTheScalarResultsLaneByLane) {
    // Edge strain.
    V4 d[3], r[3], q[3];
    for (int c = 0; c < 3; ++c)
        for (int l = 0; l < 4; ++l) {
            d[c][l] = uniform(-0.1, 0.1);
            r[c][l] = uniform(-1, 1);
        }
    const V4 z = physics::edge_strain(d[0], d[1], d[2], r[0], r[1], r[2], q[0], q[1], q[2]);
    for (int l = 0; l < 4; ++l) {
        double qs[3];
        const double zs = physics::edge_strain(d[0][l], d[1][l], d[2][l], r[0][l], r[1][l], r[2][l], qs[0], qs[1], qs[2]);
        expect_lane(z[l], zs, 4);
        for (int c = 0; c < 3; ++c) expect_lane(q[c][l], qs[c], 2);
    }
    // Per-tet deformation, forces and stiffness entries.
    Tet tets[4];
    V4 Dinv[3][3], vl, vm, U[4][3];
    double Us[4][4][3];
    for (int l = 0; l < 4; ++l) {
        random_displacements(Us[l], 0.2);
        for (int i = 0; i < 3; ++i)
            for (int c = 0; c < 3; ++c) Dinv[i][c][l] = tets[l].Dinv[i][c];
        vl[l] = tets[l].vl;
        vm[l] = tets[l].vm;
        for (int i = 0; i < 4; ++i)
            for (int c = 0; c < 3; ++c) U[i][c][l] = Us[l][i][c];
    }
    physics::TetDeformation<V4> dv;
    physics::tet_deformation<true, double>(U, Dinv, vl, vm, dv);
    V4 fv[4][3];
    physics::tet_forces(dv, Dinv, fv);
    physics::TetStiffnessTerms<V4> kv;
    physics::tet_stiffness_terms<double>(dv, Dinv, vl, vm, kv);
    for (int l = 0; l < 4; ++l) {
        physics::TetDeformation<double> ds;
        physics::tet_deformation<true, double>(Us[l], tets[l].Dinv, tets[l].vl, tets[l].vm, ds);
        expect_lane(dv.energy[l], ds.energy, 16 * std::abs(ds.energy) + 1e-3);
        double fs[4][3];
        physics::tet_forces(ds, tets[l].Dinv, fs);
        for (int i = 0; i < 4; ++i)
            for (int c = 0; c < 3; ++c) expect_lane(fv[i][c][l], fs[i][c], 64);
        physics::TetStiffnessTerms<double> ks;
        physics::tet_stiffness_terms<double>(ds, tets[l].Dinv, tets[l].vl, tets[l].vm, ks);
        for (int i = 0; i < 4; ++i)
            for (int j = i; j < 4; ++j)
                for (int a = 0; a < 3; ++a)
                    for (int b = 0; b < 3; ++b)
                        expect_lane(physics::tet_stiffness_entry(kv, i, j, a, b)[l],
                                    physics::tet_stiffness_entry(ks, i, j, a, b), 64);
    }
    // The tet-local form's W and blocks.
    V4 A[6][6], P[6][3];
    for (int k = 0; k < 6; ++k)
        for (int m = 0; m < 6; ++m)
            for (int l = 0; l < 4; ++l) A[k][m][l] = m == k ? 0.0 : (m < k ? A[m][k][l] : uniform(-1, 1));
    for (auto& row : P)
        for (V4& x : row)
            for (int l = 0; l < 4; ++l) x[l] = uniform(-1, 1);
    V4 W[6][4][3];
    physics::form_w<double>([&](int k, int m) { return A[k][m]; }, P, W);
    for (int l = 0; l < 4; ++l) {
        double Ps[6][3], Ws[6][4][3];
        for (int k = 0; k < 6; ++k)
            for (int c = 0; c < 3; ++c) Ps[k][c] = P[k][c][l];
        physics::form_w<double>([&](int k, int m) { return A[k][m][l]; }, Ps, Ws);
        for (int e = 0; e < 6; ++e) {
            V4 kb[9];
            double ks[9];
            physics::form_block<double>(e, P, W, kb);
            physics::form_block<double>(e, Ps, Ws, ks);
            for (int x = 0; x < 9; ++x) expect_lane(kb[x][l], ks[x], 64);
        }
    }
}

TEST(Physics, TetLocalFormBlocksAreTheEnergyHessian) {
    // One tet, W = 1/4 sum_{k != l} A_kl zeta_k zeta_l (the off-diagonal
    // part): its Hessian's off-diagonal blocks, by differences of the forces
    // f_a = sum_k s_ka p~_k g_k, g_k = sum_{l != k} A_kl zeta_l, are K_ab.
    double A[6][6];
    for (int k = 0; k < 6; ++k)
        for (int m = 0; m < 6; ++m) A[k][m] = m == k ? 0.0 : (m < k ? A[m][k] : uniform(-1, 1));
    double x[4][3];
    for (auto& v : x)
        for (double& c : v) c = uniform(-1, 1);
    const auto coef = [&](int k, int m) { return A[k][m]; };
    const auto forces = [&](const double (&xs)[4][3], double (&f)[4][3]) {
        double p[6][3], zeta[6];
        for (int e = 0; e < 6; ++e) {
            const int a = physics::tet_edge_vertex(e, 0), b = physics::tet_edge_vertex(e, 1);
            zeta[e] = 0;
            for (int c = 0; c < 3; ++c) {
                p[e][c] = xs[a][c] - xs[b][c];
                zeta[e] += p[e][c] * p[e][c];
            }
        }
        for (auto& v : f)
            for (double& c : v) c = 0;
        for (int e = 0; e < 6; ++e) {
            const double g = physics::form_g(e, coef, zeta);
            for (int c = 0; c < 3; ++c) {
                f[physics::tet_edge_vertex(e, 0)][c] += physics::edge_force(p[e][c], g);
                f[physics::tet_edge_vertex(e, 1)][c] -= physics::edge_force(p[e][c], g);
            }
        }
    };
    double p[6][3];
    for (int e = 0; e < 6; ++e)
        for (int c = 0; c < 3; ++c) p[e][c] = x[physics::tet_edge_vertex(e, 0)][c] - x[physics::tet_edge_vertex(e, 1)][c];
    double W[6][4][3], zeta[6], g[6];
    physics::form_w<double>(coef, p, W);
    for (int e = 0; e < 6; ++e) zeta[e] = p[e][0] * p[e][0] + p[e][1] * p[e][1] + p[e][2] * p[e][2];
    for (int e = 0; e < 6; ++e) g[e] = physics::form_g(e, coef, zeta);
    for (int e = 0; e < 6; ++e) {
        const int a = physics::tet_edge_vertex(e, 0), b = physics::tet_edge_vertex(e, 1);
        double K[9];
        physics::form_block<double>(e, p, W, K);
        for (int c = 0; c < 3; ++c) {
            const double h = 1e-6, x0 = x[b][c];
            double fp[4][3], fm[4][3];
            x[b][c] = x0 + h;
            forces(x, fp);
            x[b][c] = x0 - h;
            forces(x, fm);
            x[b][c] = x0;
            // d f_a / d x_b = K_ab - g(E) I: the -g I of the edge (a, b)
            // belongs to its edge term (physics::edge_stiffness).
            for (int r = 0; r < 3; ++r)
                EXPECT_NEAR(K[3 * r + c], (fp[a][r] - fm[a][r]) / (2 * h) + (r == c ? g[e] : 0.0), 1e-6) << e << r << c;
        }
    }
}
