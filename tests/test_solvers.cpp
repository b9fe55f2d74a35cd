// The linear solvers: CHOLMOD's factorisation (SparseCholesky) against
// dense LU, its symbolic analysis reused; smoothed aggregation's hierarchy
// (the rigid-body modes reproduced by the tentative prolongators and nearly
// in K's nullspace; the V-cycle symmetric and positive with each smoother;
// the Chebyshev smoother's damping of the top of the spectrum by its
// polynomial's bound); AMG-preconditioned CG, block-Jacobi CG and the direct
// solver reaching the same step to 1e-8; AMG's iterations at a large step;
// the preconditioner's name checked.
#include <gtest/gtest.h>

#include <Eigen/LU>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <functional>
#include <numeric>
#include <string>

#include "cantilever.hpp"
#include "edgefem/core/make_box.hpp"
#include "edgefem/core/read_mesh.hpp"
#include "edgefem/core/reference_operator.hpp"
#include "edgefem/core/scene_json.hpp"
#include "edgefem/core/simulator.hpp"
#include "edgefem/core/smoothed_aggregation.hpp"
#include "edgefem/core/sparse_assembly.hpp"
#include "edgefem/core/sparse_cholesky.hpp"
#include "edgefem/parallel/executors.hpp"
#include "test_meshes.hpp"

using namespace edgefem;

namespace {

// Plain loops throughout: Eigen's dense reductions and products trip g++
// 12's false -Wmaybe-uninitialized with AVX-512 (GCC PR 105593).
using Dense = std::vector<std::vector<double>>;

LowerCsc lower_of(const Dense& A) {
    LowerCsc L;
    L.n = index_t(A.size());
    L.col_start.push_back(0);
    for (std::size_t j = 0; j < A.size(); ++j) {
        for (std::size_t i = j; i < A.size(); ++i)
            if (A[i][j] != 0 || i == j) {
                L.row.push_back(index_t(i));
                L.value.push_back(A[i][j]);
            }
        L.col_start.push_back(index_t(L.row.size()));
    }
    return L;
}

// A symmetric banded test matrix: a shifted 1D Laplacian with a coupling to
// the dof 3 away (shift < 0 makes it indefinite).
Dense banded(int n, double shift) {
    Dense A(std::size_t(n), std::vector<double>(std::size_t(n), 0.0));
    for (std::size_t i = 0; i < std::size_t(n); ++i) {
        A[i][i] = 2.5 + shift + 0.01 * double(i);
        if (i + 1 < std::size_t(n)) A[i][i + 1] = A[i + 1][i] = -1;
        if (i + 3 < std::size_t(n)) A[i][i + 3] = A[i + 3][i] = 0.2;
    }
    return A;
}

// |A x - b| / |b|, the full matrix A.
double residual(const Dense& A, const std::vector<double>& x, const std::vector<double>& b) {
    double rr = 0, bb = 0;
    for (std::size_t i = 0; i < A.size(); ++i) {
        double r = -b[i];
        for (std::size_t j = 0; j < A.size(); ++j) r += A[i][j] * x[j];
        rr += r * r;
        bb += b[i] * b[i];
    }
    return std::sqrt(rr / bb);
}

double frobenius(const Eigen::MatrixXd& M) {
    double s = 0;
    for (Eigen::Index j = 0; j < M.cols(); ++j)
        for (Eigen::Index i = 0; i < M.rows(); ++i) s += M(i, j) * M(i, j);
    return std::sqrt(s);
}

double dot(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
    double s = 0;
    for (Eigen::Index i = 0; i < a.size(); ++i) s += a[i] * b[i];
    return s;
}

double relative(const std::vector<double>& a, const std::vector<double>& b) {
    double d = 0, s = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
        d += (a[i] - b[i]) * (a[i] - b[i]);
        s += b[i] * b[i];
    }
    return std::sqrt(d / s);
}

}  // namespace

TEST(SparseCholesky, SolvesToRoundOffAndReusesItsAnalysis) {
    const int n = 60;
    SparseCholesky chol;
    std::vector<double> b(static_cast<std::size_t>(n)), x(static_cast<std::size_t>(n));
    for (std::size_t i = 0; i < b.size(); ++i) b[i] = std::cos(0.3 * double(i));
    for (double shift : {0.0, 1.0, 7.0}) {  // same pattern: one analysis
        const Dense A = banded(n, shift);
        ASSERT_TRUE(chol.factor(lower_of(A)));
        EXPECT_FALSE(chol.used_ldlt());
        chol.solve(b.data(), x.data());
        EXPECT_LT(residual(A, x, b), 1e-13);
    }
    EXPECT_EQ(chol.analyses(), 1);
    // Indefinite: LL^T fails, LDL^T (its own analysis) solves and says so.
    const Dense A = banded(n, -2.0);
    ASSERT_TRUE(chol.factor(lower_of(A)));
    EXPECT_TRUE(chol.used_ldlt());
    EXPECT_TRUE(chol.indefinite());
    chol.solve(b.data(), x.data());
    EXPECT_LT(residual(A, x, b), 1e-11);
    EXPECT_EQ(chol.analyses(), 2);
    // A new pattern: analysed again.
    Dense C = banded(n, 1.0);
    C[0][5] = C[5][0] = 0.1;
    ASSERT_TRUE(chol.factor(lower_of(C)));
    EXPECT_EQ(chol.analyses(), 3);
}

TEST(SmoothedAggregation, TentativeProlongatorsReproduceTheRigidBodyModes) {
    const Mesh mesh = make_box(12, 6, 6);
    auto op = make_reference_operator<double>(mesh, Materials{Material{1e5, 0.3, 1000}}, ModelKind::FE, Method::Edge);
    std::vector<double> u(mesh.X.size(), 0.0), f(u.size());
    op->forces(u.data(), f.data(), false);
    op->build_stiffness(false);
    const std::size_t n = mesh.X.size();
    std::vector<index_t> dof;
    for (int fixed_first : {0, 1}) {
        SCOPED_TRACE(fixed_first ? "first 10 vertices fixed" : "free body");
        std::vector<std::uint8_t> free_dof(n, 1);
        if (fixed_first)
            for (std::size_t i = 0; i < 30; ++i) free_dof[i] = 0;
        const index_t nf = number_free_dofs(std::vector<std::uint8_t>(n, 1), dof);
        const Eigen::SparseMatrix<double> Kfull = assemble_system<double>(dof, nf, 0.0, {}, {{1.0, op.get()}});
        // The rigid-body modes are K's nullspace at rest (the near-nullspace).
        const Eigen::MatrixXd B = rigid_body_modes(mesh.X);
        const Eigen::MatrixXd KB = Kfull * B;
        double knorm = 0;
        for (int k = 0; k < Kfull.outerSize(); ++k)
            for (Eigen::SparseMatrix<double>::InnerIterator it(Kfull, k); it; ++it) knorm += it.value() * it.value();
        EXPECT_LT(frobenius(KB), 1e-9 * std::sqrt(knorm) * frobenius(B));
        // The projected system with a mass term, as the simulator's.
        SparseRows A = Kfull;
        for (Eigen::Index i = 0; i < A.rows(); ++i) A.coeffRef(i, i) += 50.0;
        for (int k = 0; k < A.outerSize(); ++k)
            for (SparseRows::InnerIterator it(A, k); it; ++it)
                if (!free_dof[std::size_t(it.row())] || !free_dof[std::size_t(it.col())]) it.valueRef() = 0;
        SmoothedAggregation amg;
        AmgSettings settings{100, 8, 1, 12};
        settings.dense_coarsest = 0;  // three levels or more
        amg.build(A, mesh.X, free_dof, settings);
        ASSERT_GE(amg.levels(), 3);
        for (int l = 0; l + 1 < amg.levels(); ++l) {
            const Eigen::MatrixXd& Bl = amg.near_nullspace(l);
            const Eigen::MatrixXd PB = amg.tentative(l) * amg.near_nullspace(l + 1);
            EXPECT_LT(frobenius(PB - Bl), 1e-10 * frobenius(Bl)) << "level " << l;
            EXPECT_GT(frobenius(Bl), 0);
            EXPECT_EQ(amg.prolongator(l).cols(), amg.dofs(l + 1));
            // Tentative columns orthonormal per aggregate: P^T P = I on the
            // columns that carry a mode.
            const Eigen::MatrixXd PtP = Eigen::MatrixXd(SparseRows(amg.tentative(l).transpose()) * amg.tentative(l));
            for (Eigen::Index c = 0; c < PtP.rows(); ++c)
                if (PtP(c, c) > 0.5) {
                    EXPECT_NEAR(PtP(c, c), 1.0, 1e-12);
                }
        }
        // Level 0's modes are the rest shape's rigid motions, zero on fixed dofs.
        const Eigen::MatrixXd& B0 = amg.near_nullspace(0);
        for (std::size_t i = 0; i < n; ++i)
            for (int c = 0; c < 6; ++c)
                EXPECT_EQ(B0(Eigen::Index(i), c), free_dof[i] ? B(Eigen::Index(i), c) : 0.0);
        // The V-cycle is a symmetric positive definite operator: x.Mz = z.Mx.
        const auto fine = [&](const double* x, double* y) {
            Eigen::Map<Eigen::VectorXd>(y, A.rows()) = A * Eigen::Map<const Eigen::VectorXd>(x, A.rows());
        };
        Eigen::VectorXd r1(A.rows()), r2(A.rows()), z1(A.rows()), z2(A.rows());
        for (Eigen::Index i = 0; i < A.rows(); ++i) {
            r1[i] = free_dof[std::size_t(i)] ? std::sin(1.0 + i) : 0.0;
            r2[i] = free_dof[std::size_t(i)] ? std::cos(0.7 * i) : 0.0;
        }
        amg.apply(r1.data(), z1.data(), fine);
        amg.apply(r2.data(), z2.data(), fine);
        EXPECT_NEAR(dot(r2, z1), dot(r1, z2), 1e-10 * std::abs(dot(r1, z2)));
        EXPECT_GT(dot(r1, z1), 0);
    }
}

namespace {

// A = K + 50 I at rest on an nx x ny x nz box with its first `fixed`
// vertices fixed, projected as the simulator's (rows and columns of fixed
// dofs zero).
struct BoxSystem {
    Mesh mesh;
    std::vector<std::uint8_t> free_dof;
    SparseRows A;
};

BoxSystem box_system(index_t nx, index_t ny, index_t nz, std::size_t fixed) {
    BoxSystem b{make_box(nx, ny, nz), {}, {}};
    auto op = make_reference_operator<double>(b.mesh, Materials{Material{1e5, 0.3, 1000}}, ModelKind::FE, Method::Edge);
    std::vector<double> u(b.mesh.X.size(), 0.0), f(u.size());
    op->forces(u.data(), f.data(), false);
    op->build_stiffness(false);
    const std::size_t n = b.mesh.X.size();
    b.free_dof.assign(n, 1);
    for (std::size_t i = 0; i < 3 * fixed; ++i) b.free_dof[i] = 0;
    std::vector<index_t> dof;
    const index_t nf = number_free_dofs(std::vector<std::uint8_t>(n, 1), dof);
    b.A = assemble_system<double>(dof, nf, 0.0, {}, {{1.0, op.get()}});
    for (Eigen::Index i = 0; i < b.A.rows(); ++i) b.A.coeffRef(i, i) += 50.0;
    for (int k = 0; k < b.A.outerSize(); ++k)
        for (SparseRows::InnerIterator it(b.A, k); it; ++it)
            if (!b.free_dof[std::size_t(it.row())] || !b.free_dof[std::size_t(it.col())]) it.valueRef() = 0;
    return b;
}

// dense_coarsest 0: these boxes coarsen to at least 3 levels (the default
// would stop at a dense level 1 on the smaller ones)
AmgSettings smoother_settings(AmgSmoother kind, int steps, int max_coarse_dofs, double dense_coarsest = 0) {
    AmgSettings a;
    a.smoother = kind;
    a.smoothing_steps = steps;
    a.max_coarse_dofs = max_coarse_dofs;
    a.dense_coarsest = dense_coarsest;
    return a;
}


// The system of the box turned rigidly by R (`angle` about the axis (1, 2,
// 3)) about the origin: the positions R X and the matrix with each 3x3
// block R A_IJ R^T, in A's pattern (its blocks stored whole).
struct Turned {
    std::vector<double> X;
    SparseRows A;
};
Turned turned(const BoxSystem& sys, double angle) {
    double k[3] = {1, 2, 3}, R[3][3];
    const double len = std::sqrt(14.0), c = std::cos(angle), s = std::sin(angle);
    for (double& x : k) x /= len;
    for (int i = 0; i < 3; ++i)  // Rodrigues: c I + s [k]x + (1 - c) k k^T
        for (int j = 0; j < 3; ++j) R[i][j] = (i == j ? c : 0.0) + (1 - c) * k[i] * k[j];
    R[0][1] -= s * k[2];
    R[0][2] += s * k[1];
    R[1][0] += s * k[2];
    R[1][2] -= s * k[0];
    R[2][0] -= s * k[1];
    R[2][1] += s * k[0];
    Turned t{sys.mesh.X, sys.A};
    for (std::size_t v = 0; v < t.X.size(); v += 3)
        for (int i = 0; i < 3; ++i) {
            t.X[v + std::size_t(i)] = 0;
            for (int j = 0; j < 3; ++j) t.X[v + std::size_t(i)] += R[i][j] * sys.mesh.X[v + std::size_t(j)];
        }
    for (Eigen::Index row = 0; row < t.A.rows(); ++row)
        for (SparseRows::InnerIterator it(t.A, row); it; ++it) {
            const Eigen::Index I = 3 * (row / 3), J = 3 * (it.col() / 3);
            const int i = int(row % 3), j = int(it.col() % 3);
            double v = 0;
            for (int a = 0; a < 3; ++a)
                for (int b = 0; b < 3; ++b) v += R[i][a] * sys.A.coeff(I + a, J + b) * R[j][b];
            it.valueRef() = v;
        }
    return t;
}

// max |a - b| over max |b| (the same shape; b's pattern or a's)
double max_difference(const SparseRows& a, const SparseRows& b) {
    const SparseRows d = a - b;
    double dm = 0, bm = 0;
    for (Eigen::Index i = 0; i < d.outerSize(); ++i)
        for (SparseRows::InnerIterator it(d, i); it; ++it) dm = std::max(dm, std::abs(it.value()));
    for (Eigen::Index i = 0; i < b.outerSize(); ++i)
        for (SparseRows::InnerIterator it(b, i); it; ++it) bm = std::max(bm, std::abs(it.value()));
    return dm / bm;
}

}  // namespace

// rebuild() on a body turned rigidly from where build() was: the strength
// of connection (|A_IJ|_F) is rotation invariant, so build()'s aggregates
// are those a fresh build() on the turned body forms, and the rebuilt
// prolongators, coarse operators and V-cycle are the fresh build's to
// round-off: the prolongators and coarse operators are held in float, so
// within 1e-6 of the largest entry (a few float roundings), the V-cycle within
// 1e-5. A refresh alone (the rest shape's prolongators) is far off (the
// rotation's size), with each smoother.
TEST(SmoothedAggregation, RebuildOnATurnedBodyIsAFreshBuildThere) {
    const BoxSystem sys = box_system(16, 8, 8, 10);
    const Turned t = turned(sys, 0.7);
    const auto fine = [&](const double* x, double* y) {
        Eigen::Map<Eigen::VectorXd>(y, t.A.rows()) = t.A * Eigen::Map<const Eigen::VectorXd>(x, t.A.rows());
    };
    Eigen::VectorXd r(t.A.rows()), z0(t.A.rows()), z(t.A.rows());
    for (Eigen::Index i = 0; i < r.size(); ++i) r[i] = sys.free_dof[std::size_t(i)] ? std::sin(1.0 + double(i)) : 0.0;
    for (const AmgSmoother kind : {AmgSmoother::L1Jacobi, AmgSmoother::Chebyshev}) {
        SCOPED_TRACE(kind == AmgSmoother::Chebyshev ? "Chebyshev" : "l1 block-Jacobi");
        const AmgSettings settings = smoother_settings(kind, 2, 100);
        SmoothedAggregation fresh, re, stale;
        fresh.build(t.A, t.X, sys.free_dof, settings);
        re.build(sys.A, sys.mesh.X, sys.free_dof, settings);
        re.release_build_data();
        stale.build(sys.A, sys.mesh.X, sys.free_dof, settings);
        EXPECT_TRUE(re.rebuild(t.A, t.X));
        stale.refresh(t.A);
        ASSERT_GE(fresh.levels(), 3);
        ASSERT_EQ(re.levels(), fresh.levels());
        for (int l = 0; l + 1 < fresh.levels(); ++l) {
            const SparseRows P = fresh.prolongator(l);
            ASSERT_EQ(re.prolongator(l).rows(), P.rows());
            ASSERT_EQ(re.prolongator(l).cols(), P.cols());
            EXPECT_LT(max_difference(re.prolongator(l), P), 1e-6) << "level " << l;
            EXPECT_GT(max_difference(stale.prolongator(l), P), 0.1) << "level " << l;
            if (l == 0) continue;
            EXPECT_LT(max_difference(re.matrix(l), fresh.matrix(l)), 1e-6) << "level " << l;
            EXPECT_GT(max_difference(stale.matrix(l), fresh.matrix(l)), 0.1) << "level " << l;
        }
        fresh.apply(r.data(), z0.data(), fine);
        re.apply(r.data(), z.data(), fine);
        double dz2 = 0, z02 = 0;  // a plain loop: Eigen's AVX-512 norm here trips GCC 12's -Wmaybe-uninitialized
        for (Eigen::Index i = 0; i < z.size(); ++i) {
            dz2 += (z[i] - z0[i]) * (z[i] - z0[i]);
            z02 += z0[i] * z0[i];
        }
        EXPECT_LT(std::sqrt(dz2), 1e-5 * std::sqrt(z02));
        EXPECT_EQ(re.cycle_cost(), fresh.cycle_cost());
    }
}

// rebuild() is one thread's fixed order, the V-cycle's passes bitwise the
// serial ones: on 2 threads (P grouped by columns) the rebuilt hierarchy's
// V-cycle, prolongators and coarse operators are the serial bits, and a
// second rebuild on the same input gives them again.
TEST(SmoothedAggregation, RebuildGivesTheSameBitsOnAnyThreadCount) {
    const BoxSystem sys = box_system(16, 8, 8, 10);
    const Turned t = turned(sys, 1.1);
    const auto fine = [&](const double* x, double* y) {
        Eigen::Map<Eigen::VectorXd>(y, t.A.rows()) = t.A * Eigen::Map<const Eigen::VectorXd>(x, t.A.rows());
    };
    Eigen::VectorXd r(t.A.rows());
    for (Eigen::Index i = 0; i < r.size(); ++i) r[i] = sys.free_dof[std::size_t(i)] ? std::cos(0.3 * double(i)) : 0.0;
    const auto same = [](const SparseRows& a, const SparseRows& b) {
        return a.nonZeros() == b.nonZeros() && a.rows() == b.rows() &&
               std::memcmp(a.valuePtr(), b.valuePtr(), sizeof(double) * std::size_t(a.nonZeros())) == 0 &&
               std::memcmp(a.innerIndexPtr(), b.innerIndexPtr(), sizeof(int) * std::size_t(a.nonZeros())) == 0;
    };
    SmoothedAggregation serial, par;
    par.set_executor(make_executor(ExecutorKind::Pool, 2));
    for (SmoothedAggregation* sa : {&serial, &par}) {
        sa->build(sys.A, sys.mesh.X, sys.free_dof, smoother_settings(AmgSmoother::Chebyshev, 2, 100));
        sa->release_build_data();
        sa->rebuild(t.A, t.X);
    }
    Eigen::VectorXd z0(r.size()), z(r.size());
    serial.apply(r.data(), z0.data(), fine);
    for (int again = 0; again < 2; ++again) {
        SCOPED_TRACE(again ? "rebuilt twice" : "rebuilt once");
        par.apply(r.data(), z.data(), fine);
        EXPECT_EQ(0, std::memcmp(z.data(), z0.data(), sizeof(double) * std::size_t(z.size())));
        for (int l = 0; l + 1 < serial.levels(); ++l) {
            EXPECT_TRUE(same(par.prolongator(l), serial.prolongator(l))) << "level " << l;
            if (l > 0) {
                EXPECT_TRUE(same(par.matrix(l), serial.matrix(l))) << "level " << l;
            }
        }
        par.rebuild(t.A, t.X);
    }
}

// rebuild() before build(), with positions of another size, or with a
// matrix of another pattern (an entry more, or another size) is an error
// that names it, and leaves the hierarchy as it was.
TEST(SmoothedAggregation, RebuildOnAnotherPatternOrPositionsIsAnError) {
    const BoxSystem sys = box_system(8, 4, 4, 5);
    const auto fails = [](const std::function<void()>& f, const std::string& what) {
        try {
            f();
            ADD_FAILURE() << "no error for " << what;
        } catch (const InvalidArgument& e) {
            EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
        }
    };
    SmoothedAggregation sa;
    fails([&] { sa.rebuild(sys.A, sys.mesh.X); }, "build() first");
    sa.build(sys.A, sys.mesh.X, sys.free_dof, smoother_settings(AmgSmoother::Chebyshev, 2, 100));
    const SparseRows P = sa.prolongator(0);
    std::vector<double> X = sys.mesh.X;
    X.pop_back();
    fails([&] { sa.rebuild(sys.A, X); }, "positions has " + std::to_string(X.size()) + " coordinates");
    SparseRows wider = sys.A;
    const Eigen::Index n = wider.rows();
    wider.coeffRef(n - 1, 0) = wider.coeffRef(0, n - 1) = 1e-3;  // the box's far corners: no edge
    ASSERT_GT(wider.nonZeros(), sys.A.nonZeros());
    fails([&] { sa.rebuild(wider, sys.mesh.X); }, "A's pattern");
    const BoxSystem other = box_system(8, 4, 5, 5);
    fails([&] { sa.rebuild(other.A, other.mesh.X); }, "coordinates");
    std::vector<double> Xo = other.mesh.X;
    Xo.resize(sys.mesh.X.size());
    fails([&] { sa.rebuild(other.A, Xo); }, "A's pattern");
    EXPECT_EQ(max_difference(sa.prolongator(0), P), 0);
    EXPECT_TRUE(sa.rebuild(sys.A, sys.mesh.X));
}

// Each prolongator is its tentative one smoothed by its level's operator A_l:
// P = (I - f D^-1 A_l) P_tent, D the 3x3 (coarser: 6x6) diagonal blocks of
// A_l, one f > 0 per level (w / rho, rho the power iteration's estimate of
// D^-1 A_l's largest eigenvalue). Checked as D (P_tent - P) = f A_l P_tent
// with Eigen's sparse products (the formula in another form than the row
// by row one that builds P), with each smoother, within the float rounding
// of the stored P and A_l.
TEST(SmoothedAggregation, ProlongatorsAreTheTentativeOnesSmoothed) {
    const BoxSystem sys = box_system(16, 8, 8, 10);
    for (const AmgSmoother kind : {AmgSmoother::Chebyshev, AmgSmoother::L1Jacobi}) {
        SCOPED_TRACE(kind == AmgSmoother::Chebyshev ? "Chebyshev" : "l1-Jacobi");
        SmoothedAggregation amg;
        amg.build(sys.A, sys.mesh.X, sys.free_dof, smoother_settings(kind, 2, 100));
        ASSERT_GE(amg.levels(), 3);
        SparseRows Al = sys.A;
        for (int l = 0; l + 1 < amg.levels(); ++l) {
            const Eigen::Index bs = l == 0 ? 3 : 6;
            std::vector<Eigen::Triplet<double>> t;
            for (Eigen::Index k = 0; k < Al.outerSize(); ++k)
                for (SparseRows::InnerIterator it(Al, k); it; ++it)
                    if (it.row() / bs == it.col() / bs) t.emplace_back(int(it.row()), int(it.col()), it.value());
            SparseRows D(Al.rows(), Al.cols());
            D.setFromTriplets(t.begin(), t.end());
            const SparseRows Pt = amg.tentative(l), P = amg.prolongator(l);
            const SparseRows X = D * SparseRows(Pt - P), Y = Al * Pt;
            const double f = X.cwiseProduct(Y).sum() / Y.squaredNorm();
            EXPECT_GT(f, 0) << "level " << l;
            EXPECT_LT(SparseRows(X - f * Y).norm(), 1e-5 * X.norm()) << "level " << l;
            if (l + 2 < amg.levels()) Al = amg.matrix(l + 1);
        }
    }
}

TEST(SmoothedAggregation, VCycleIsSymmetricAndPositiveWithEachSmoother) {
    const BoxSystem sys = box_system(12, 6, 6, 10);
    const SparseRows& A = sys.A;
    const auto fine = [&](const double* x, double* y) {
        Eigen::Map<Eigen::VectorXd>(y, A.rows()) = A * Eigen::Map<const Eigen::VectorXd>(x, A.rows());
    };
    Eigen::VectorXd r1(A.rows()), r2(A.rows()), z1(A.rows()), z2(A.rows());
    for (Eigen::Index i = 0; i < A.rows(); ++i) {
        r1[i] = sys.free_dof[std::size_t(i)] ? std::sin(1.0 + double(i)) : 0.0;
        r2[i] = sys.free_dof[std::size_t(i)] ? std::cos(0.7 * double(i)) : 0.0;
    }
    // dense_coarsest 0: three levels or more; the default: the dense level 1
    // is the coarsest (its float LDL^T the coarse solve)
    for (const double dense : {0.0, AmgSettings{}.dense_coarsest})
    for (const AmgSmoother kind : {AmgSmoother::L1Jacobi, AmgSmoother::Chebyshev})
        for (int steps : {1, 2, 3}) {
            SCOPED_TRACE((kind == AmgSmoother::Chebyshev ? "Chebyshev degree " : "l1 sweeps ") + std::to_string(steps) +
                         ", dense_coarsest " + std::to_string(dense));
            SmoothedAggregation amg;
            amg.build(A, sys.mesh.X, sys.free_dof, smoother_settings(kind, steps, 100, dense));
            if (dense == 0) ASSERT_GE(amg.levels(), 3);
            else ASSERT_EQ(amg.levels(), 2);
            amg.apply(r1.data(), z1.data(), fine);
            amg.apply(r2.data(), z2.data(), fine);
            // <r2, M r1> = <r1, M r2> to round-off: PCG's preconditioner must be symmetric.
            EXPECT_NEAR(dot(r2, z1), dot(r1, z2), 1e-12 * std::sqrt(dot(r1, z1) * dot(r2, z2)));
            EXPECT_GT(dot(r1, z1), 0);
            EXPECT_GT(dot(r2, z2), 0);
        }
}

// The coarsest level's dense LDL^T pivots, so an indefinite operator (a
// StVK tangent under compression makes A = M + dt^2 K indefinite) factors
// too: A shifted by minus its mean diagonal, refreshed into the hierarchy
// built for A, still gives a finite, symmetric V-cycle, and its coarsest
// solve is exact to float rounding: with the smoothers' contributions
// removed (one level: the coarsest is the finest), M A x = x.
TEST(SmoothedAggregation, AnIndefiniteOperatorFactorsAtTheCoarsestLevel) {
    const BoxSystem sys = box_system(6, 3, 3, 4);
    SparseRows A = sys.A;
    double mean = 0;
    int live = 0;
    for (Eigen::Index i = 0; i < A.rows(); ++i)
        if (sys.free_dof[std::size_t(i)]) {
            mean += A.coeff(i, i);
            ++live;
        }
    mean /= live;
    for (Eigen::Index i = 0; i < A.rows(); ++i)
        if (sys.free_dof[std::size_t(i)]) A.coeffRef(i, i) -= mean;
    const auto fine = [&](const double* x, double* y) {
        Eigen::Map<Eigen::VectorXd>(y, A.rows()) = A * Eigen::Map<const Eigen::VectorXd>(x, A.rows());
    };
    Eigen::VectorXd x(A.rows());
    for (Eigen::Index i = 0; i < A.rows(); ++i) x[i] = sys.free_dof[std::size_t(i)] ? std::sin(0.3 + double(i)) : 0.0;
    const Eigen::VectorXd b = A * x;
    // one level (max_coarse_dofs above the system's size): the V-cycle is the coarsest solve
    SmoothedAggregation direct;
    AmgSettings one;
    one.max_coarse_dofs = int(A.rows());
    direct.build(sys.A, sys.mesh.X, sys.free_dof, one);
    ASSERT_EQ(direct.levels(), 1);
    direct.refresh(A);
    Eigen::VectorXd z(A.rows());
    direct.apply(b.data(), z.data(), fine);
    double err = 0, ref = 0;
    for (Eigen::Index i = 0; i < A.rows(); ++i)
        if (sys.free_dof[std::size_t(i)]) {
            err = std::max(err, std::abs(z[i] - x[i]));
            ref = std::max(ref, std::abs(x[i]));
        }
    EXPECT_LT(err, 1e-3 * ref);  // float-rounded factor of an indefinite matrix
    // several levels, the coarsest a dense coarse operator: finite and symmetric
    SmoothedAggregation amg;
    amg.build(sys.A, sys.mesh.X, sys.free_dof, smoother_settings(AmgSmoother::Chebyshev, 2, 20, 0.25));
    ASSERT_GE(amg.levels(), 2);
    amg.refresh(A);
    Eigen::VectorXd r2(A.rows()), z1(A.rows()), z2(A.rows());
    for (Eigen::Index i = 0; i < A.rows(); ++i) r2[i] = sys.free_dof[std::size_t(i)] ? std::cos(0.7 * double(i)) : 0.0;
    amg.apply(b.data(), z1.data(), fine);
    amg.apply(r2.data(), z2.data(), fine);
    for (Eigen::Index i = 0; i < A.rows(); ++i) ASSERT_TRUE(std::isfinite(z1[i]) && std::isfinite(z2[i]));
    EXPECT_NEAR(dot(r2, z1), dot(b, z2), 1e-10 * std::sqrt(dot(b, b) * dot(z2, z2) + dot(r2, r2) * dot(z1, z1)));
}

// The coarsest solve goes through its factor in blocks of 8 rows and
// columns: at sizes that are not a multiple of 8 (54, 81, 180, 189, 378
// dofs: remainders 6, 1, 4, 5, 2), for a definite operator (Cholesky) and an
// indefinite one (the pivoted LDL^T, whose permutation the solve applies),
// its residual is the float factor's rounding (backward error |b - A z| /
// (|A| |z|), max norms: below 1e-6 definite, 5-9e-9 measured; below 1e-4
// indefinite, 1e-7 - 2.6e-5 measured, the pivoted factor's growth), and
// the definite solutions are within 1e-5 of x (1-2e-7 measured; the
// indefinite ones are as far as their conditioning makes them). One
// level: the V-cycle is the coarsest solve.
TEST(SmoothedAggregation, CoarsestSolveIsExactAtEverySize) {
    for (const auto& [nx, ny, nz] : std::vector<std::array<index_t, 3>>{{2, 2, 1}, {2, 2, 2}, {4, 3, 2}, {6, 2, 2}, {6, 5, 2}})
        for (const bool indefinite : {false, true}) {
            const BoxSystem sys = box_system(nx, ny, nz, 2);
            SparseRows A = sys.A;
            const Eigen::Index n = A.rows();
            SCOPED_TRACE(std::to_string(n) + (indefinite ? " dofs, indefinite" : " dofs, definite"));
            if (indefinite) {
                double mean = 0;
                for (Eigen::Index i = 0; i < n; ++i) mean += A.coeff(i, i);
                for (Eigen::Index i = 0; i < n; ++i)
                    if (sys.free_dof[std::size_t(i)]) A.coeffRef(i, i) -= mean / double(n);
            }
            SmoothedAggregation direct;
            AmgSettings one;
            one.max_coarse_dofs = int(n);
            direct.build(A, sys.mesh.X, sys.free_dof, one);
            ASSERT_EQ(direct.levels(), 1);
            ASSERT_EQ(direct.coarsest_indefinite(), indefinite);
            Eigen::VectorXd x(n);
            for (Eigen::Index i = 0; i < n; ++i) x[i] = sys.free_dof[std::size_t(i)] ? std::sin(0.3 + double(i)) : 0.0;
            const Eigen::VectorXd b = A * x;
            Eigen::VectorXd z(n);
            direct.apply(b.data(), z.data(), [&](const double* in, double* out) {
                Eigen::Map<Eigen::VectorXd>(out, n) = A * Eigen::Map<const Eigen::VectorXd>(in, n);
            });
            // max norms in plain loops (Eigen's dense reductions trip g++ 12's
            // false -Wmaybe-uninitialized with AVX-512, GCC PR 105593)
            const Eigen::VectorXd r = b - A * z;
            double norm_a = 0, res = 0, zmax = 0, xmax = 0, diff = 0;
            for (Eigen::Index i = 0; i < n; ++i) {
                double row = 0;
                for (SparseRows::InnerIterator it(A, i); it; ++it) row += std::abs(it.value());
                norm_a = std::max(norm_a, row);
                res = std::max(res, std::abs(r[i]));
                zmax = std::max(zmax, std::abs(z[i]));
                xmax = std::max(xmax, std::abs(x[i]));
                diff = std::max(diff, std::abs(z[i] - x[i]));
            }
            EXPECT_LT(res / (norm_a * zmax), indefinite ? 1e-4 : 1e-6);
            if (!indefinite) {
                EXPECT_LT(diff, 1e-5 * xmax);
            }
        }
}

// A refresh forms each coarse operator numerically, into a block pattern
// kept from the first refresh (amg/galerkin_product.*): it is P^T A P of the
// level above as Eigen's sparse product gives it, to the float rounding it
// is stored in; after a refresh with other values on the same pattern, and
// with an operator of a wider pattern (the pattern is found again).
TEST(SmoothedAggregation, RefreshFormsTheGalerkinOperators) {
    const BoxSystem sys = box_system(16, 8, 8, 10);
    SmoothedAggregation amg;
    amg.build(sys.A, sys.mesh.X, sys.free_dof, smoother_settings(AmgSmoother::Chebyshev, 2, 100));
    ASSERT_GE(amg.levels(), 3);
    const auto check = [&](const SparseRows& A, const char* what) {
        SCOPED_TRACE(what);
        amg.refresh(A);
        SparseRows above = A;
        for (int l = 1; l + 1 < amg.levels(); ++l) {
            const SparseRows P = amg.prolongator(l - 1);
            const SparseRows ref = SparseRows(P.transpose()) * above * P;
            const SparseRows got = amg.matrix(l);
            ASSERT_EQ(got.rows(), ref.rows());
            EXPECT_LT(SparseRows(got - ref).norm(), 1e-6 * ref.norm()) << "level " << l;
            above = ref;
        }
    };
    check(sys.A, "the built operator");
    SparseRows B = 0.7 * sys.A;
    for (Eigen::Index i = 0; i < B.rows(); ++i)
        if (sys.free_dof[std::size_t(i)]) B.coeffRef(i, i) *= 1.5;
    check(B, "other values, the same pattern");
    std::vector<Eigen::Triplet<double>> far;
    const Eigen::Index n = B.rows(), step = 3 * 40;  // a vertex 40 on: no neighbour
    for (Eigen::Index i = 0; i + step < n; i += 3)
        if (sys.free_dof[std::size_t(i)] && sys.free_dof[std::size_t(i + step)]) {
            const double c = 1e-3 * B.coeff(i, i);
            far.emplace_back(i, i + step, c);
            far.emplace_back(i + step, i, c);
        }
    SparseRows wide(n, n);
    wide.setFromTriplets(far.begin(), far.end());
    check(SparseRows(B + wide), "a wider pattern");
}

// A share of nonzeros outside [0, 1] (or NaN) for dense_coarsest is an
// error that names it, before anything is built.
TEST(SmoothedAggregation, DenseCoarsestOutsideZeroToOneIsAnError) {
    const BoxSystem sys = box_system(4, 2, 2, 2);
    for (const double bad : {-0.1, 1.5, std::nan("")}) {
        AmgSettings settings;
        settings.dense_coarsest = bad;
        SmoothedAggregation amg;
        try {
            amg.build(sys.A, sys.mesh.X, sys.free_dof, settings);
            ADD_FAILURE() << "no error for " << bad;
        } catch (const InvalidArgument& e) {
            EXPECT_NE(std::string(e.what()).find("dense_coarsest in [0, 1]"), std::string::npos) << e.what();
        }
    }
}

// On an executor's threads the V-cycle and a smoother application give
// bitwise what they give serially (every pass splits into fixed blocks; P
// grouped by columns instead of rows adds each coarse entry's terms in the
// order of the serial restriction's scatter, and its prolongation's scatter
// each fine entry's in the serial gather's: amg/block_rows.hpp), for 2 and 3
// threads and an executor set before or after build(); and hold no more
// memory.
TEST(SmoothedAggregation, ThreadsGiveTheSerialBits) {
    const BoxSystem sys = box_system(16, 8, 8, 10);
    const SparseRows& A = sys.A;
    const auto fine = [&](const double* x, double* y) {
        Eigen::Map<Eigen::VectorXd>(y, A.rows()) = A * Eigen::Map<const Eigen::VectorXd>(x, A.rows());
    };
    Eigen::VectorXd r(A.rows());
    for (Eigen::Index i = 0; i < A.rows(); ++i) r[i] = sys.free_dof[std::size_t(i)] ? std::sin(1.0 + double(i)) : 0.0;
    for (const AmgSmoother kind : {AmgSmoother::L1Jacobi, AmgSmoother::Chebyshev}) {
        SmoothedAggregation serial;
        serial.build(A, sys.mesh.X, sys.free_dof, smoother_settings(kind, 2, 100));
        ASSERT_GE(serial.levels(), 3);
        Eigen::VectorXd z0(A.rows()), s0 = Eigen::VectorXd::Zero(A.rows());
        serial.apply(r.data(), z0.data(), fine);
        serial.smooth(0, r.data(), s0.data(), fine);
        for (const auto& [kind_name, threads] : {std::pair{"pool", 2}, std::pair{"pool", 3}, std::pair{"omp", 3}})
            for (bool before : {true, false}) {
                SCOPED_TRACE(std::string(kind_name) + " x" + std::to_string(threads) + (before ? " set before build" : " set after"));
                SmoothedAggregation par;
                const auto ex = make_executor(parse_executor_kind(kind_name), threads);
                if (before) par.set_executor(ex);
                par.build(A, sys.mesh.X, sys.free_dof, smoother_settings(kind, 2, 100));
                if (!before) par.set_executor(ex);
                Eigen::VectorXd z(A.rows()), sm = Eigen::VectorXd::Zero(A.rows());
                par.apply(r.data(), z.data(), fine);
                par.smooth(0, r.data(), sm.data(), fine);
                EXPECT_EQ(0, std::memcmp(z.data(), z0.data(), sizeof(double) * std::size_t(z.size())));
                EXPECT_EQ(0, std::memcmp(sm.data(), s0.data(), sizeof(double) * std::size_t(sm.size())));
                EXPECT_LE(par.bytes(), serial.bytes());  // P regrouped, not held twice
            }
    }
}

// cycle_cost (the auto preconditioner's count of a V-cycle's work) from the
// hierarchy's matrices as the accessors give them: the finest level's
// 2 x smoothing_steps products, and over the finest matrix's entries on and
// above the diagonal, each coarser non-coarsest level's products, the
// restriction and prolongation through each P and the two triangular solves
// with the dense coarsest factor. The same whichever way P is held (P with
// one thread, grouped by columns with more).
TEST(SmoothedAggregation, CycleCostCountsTheHierarchysEntries) {
    const BoxSystem sys = box_system(16, 8, 8, 10);
    const SparseRows& A = sys.A;
    for (const int steps : {1, 2, 3}) {
        SCOPED_TRACE(std::to_string(steps) + " smoothing steps");
        SmoothedAggregation sa;
        sa.build(A, sys.mesh.X, sys.free_dof, smoother_settings(AmgSmoother::Chebyshev, steps, 100));
        ASSERT_GE(sa.levels(), 3);
        const int last = sa.levels() - 1;
        double coarse = double(sa.dofs(last)) * double(sa.dofs(last));
        for (int l = 0; l < last; ++l) {
            coarse += 2.0 * double(sa.prolongator(l).nonZeros());
            if (l > 0) coarse += 2.0 * steps * double(sa.matrix(l).nonZeros());
        }
        index_t free = 0;
        for (const auto f : sys.free_dof) free += f;
        const double fine = 0.5 * (double(A.nonZeros()) + 3.0 * double(free));
        const double expected = 2.0 * steps + coarse / fine;
        // Within 10 %: the expanded matrices drop the zeros inside blocks,
        // which the block storage keeps (and reads).
        EXPECT_GE(sa.cycle_cost(), 0.999 * expected);
        EXPECT_LE(sa.cycle_cost(), 1.1 * expected);
        SmoothedAggregation par;
        par.set_executor(make_executor(ExecutorKind::Pool, 2));
        par.build(A, sys.mesh.X, sys.free_dof, smoother_settings(AmgSmoother::Chebyshev, steps, 100));
        EXPECT_EQ(par.cycle_cost(), sa.cycle_cost());
    }
}

// The Chebyshev smoother's error propagation E = I - S A is the polynomial
// q(D^-1 A) = T_m((beta + alpha - 2 lambda) / (beta - alpha)) / T_m(sigma),
// sigma = (beta + alpha) / (beta - alpha) = (ratio + 1) / (ratio - 1): on
// the upper end of the spectrum (the error's high-frequency part, which the
// coarse levels cannot see) it damps by 1 / T_m(sigma) at least, and it
// never increases the error's energy norm.
TEST(SmoothedAggregation, ChebyshevSmootherDampsTheHighFrequencyErrorByItsBound) {
    const BoxSystem sys = box_system(10, 5, 5, 6);
    const SparseRows& A = sys.A;
    const Eigen::Index n = A.rows();
    const auto fine = [&](const double* x, double* y) {
        Eigen::Map<Eigen::VectorXd>(y, n) = A * Eigen::Map<const Eigen::VectorXd>(x, n);
    };
    // D^-1 A's top eigenvector by power iteration (the test's own, 400
    // steps), D the 3x3 diagonal blocks (identity on fixed dofs).
    std::vector<Eigen::Matrix3d> Dinv(std::size_t(n / 3));
    for (Eigen::Index v = 0; v < n / 3; ++v) {
        Eigen::Matrix3d D;
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c) {
                const bool live = sys.free_dof[std::size_t(3 * v + r)] && sys.free_dof[std::size_t(3 * v + c)];
                D(r, c) = live ? A.coeff(3 * v + r, 3 * v + c) : double(r == c);
            }
        Dinv[std::size_t(v)] = D.inverse();
    }
    Eigen::VectorXd top(n), Ax(n);
    for (Eigen::Index i = 0; i < n; ++i) top[i] = sys.free_dof[std::size_t(i)] ? std::sin(3.0 * double(i) + 0.3) : 0.0;
    for (int k = 0; k < 400; ++k) {
        Ax = A * top;
        for (Eigen::Index v = 0; v < n / 3; ++v) top.segment<3>(3 * v) = Dinv[std::size_t(v)] * Ax.segment<3>(3 * v);
        top /= std::sqrt(dot(top, top));
    }
    const auto energy = [&](const Eigen::VectorXd& e) { return std::sqrt(dot(e, A * e)); };
    // E e: the smoother on A x = A e from x = 0.
    const auto propagate = [&](const SmoothedAggregation& amg, const Eigen::VectorXd& e) {
        const Eigen::VectorXd b = A * e;
        Eigen::VectorXd x = Eigen::VectorXd::Zero(n);
        amg.smooth(0, b.data(), x.data(), fine);
        return Eigen::VectorXd(e - x);
    };
    Eigen::VectorXd rough(n);
    for (Eigen::Index i = 0; i < n; ++i) rough[i] = sys.free_dof[std::size_t(i)] ? std::sin(12.9898 * double(i)) : 0.0;
    for (int degree : {2, 3}) {
        SCOPED_TRACE("degree " + std::to_string(degree));
        AmgSettings set = smoother_settings(AmgSmoother::Chebyshev, degree, 60);
        SmoothedAggregation amg;
        amg.build(A, sys.mesh.X, sys.free_dof, set);
        ASSERT_GE(amg.levels(), 2);
        const double sigma = (set.chebyshev_ratio + 1) / (set.chebyshev_ratio - 1);
        const double t = degree == 2 ? 2 * sigma * sigma - 1 : 4 * sigma * sigma * sigma - 3 * sigma;  // T_m(sigma)
        EXPECT_LE(energy(propagate(amg, top)), (1 / t) * energy(top) * 1.001);
        EXPECT_LT(energy(propagate(amg, rough)), energy(rough));
        // Also the l1 block-Jacobi sweeps never increase the energy norm.
        SmoothedAggregation l1;
        l1.build(A, sys.mesh.X, sys.free_dof, smoother_settings(AmgSmoother::L1Jacobi, degree, 60));
        EXPECT_LT(energy(propagate(l1, top)), energy(top));
        EXPECT_LT(energy(propagate(l1, rough)), energy(rough));
    }
}

namespace {

// Displacement after `steps` steps of `scene` with the given solver.
std::vector<double> displacement_after(Scene s, LinearSolver ls, PreconditionerKind pc, int steps, int* iterations) {
    s.solver.linear_solver = ls;
    s.solver.preconditioner = pc;
    s.solver.cg_tolerance = 1e-12;
    s.solver.cg_max_iterations = 20000;
    Simulator<double> sim(std::move(s));
    int its = 0;
    for (int k = 0; k < steps; ++k) its += sim.step().solver_iterations;
    if (iterations) *iterations = its;
    const auto u = sim.displacement();
    return {u.begin(), u.end()};
}

void expect_same_solutions(const Scene& s, int steps) {
    int its_bj = 0, its_amg = 0;
    const auto bj = displacement_after(s, LinearSolver::CG, PreconditionerKind::BlockJacobi, steps, &its_bj);
    const auto amg = displacement_after(s, LinearSolver::CG, PreconditionerKind::Amg, steps, &its_amg);
    const auto direct = displacement_after(s, LinearSolver::Direct, PreconditionerKind::BlockJacobi, steps, nullptr);
    EXPECT_LT(relative(amg, direct), 1e-8);
    EXPECT_LT(relative(bj, direct), 1e-8);
    EXPECT_LT(relative(amg, bj), 1e-8);
    EXPECT_LT(its_amg, its_bj);
}

}  // namespace

TEST(Solvers, AmgCgBlockJacobiCgAndDirectAgreeOnABox) {
    Scene s = test::clamped_box_scene(12, 4, 4, 1e5);
    s.dt = 4e-3;
    expect_same_solutions(s, 3);
}

TEST(Solvers, AmgCgBlockJacobiCgAndDirectAgreeOnASharedMesh) {
    const std::string prefix = test::shared_mesh_prefix("bunny-4k");
    if (prefix.empty()) GTEST_SKIP() << "no ../shared/meshes/bunny-4k";
    Scene s;
    s.mesh = read_mesh(prefix + ".node");
    s.materials = Material{1e5, 0.3, 1000};
    s.gravity = {0, 0, -9.81};
    // The lowest 1 % of the vertices (by z) fixed.
    std::vector<std::pair<double, index_t>> z;
    for (index_t v = 0; v < s.mesh.num_vertices(); ++v) z.emplace_back(s.mesh.X[3 * std::size_t(v) + 2], v);
    std::sort(z.begin(), z.end());
    for (std::size_t k = 0; k < z.size() / 100; ++k) s.fixed.push_back(z[k].second);
    s.dt = 4e-3;
    expect_same_solutions(s, 2);
}

TEST(Solvers, AmgNeedsFarFewerIterationsThanBlockJacobiAtALargeStep) {
    Scene s = test::clamped_box_scene(24, 6, 6, 1e6);
    s.dt = 10e-3;
    s.solver.cg_tolerance = 1e-6;
    s.solver.cg_max_iterations = 5000;
    int its[2] = {0, 0};
    for (int k = 0; k < 2; ++k) {
        s.solver.preconditioner = k ? PreconditionerKind::Amg : PreconditionerKind::BlockJacobi;
        Simulator<double> sim(s);
        for (int i = 0; i < 2; ++i) its[k] += sim.step().solver_iterations;
    }
    EXPECT_LT(4 * its[1], its[0]) << "block-Jacobi " << its[0] << ", AMG " << its[1];
}

namespace {

struct AutoRun {
    std::vector<double> u;
    std::vector<int> its;
};

AutoRun run_steps(Scene s, PreconditionerKind kind, int steps, int threshold = 200) {
    s.solver.preconditioner = kind;
    s.solver.auto_amg_iterations = threshold;
    Simulator<double> sim(std::move(s));
    AutoRun r;
    for (int k = 0; k < steps; ++k) r.its.push_back(sim.step().solver_iterations);
    r.u.assign(sim.displacement().begin(), sim.displacement().end());
    return r;
}

bool same_bits(const std::vector<double>& a, const std::vector<double>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), sizeof(double) * a.size()) == 0;
}

}  // namespace

// auto (the default): block-Jacobi, bitwise, while its solves stay within
// the threshold; the solve that goes past it goes on under AMG from its
// iterate, and AMG stays (far fewer iterations, the same solution to the
// solver's tolerance); never with a fixed budget.
TEST(Solvers, AutoPreconditionerSwitchesToAmgPastItsThreshold) {
    EXPECT_EQ(SolverSettings{}.preconditioner, PreconditionerKind::Auto);
    Scene s = test::clamped_box_scene(24, 6, 6, 1e6);
    s.dt = 10e-3;
    s.solver.cg_tolerance = 1e-10;
    s.solver.cg_max_iterations = 5000;
    const AutoRun bj = run_steps(s, PreconditionerKind::BlockJacobi, 4);
    const AutoRun amg = run_steps(s, PreconditionerKind::Amg, 4);
    ASSERT_GT(bj.its[0], 50);
    ASSERT_LT(2 * amg.its[0], bj.its[0]);
    // Within the threshold: block-Jacobi's bits.
    const AutoRun below = run_steps(s, PreconditionerKind::Auto, 4, 100000);
    EXPECT_TRUE(same_bits(below.u, bj.u));
    EXPECT_EQ(below.its, bj.its);
    // Past it in the first solve: its first `threshold` iterations are
    // block-Jacobi's, the rest (from that iterate) and every later solve AMG's.
    const int threshold = bj.its[0] / 2;
    const AutoRun past = run_steps(s, PreconditionerKind::Auto, 4, threshold);
    EXPECT_GT(past.its[0], threshold);
    EXPECT_LE(past.its[0], threshold + amg.its[0] + 2);
    EXPECT_LT(past.its[0], bj.its[0]);
    for (int k = 1; k < 4; ++k) {
        EXPECT_LE(past.its[std::size_t(k)], amg.its[std::size_t(k)] + 2) << "step " << k;
        EXPECT_LT(4 * past.its[std::size_t(k)], bj.its[std::size_t(k)]) << "step " << k;
    }
    double diff = 0, norm = 0;
    for (std::size_t i = 0; i < bj.u.size(); ++i) {
        diff += (past.u[i] - bj.u[i]) * (past.u[i] - bj.u[i]);
        norm += bj.u[i] * bj.u[i];
    }
    EXPECT_LT(std::sqrt(diff / norm), 1e-8);
    // A fixed CG budget keeps block-Jacobi whatever the threshold.
    s.solver.cg_fixed_iterations = 30;
    EXPECT_TRUE(same_bits(run_steps(s, PreconditionerKind::Auto, 3, 1).u, run_steps(s, PreconditionerKind::BlockJacobi, 3).u));
}

// A step too large for block-Jacobi within cg_max_iterations fails under
// block-Jacobi and succeeds under auto (at the default threshold), whose
// solve changes to AMG part way, to AMG's solution.
TEST(Solvers, AutoPreconditionerCompletesASolveBlockJacobiCannot) {
    Scene s = test::clamped_box_scene(24, 6, 6, 1e6);
    s.dt = 10e-3;
    s.solver.cg_tolerance = 1e-10;
    s.solver.cg_max_iterations = 100;
    EXPECT_THROW(run_steps(s, PreconditionerKind::BlockJacobi, 1), SimulationError);
    const AutoRun amg = run_steps(s, PreconditionerKind::Amg, 2);
    const AutoRun a = run_steps(s, PreconditionerKind::Auto, 2, SolverSettings{}.auto_amg_iterations);
    EXPECT_GT(a.its[0], SolverSettings{}.auto_amg_iterations);
    EXPECT_LE(a.its[0], 100);
    EXPECT_LE(a.its[1], amg.its[1] + 2);
    double diff = 0, norm = 0;
    for (std::size_t i = 0; i < amg.u.size(); ++i) {
        diff += (a.u[i] - amg.u[i]) * (a.u[i] - amg.u[i]);
        norm += amg.u[i] * amg.u[i];
    }
    EXPECT_LT(std::sqrt(diff / norm), 1e-8);
}

namespace {

// Each step's CG iterations and preconditioner refreshes, and the final
// displacement.
struct StepTrace {
    std::vector<int> its, refreshes;
    std::vector<double> u;
};

StepTrace trace_steps(Scene s, PreconditionerKind kind, int steps, std::shared_ptr<const Executor> ex = nullptr) {
    s.solver.preconditioner = kind;
    Simulator<double> sim(std::move(s), std::move(ex));
    StepTrace t;
    for (int k = 0; k < steps; ++k) {
        const StepStats st = sim.step();
        t.its.push_back(st.solver_iterations);
        t.refreshes.push_back(st.preconditioner_refreshes);
    }
    t.u.assign(sim.displacement().begin(), sim.displacement().end());
    return t;
}

int sum_from(const std::vector<int>& v, int first) { return std::accumulate(v.begin() + first, v.end(), 0); }

// A step's iterations within 20 % of another run's (block-Jacobi's, say).
bool within_a_fifth(int its, int reference) { return std::abs(its - reference) * 5 <= reference; }

}  // namespace

// Soft and long steps: K changes so much from step to step that the lagged
// AMG refreshes at nearly every step, and a refresh (counted as 350
// block-Jacobi iterations) costs more than a whole block-Jacobi solve
// (~200 here). auto goes back to block-Jacobi after the AMG solves that show
// it, tries the AMG once more after 8 set-ups (its cheapest solve cost less
// than block-Jacobi's), goes back again, and solves to the same tolerance:
// in 20 steps on block-Jacobi's iterations in at least 8, the last two
// among them, with at most 2/3 of the AMG's refreshes. Its switches are made
// on counts, so its bits are those of any thread count.
TEST(Solvers, AutoPreconditionerGoesBackWhereAmgRefreshesEveryStep) {
    Scene s = test::clamped_box_scene(24, 6, 6, 1e4);
    s.dt = 33e-3;
    s.solver.cg_tolerance = 1e-6;
    s.solver.cg_max_iterations = 5000;
    const int steps = 20;
    const StepTrace bj = trace_steps(s, PreconditionerKind::BlockJacobi, steps);
    const StepTrace amg = trace_steps(s, PreconditionerKind::Amg, steps);
    const StepTrace a = trace_steps(s, PreconditionerKind::Auto, steps);
    ASSERT_GT(*std::min_element(bj.its.begin(), bj.its.end()), SolverSettings{}.auto_amg_iterations);
    ASSERT_GE(3 * sum_from(amg.refreshes, 0), 2 * steps) << "the AMG refreshes at most steps";
    EXPECT_LE(3 * sum_from(a.refreshes, 0), 2 * sum_from(amg.refreshes, 0));
    const auto on_bj = [&](int k) {  // a step on block-Jacobi's iterations
        return within_a_fifth(a.its[std::size_t(k)], bj.its[std::size_t(k)]);
    };
    int steps_on_bj = 0;
    for (int k = 0; k < steps; ++k) steps_on_bj += on_bj(k);
    EXPECT_GE(steps_on_bj, 8);
    EXPECT_TRUE(on_bj(steps - 2) && on_bj(steps - 1));
    double diff = 0, norm = 0;
    for (std::size_t i = 0; i < bj.u.size(); ++i) {
        diff += (a.u[i] - bj.u[i]) * (a.u[i] - bj.u[i]);
        norm += bj.u[i] * bj.u[i];
    }
    EXPECT_LT(std::sqrt(diff / norm), 1e-4);
    const StepTrace threaded = trace_steps(s, PreconditionerKind::Auto, steps, make_executor(ExecutorKind::Pool, 2));
    EXPECT_EQ(threaded.its, a.its);
    EXPECT_EQ(threaded.refreshes, a.refreshes);
    EXPECT_TRUE(same_bits(threaded.u, a.u));
}

// auto goes back to block-Jacobi where the AMG's first solves cost more (the
// built-in beam at 1e4 Pa folding under 33 ms steps: the lagged AMG
// refreshes at nearly every one of its first 15 steps), then, block-Jacobi's
// wait over, tries the AMG again, on a hierarchy built on the folded beam,
// and keeps it: in the last 8 of 32 steps auto's iterations are the AMG's,
// a small fraction of block-Jacobi's (before, it stayed on block-Jacobi: 360
// iterations per step where the AMG takes 15-30).
TEST(Solvers, AutoPreconditionerTriesAmgAgainAfterTheEarlyTransient) {
    Scene s = default_scene();
    s.materials.fallback.young = 1e4;
    s.dt = 33e-3;
    s.solver.cg_max_iterations = 20000;
    const int steps = 32, last = steps - 8;
    const StepTrace bj = trace_steps(s, PreconditionerKind::BlockJacobi, steps);
    const StepTrace amg = trace_steps(s, PreconditionerKind::Amg, steps);
    const StepTrace a = trace_steps(s, PreconditionerKind::Auto, steps);
    ASSERT_GE(sum_from(amg.refreshes, 0) - sum_from(amg.refreshes, 15), 10) << "the AMG's early transient";
    int back = 0;  // steps of auto's first 15 on block-Jacobi's iterations
    for (int k = 1; k < 15; ++k) back += within_a_fifth(a.its[std::size_t(k)], bj.its[std::size_t(k)]);
    EXPECT_GE(back, 3) << "auto went back to block-Jacobi in the transient";
    EXPECT_LT(5 * sum_from(a.its, last), sum_from(bj.its, last));
    // Refreshed there instead of rebuilt, on the hierarchy of the beam as it
    // was in step 1, it took 192 iterations against the AMG's 137.
    EXPECT_LE(5 * sum_from(a.its, last), 6 * sum_from(amg.its, last) + 40)
        << "auto's AMG, rebuilt where it was tried again, as good as the AMG's own";
}

// Where even the AMG's cheapest solve costs more than a block-Jacobi one (a
// soft box at 4 ms steps: ~6 AMG iterations of ~8 block-Jacobi ones each
// against 18-28 block-Jacobi iterations), auto, taken to AMG by a threshold
// set below block-Jacobi's count, goes back as soon as two AMG solves show
// it and never tries the AMG again: no refresh after it, block-Jacobi's
// iterations to the end.
TEST(Solvers, AutoPreconditionerDoesNotTryAgainAnAmgThatCannotWin) {
    Scene s = test::clamped_box_scene(24, 6, 6, 1e4);
    s.dt = 4e-3;
    s.solver.auto_amg_iterations = 8;
    const int steps = 60;
    const StepTrace bj = trace_steps(s, PreconditionerKind::BlockJacobi, steps);
    const StepTrace a = trace_steps(s, PreconditionerKind::Auto, steps);
    const auto on_bj = [&](int k) { return within_a_fifth(a.its[std::size_t(k)], bj.its[std::size_t(k)]); };
    ASSERT_GT(*std::min_element(bj.its.begin(), bj.its.end()), 2 * s.solver.auto_amg_iterations);
    int first_back = 0;  // the first step on block-Jacobi's iterations after one on the AMG's
    for (int k = 1; k < steps && first_back == 0; ++k)
        if (on_bj(k) && 2 * a.its[std::size_t(k) - 1] < bj.its[std::size_t(k) - 1]) first_back = k;
    ASSERT_GT(first_back, 0) << "auto took the AMG and went back";
    // After the switch's solve and two more, which cost more than 1.25x
    // block-Jacobi's would (before: after five, the window's lenient test).
    EXPECT_LE(first_back, 3);
    EXPECT_EQ(sum_from(a.refreshes, first_back), 0);
    for (int k = first_back; k < steps; ++k) EXPECT_TRUE(on_bj(k)) << "step " << k + 1 << ": " << a.its[std::size_t(k)];
}

// auto's first AMG solve after its switch has no fresh solve of its own to
// judge staleness by (the switch solve went on from block-Jacobi's
// iterate), so a hierarchy already stale (a beam released from a bend: K
// changes much in one 2 ms step) used to run on: here 386 iterations, and
// 464 on the same beam of 2.5 mm cells. Past solver.auto_amg_iterations
// (60) it now refreshes part way and goes on from its iterate, as the
// lagged AMG does once it has a fresh count (bunny-50k at 1e4 Pa and 33 ms:
// auto 1.12x -> 0.94x the best, docs/solvers.md).
TEST(Solvers, AutoPreconditionerRefreshesAStaleFirstAmgSolve) {
    Scene s = test::clamped_box_scene(48, 3, 3, 1e6, 0.005);
    s.materials = Material{1e6, 0.45, 1000};
    s.gravity = {0, 0, 0};
    s.integrator = Integrator::GeneralizedAlphaLinear;
    s.dt = 2e-3;
    s.solver.cg_tolerance = 1e-2;
    // From the prediction alone: the warm start along the balance's
    // acceleration takes the first solve to 56 iterations, below the switch.
    s.solver.warm_start = false;
    test::bend_from_clamp(s, 1.0 / 6);  // the 24 cm beam's tip 4 cm up
    const StepTrace a = trace_steps(s, PreconditionerKind::Auto, 2);
    const int threshold = SolverSettings{}.auto_amg_iterations;
    ASSERT_GT(a.its[0], threshold) << "auto switched in the first solve";
    ASSERT_EQ(a.refreshes[0], 1);
    EXPECT_EQ(a.refreshes[1], 1) << "the stale AMG refreshed part way";
    EXPECT_LE(a.its[1], threshold + 20);
    // A hierarchy made for the A being solved is not refreshed part way,
    // whatever the count (the AMG alone, its limit set below its first
    // solve's iterations): it would only make the same operators again.
    s.solver.auto_amg_iterations = 3;
    const StepTrace amg = trace_steps(s, PreconditionerKind::Amg, 1);
    ASSERT_GT(amg.its[0], 3);
    EXPECT_EQ(amg.refreshes[0], 1) << "the build only";
}

// A lagged AMG whose hierarchy a large change of K made stale refreshes part
// way through the solve (past 3x + 10 the iterations after its last
// refresh) instead of running on: the built-in beam at 1e4 Pa and 33 ms
// steps, folding, took 728 and 4,022 iterations in such solves where a
// fresh hierarchy takes 10-30 (6,592 in the 24th step of this run before).
// Each step's iterations stay within 6x + 10 those of an AMG refreshed at
// every K (at most 90 against 15 measured), to the same solution.
TEST(Solvers, LaggedAmgRefreshesPartWayThroughAHopelessSolve) {
    Scene s = default_scene();
    s.materials.fallback.young = 1e4;
    s.dt = 33e-3;
    s.solver.cg_max_iterations = 20000;
    s.solver.preconditioner = PreconditionerKind::Amg;
    std::vector<int> its[2];
    std::vector<double> u[2];
    for (int k = 0; k < 2; ++k) {
        s.solver.amg_refresh_interval = k;  // 0 lagged, 1 every K
        Simulator<double> sim(s);
        for (int i = 0; i < 30; ++i) its[k].push_back(sim.step().solver_iterations);
        u[k].assign(sim.displacement().begin(), sim.displacement().end());
    }
    for (std::size_t i = 0; i < its[0].size(); ++i)
        EXPECT_LE(its[0][i], 6 * its[1][i] + 10) << "step " << i + 1;
    double diff = 0, norm = 0;
    for (std::size_t i = 0; i < u[0].size(); ++i) {
        diff += (u[0][i] - u[1][i]) * (u[0][i] - u[1][i]);
        norm += u[1][i] * u[1][i];
    }
    EXPECT_LT(std::sqrt(diff / norm), 1e-4);
}

// The AMG's hierarchy is built on the body's positions where it is set up:
// the rigid-body modes of a body turned a quarter turn from its rest shape
// are its rest modes turned too (about the rest shape they are no
// near-nullspace of its K). So CG under AMG needs as many iterations for a
// free box turned 90 degrees about z (u = R X - X, R exact in floating
// point) and bent by a velocity field as for the same box and velocity
// unturned (13); built on the rest positions it needed 32.
TEST(Solvers, AmgIterationsAreTheSameForABodyTurnedFromItsRestShape) {
    Scene s;
    s.mesh = make_box(12, 4, 4);
    s.materials = Material{1e6, 0.3, 1000};
    s.gravity = {0, 0, 0};
    s.dt = 10e-3;
    s.solver.cg_tolerance = 1e-8;
    s.solver.cg_max_iterations = 5000;
    const std::size_t n = s.mesh.X.size();
    std::vector<double> v(n);  // bending: v_z = x^2 (rest coordinates)
    for (std::size_t i = 0; i < n; i += 3) v[i + 2] = 100 * s.mesh.X[i] * s.mesh.X[i];
    int its[2][2] = {{0, 0}, {0, 0}};
    for (int turned = 0; turned < 2; ++turned) {
        Scene st = s;
        if (turned) {
            st.initial_displacement.assign(n, 0.0);
            st.initial_velocity.assign(n, 0.0);
            for (std::size_t i = 0; i < n; i += 3) {
                const double x = s.mesh.X[i], y = s.mesh.X[i + 1];
                st.initial_displacement[i] = -y - x;  // (x, y, z) -> (-y, x, z)
                st.initial_displacement[i + 1] = x - y;
                st.initial_velocity[i] = -v[i + 1];
                st.initial_velocity[i + 1] = v[i];
                st.initial_velocity[i + 2] = v[i + 2];
            }
        } else {
            st.initial_velocity = v;
        }
        for (int k = 0; k < 2; ++k) {
            st.solver.preconditioner = k ? PreconditionerKind::Amg : PreconditionerKind::BlockJacobi;
            Simulator<double> sim(st);
            its[turned][k] = sim.step().solver_iterations;
        }
    }
    ASSERT_GT(its[0][0], 3 * its[0][1]) << "AMG must matter here";
    EXPECT_LE(std::abs(its[1][0] - its[0][0]), 2) << "block-Jacobi, turned against not";
    EXPECT_LE(std::abs(its[1][1] - its[0][1]), 1) << "AMG, turned " << its[1][1] << " against not " << its[0][1];
}

TEST(Solvers, DirectSolverAnalysesThePatternOnce) {
    for (const Integrator in : {Integrator::SemiImplicit, Integrator::Implicit}) {
        Scene s = test::cantilever_scene(in, 2e-3);
        s.solver.linear_solver = LinearSolver::Direct;
        Simulator<double> sim(std::move(s));
        int analyses = 0, newton = 0;
        for (int k = 0; k < 5; ++k) {
            const StepStats st = sim.step();
            analyses += st.symbolic_analyses;
            newton += st.newton_iterations;
            if (k == 0) {
                EXPECT_EQ(st.symbolic_analyses, 1);
            }
        }
        EXPECT_EQ(analyses, 1) << to_string(in);
        if (in == Integrator::Implicit) {
            EXPECT_GT(newton, 5);
        }
    }
}

TEST(Solvers, PreconditionerNamesAreCheckedAndNamed) {
    EXPECT_EQ(parse_preconditioner("amg"), PreconditionerKind::Amg);
    EXPECT_EQ(parse_preconditioner("auto"), PreconditionerKind::Auto);
    EXPECT_EQ(parse_preconditioner("block-jacobi"), PreconditionerKind::BlockJacobi);
    try {
        parse_preconditioner("jacobi");
        FAIL() << "no error";
    } catch (const InvalidArgument& e) {
        EXPECT_NE(std::string(e.what()).find("solver.preconditioner"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("\"jacobi\""), std::string::npos) << e.what();
    }
    const SceneFile ok = parse_scene(R"({"mesh": "box:2x2x2", "solver": {"preconditioner": "amg"}})", "", "scene.json");
    EXPECT_EQ(ok.scene.solver.preconditioner, PreconditionerKind::Amg);
    try {
        parse_scene(R"({"mesh": "box:2x2x2", "solver": {"preconditioner": "ilu"}})", "", "scene.json");
        FAIL() << "no error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("solver.preconditioner"), std::string::npos) << e.what();
    }
    Scene s = test::cantilever_scene();
    s.solver.preconditioner = static_cast<PreconditionerKind>(7);
    try {
        s.validate();
        FAIL() << "no error";
    } catch (const InvalidArgument& e) {
        EXPECT_NE(std::string(e.what()).find("solver.preconditioner"), std::string::npos) << e.what();
    }
    s.solver.preconditioner = PreconditionerKind::Auto;
    s.solver.auto_amg_iterations = 0;
    try {
        s.validate();
        FAIL() << "no error";
    } catch (const InvalidArgument& e) {
        EXPECT_NE(std::string(e.what()).find("solver.auto_amg_iterations"), std::string::npos) << e.what();
    }
    const SceneFile a = parse_scene(R"({"mesh": "box:2x2x2", "solver": {"preconditioner": "auto", "auto_amg_iterations": 50}})",
                                    "", "scene.json");
    EXPECT_EQ(a.scene.solver.auto_amg_iterations, 50);
    EXPECT_THROW(parse_scene(R"({"mesh": "box:2x2x2", "solver": {"auto_amg_iterations": 0}})", "", "scene.json"), Error);
}

// The lagged AMG under Newton: Newton's solves ask for different
// tolerances from one iteration to the next (its forcing term), so a raw
// iteration count after a refresh says nothing about the next solve's. The
// staleness test is per decade of residual reduction: a trapezoidal
// Newton run refreshes a few times, not at nearly every Newton iteration
// (it did: 2.0 of 2.6 ms per step on this cantilever went to refreshes);
// refreshed at every K (interval 1) it refreshes once per K built.
TEST(Solvers, LaggedAmgUnderNewtonRefreshesRarely) {
    Scene s = test::clamped_box_scene(12, 3, 3, 2e5);
    s.integrator = Integrator::Newmark;
    s.dt = 5e-3;
    s.solver.preconditioner = PreconditionerKind::Amg;
    int refreshes[2] = {0, 0}, newton[2] = {0, 0};
    std::vector<double> u[2];
    for (int k = 0; k < 2; ++k) {
        s.solver.amg_refresh_interval = k;  // 0 lagged, 1 every K
        Simulator<double> sim(s);
        for (int i = 0; i < 20; ++i) {
            const StepStats st = sim.step();
            refreshes[k] += st.preconditioner_refreshes;
            newton[k] += st.newton_iterations;
        }
        u[k].assign(sim.displacement().begin(), sim.displacement().end());
    }
    EXPECT_EQ(refreshes[1], newton[1]);
    EXPECT_GE(newton[0], 40);
    EXPECT_LE(refreshes[0], 10) << newton[0] << " Newton iterations";
    double diff = 0, norm = 0;
    for (std::size_t i = 0; i < u[0].size(); ++i) {
        diff += (u[0][i] - u[1][i]) * (u[0][i] - u[1][i]);
        norm += u[1][i] * u[1][i];
    }
    EXPECT_LT(std::sqrt(diff / norm), 1e-8);  // Newton's tolerance, whatever the preconditioner
}

// A fixed refresh interval still refreshes where the system's coefficients
// change: BDF2's first step is a backward Euler one (c_m = 1 / T^2), its
// second has c_m 2.25x that. A smoother and coarse operators made for the
// first step's A are no preconditioner for the second's: its D^-1 A reaches
// past the Chebyshev bound and the V-cycle is indefinite (r.z < 0; a float
// model's CG stalled at 3e-4 for 2,000 iterations). Each of the first two
// steps refreshes once, and the second solve takes about the third's
// iterations (the third reuses the second's set-up: interval 3).
TEST(Solvers, FixedIntervalAmgRefreshesWhenTheStepSizeChanges) {
    Scene s = test::clamped_box_scene(12, 3, 3, 2e5);
    s.integrator = Integrator::Bdf2Linear;
    s.dt = 5e-3;
    s.solver.preconditioner = PreconditionerKind::Amg;
    s.solver.amg_refresh_interval = 3;
    s.solver.cg_tolerance = 1e-8;
    Simulator<double> sim(s);
    StepStats st[3];
    for (StepStats& x : st) x = sim.step();
    EXPECT_EQ(st[0].preconditioner_refreshes, 1);
    EXPECT_EQ(st[1].preconditioner_refreshes, 1) << "BDF2's c_m differs from the backward Euler step's";
    EXPECT_EQ(st[2].preconditioner_refreshes, 0);
    EXPECT_LE(st[1].solver_iterations, st[2].solver_iterations + 3);
}
